"""capsflow.fmm refuses malformed input with a clear exception (never a crash), and handles empty
point sets as sums over nothing."""
import numpy as np
import pytest

from capsflow import fmm

SRC = np.random.default_rng(1).normal(size=(50, 3))
F = np.random.default_rng(2).normal(size=(50, 3))

CALLS = {
    "stokeslet": lambda s, f, t=None: fmm.stokeslet(s, f, t),
    "stokeslet_direct": lambda s, f, t=None: fmm.stokeslet_direct(s, f, t),
    "StokesletFmm": lambda s, f, t=None: fmm.StokesletFmm(s, t).evaluate(f),
    # the stresslet with valid normals of the forces' shape: the forces' checks come first
    # (the normals' own checks: test_fmm_stresslet.py)
    "stresslet": lambda s, f, t=None: fmm.stresslet(s, f, np.ones(np.shape(f)), t),
    "stresslet_direct": lambda s, f, t=None: fmm.stresslet_direct(s, f, np.ones(np.shape(f)), t),
    "StressletFmm": lambda s, f, t=None: fmm.StressletFmm(s, t).evaluate(f, np.ones(np.shape(f))),
}


@pytest.mark.parametrize("call", CALLS.values(), ids=CALLS.keys())
@pytest.mark.parametrize("shape", [(50,), (50, 2), (50, 4), (50, 3, 1), (3, 50)])
def test_wrong_shapes_are_value_errors(call, shape):
    with pytest.raises(ValueError, match=r"sources must have shape \(N, 3\), got"):
        call(np.zeros(shape), F)
    with pytest.raises(ValueError, match=r"targets must have shape \(N, 3\), got"):
        call(SRC, F, np.zeros(shape))


@pytest.mark.parametrize("call", CALLS.values(), ids=CALLS.keys())
def test_forces_must_match_the_sources(call):
    with pytest.raises(ValueError, match="forces must have 50 rows"):
        call(SRC, F[:49])
    with pytest.raises(ValueError, match=r"forces must have shape"):
        call(SRC, F.ravel())


@pytest.mark.parametrize("call", CALLS.values(), ids=CALLS.keys())
@pytest.mark.parametrize("dtype", [np.float32, np.int64, np.complex128, object])
def test_other_dtypes_are_type_errors(call, dtype):
    with pytest.raises(TypeError, match=f"sources must be a float64 array, got dtype {np.dtype(dtype)}"):
        call(SRC.astype(dtype), F)
    with pytest.raises(TypeError, match="forces must be a float64 array"):
        call(SRC, F.astype(dtype))


@pytest.mark.parametrize("call", CALLS.values(), ids=CALLS.keys())
def test_non_numbers_are_type_errors(call):
    with pytest.raises(TypeError, match="sources must be an array of float64, got list"):
        call([["a", "b", "c"]], F)


@pytest.mark.parametrize("call", CALLS.values(), ids=CALLS.keys())
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_values_are_named(call, bad):
    for name, arg in (("sources", 0), ("forces", 1), ("targets", 2)):
        args = [SRC.copy(), F.copy(), SRC.copy()]
        args[arg][17, 2] = bad
        with pytest.raises(ValueError, match=rf"{name}\[17, 2\] is {bad}: every coordinate and force must be finite"):
            call(*args)


def test_empty_point_sets_are_sums_over_nothing():
    empty = np.zeros((0, 3))
    for call in CALLS.values():
        # no sources: the velocity is exactly zero at every target
        u = call(empty, empty, SRC)
        assert u.shape == (50, 3) and not u.any()
        # no targets: an empty result
        assert call(SRC, F, empty).shape == (0, 3)
    with pytest.raises(ValueError, match=r"sources must have shape \(N, 3\), got \(0,\)"):
        fmm.stokeslet(np.array([]), F)


@pytest.mark.parametrize("tolerance", [0, -1e-6, 1, 2.0, float("nan"), float("inf")])
def test_tolerance_must_be_in_0_1(tolerance):
    with pytest.raises(ValueError, match="tolerance must be in"):
        fmm.stokeslet(SRC, F, tolerance=tolerance)


@pytest.mark.parametrize("threads", [0, -1, 2.5, True, "2"])
def test_threads_must_be_a_positive_integer(threads):
    with pytest.raises(ValueError, match="threads must be an integer in 1..4096 or None"):
        fmm.stokeslet_direct(SRC, F, threads=threads)


@pytest.mark.parametrize("order", [3, 15, 8.0])
def test_order_must_be_in_4_14(order):
    with pytest.raises(ValueError, match="order must be an integer in 4..14 or None"):
        fmm.StokesletFmm(SRC, order=order)


def test_stacked_forces_must_match_the_sources():
    obj = fmm.StokesletFmm(SRC)
    with pytest.raises(ValueError, match="forces must have 50 rows"):
        obj.evaluate(np.zeros((2, 49, 3)))
    with pytest.raises(ValueError, match=r"forces must have shape \(N, 3\) or \(K, N, 3\)"):
        obj.evaluate(np.zeros((2, 2, 50, 3)))
    # stacking is only for evaluate: the direct sum and stokeslet() take one force set
    with pytest.raises(ValueError, match=r"forces must have shape \(N, 3\), got"):
        fmm.stokeslet_direct(SRC, np.zeros((2, 50, 3)))
