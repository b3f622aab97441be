"""capsflow.fmm: the FMM against the direct sum, the direct sum against the formula, reuse of an
FMM object, and that C-contiguous float64 input is read in place."""
import math
import threading
import time

import numpy as np
import pytest

from capsflow import fmm
from points import forces, make_points, rel_l2, traced_peak


@pytest.mark.parametrize("tolerance", [1e-3, 1e-6, 1e-8])
@pytest.mark.parametrize("separate", [False, True], ids=["self", "separate"])
@pytest.mark.parametrize("kind", ["sphere", "cube", "clustered"])
def test_fmm_error_is_within_the_tolerance(kind, separate, tolerance):
    src = make_points(kind, 3000, 1)
    trg = make_points(kind, 1000, 2) if separate else None
    f = forces(3000, 3)
    # small leaves: several levels, so every translation operator takes part (tests/fmm uses 48;
    # 128 at 1e-8, whose order-10 boxes make 48-point leaves slow, still gives three levels)
    leaf = 128 if tolerance < 1e-6 else 48
    u = fmm.StokesletFmm(src, trg, tolerance=tolerance, leaf_size=leaf).evaluate(f)
    ref = fmm.stokeslet_direct(src, f, trg)
    # the FMM's contract (fmm/calibration.hpp): relative L2 error against the direct sum <= tolerance
    assert rel_l2(u, ref) <= tolerance


def test_stokeslet_with_default_leaves_on_a_larger_sphere():
    src, f = make_points("sphere", 30000, 4), forces(30000, 5)
    u = fmm.stokeslet(src, f, tolerance=1e-6)
    sample = np.arange(0, 30000, 30)  # 1000 targets: the direct sum over all would take long
    ref = fmm.stokeslet_direct(src, f, src[sample])
    # the sampled targets are sources too; direct skips their self pair as the FMM does.
    # Contract as above, measured on the sample
    assert rel_l2(u[sample], ref) <= 1e-6


def test_direct_sum_matches_the_formula():
    rng = np.random.default_rng(6)
    src, f, trg = rng.normal(size=(7, 3)), rng.normal(size=(7, 3)), rng.normal(size=(5, 3))
    r = trg[:, None, :] - src[None, :, :]
    d = np.linalg.norm(r, axis=2)
    rf = np.einsum("ijk,jk->ij", r, f)
    ref = (f[None] / d[..., None] + r * (rf / d**3)[..., None]).sum(axis=1) / (8 * math.pi)
    # 1e-13: rounding of a 7-term sum of O(1) terms (the kernel's rsqrt is refined to full precision)
    np.testing.assert_allclose(fmm.stokeslet_direct(src, f, trg), ref, rtol=1e-13, atol=1e-15)


def test_self_interaction_is_skipped():
    src = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    f = np.array([[1.0, 0, 0], [0.0, 0, 0]])
    u = fmm.stokeslet_direct(src, f)
    # point 0 feels nothing (its own pair skipped, point 1 has no force); point 1 gets
    # (f/r + r (r·f)/r³)/(8π) = 2/(8π) along x
    np.testing.assert_allclose(u, [[0, 0, 0], [2 / (8 * math.pi), 0, 0]], rtol=1e-15, atol=0)


def test_an_fmm_object_is_reused_over_force_sets_and_points():
    src, trg = make_points("cube", 4000, 7), make_points("cube", 500, 8)
    f1, f2 = forces(4000, 9), forces(4000, 10)
    obj = fmm.StokesletFmm(src, trg, tolerance=1e-6)
    u1, u2 = obj.evaluate(f1), obj(f2)
    # same tree, same order, owner-computes threads: a fresh object computes the same numbers
    # (1e-14: allow the last bits, the arithmetic is the same)
    np.testing.assert_allclose(u2, fmm.stokeslet(src, f2, trg, tolerance=1e-6), rtol=1e-14, atol=1e-14)
    stacked = obj.evaluate(np.stack([f1, f2]))
    assert stacked.shape == (2, 500, 3)
    # several densities in one pass: "results equal separate calls to rounding" (fmm/fmm.hpp)
    np.testing.assert_allclose(stacked, np.stack([u1, u2]), rtol=1e-12, atol=1e-14)
    moved = src + 0.5
    obj.move(moved, trg)
    np.testing.assert_allclose(obj.evaluate(f1), fmm.stokeslet(moved, f1, trg, tolerance=1e-6), rtol=1e-14, atol=1e-14)
    assert (obj.n_sources, obj.n_targets) == (4000, 500)
    assert obj.order == fmm.order_for_tolerance(1e-6)


def test_lists_and_non_contiguous_arrays_give_the_same_result():
    src, f = make_points("sphere", 200, 11), forces(200, 12)
    ref = fmm.stokeslet_direct(src, f)
    # exact: the same numbers reach the same arithmetic, whichever container held them
    assert np.array_equal(fmm.stokeslet_direct(src.tolist(), f.tolist()), ref)
    assert np.array_equal(fmm.stokeslet_direct(np.asfortranarray(src), f[::1]), ref)
    wide = np.zeros((200, 6))
    wide[:, ::2] = src
    assert np.array_equal(fmm.stokeslet_direct(wide[:, ::2], f), ref)


def test_c_contiguous_float64_input_is_not_copied():
    n = 100_000
    src, f = make_points("sphere", n, 13), forces(n, 14)
    obj = fmm.StokesletFmm(src[:10], tolerance=1e-3)
    out_bytes = n * 3 * 8

    def move_and_evaluate(points, force):
        obj.move(points)
        obj.evaluate(force)

    # the only array the call makes is its output (C++ allocations are not traced); a copy of
    # any (N, 3) input would add another out_bytes. 0.25·out_bytes of slack for small objects
    assert traced_peak(lambda: move_and_evaluate(src, f)) < 1.25 * out_bytes
    assert traced_peak(lambda: fmm.stokeslet(src, f, tolerance=1e-3)) < 1.25 * out_bytes
    # the check can fail: Fortran-ordered points are copied into C order, and that copy shows
    assert traced_peak(lambda: move_and_evaluate(np.asfortranarray(src), f)) >= 2 * out_bytes


def test_the_gil_is_released_during_a_sum():
    src, f = make_points("cube", 20000, 15), forces(20000, 16)
    started, times = threading.Event(), {}

    def work():
        started.set()
        times["start"] = time.perf_counter()
        fmm.stokeslet_direct(src, f, threads=1)  # 4e8 pairs: ~1 s
        times["end"] = time.perf_counter()

    t = threading.Thread(target=work)
    t.start()
    started.wait()
    first_python_step = time.perf_counter()  # this thread runs Python while the sum goes on
    t.join()
    # with the GIL held, this thread could run no Python until the sum returned; released, it
    # runs at once: well before the end of a sum of ~1 s (half of it: margin for a loaded machine)
    assert first_python_step < times["end"] - 0.5 * (times["end"] - times["start"])


def test_the_one_shot_functions_reuse_their_fmm_and_give_a_fresh_ones_result():
    """stokeslet()/stresslet() keep their last FMM and move it to new points (warm buffers): the
    result must be exactly that of a new FMM on those points, whatever came before."""
    a, b = make_points("sphere", 2000, 11), make_points("cube", 1500, 12)
    fa, fb = forces(2000, 13), forces(1500, 14)
    for points, f, targets in [(a, fa, None), (b, fb, None), (a, fa, b), (b, fb, None)]:
        got = fmm.stokeslet(points, f, targets, tolerance=1e-6)
        fresh = fmm.StokesletFmm(points, targets, tolerance=1e-6).evaluate(f)
        # same points, same order, same tree: the same arithmetic, bit for bit
        assert np.array_equal(got, fresh)
    n = forces(1500, 15)
    got = fmm.stresslet(b, fb, n, tolerance=1e-3)
    assert np.array_equal(got, fmm.StressletFmm(b, tolerance=1e-3).evaluate(fb, n))
    # another tolerance builds another FMM (another order): still the fresh result
    got = fmm.stokeslet(b, fb, tolerance=1e-3)
    assert np.array_equal(got, fmm.StokesletFmm(b, tolerance=1e-3).evaluate(fb))
    fmm.clear_operator_cache()  # frees the kept FMMs too; the next call builds anew
    assert np.array_equal(fmm.stokeslet(a, fa, tolerance=1e-6), fmm.StokesletFmm(a, tolerance=1e-6).evaluate(fa))
