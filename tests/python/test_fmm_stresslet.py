"""capsflow.fmm's stresslet (double layer): the FMM against the direct sum, the direct sum against the
formula, the closed-surface identity, reuse of a StressletFmm, and the checks of the normals."""
import math

import numpy as np
import pytest

from capsflow import fmm
from points import forces, make_points, rel_l2, traced_peak


def stresslet_formula(src, f, n, trg):
    """1/(8π) Σ_j −6 (r·f_j)(r·n_j) r/|r|⁵, r = target − source, coincident pairs skipped: the
    convention of fmm/include/capsflow/fmm/stresslet.hpp written out pair by pair."""
    u = np.zeros((len(trg), 3))
    for i, x in enumerate(trg):
        for j, y in enumerate(src):
            r = x - y
            d = math.sqrt(r @ r)
            if d == 0:
                continue
            u[i] += -6 * (r @ f[j]) * (r @ n[j]) * r / d**5
    return u / (8 * math.pi)


def sphere_rule(n_theta: int):
    """Gauss-Legendre in cos θ × midpoint in φ (2·n_theta) on the unit sphere: points (= outward unit
    normals) and area weights; exact for the area (4π) and spectrally accurate for smooth integrands."""
    x, w = np.polynomial.legendre.leggauss(n_theta)
    n_phi = 2 * n_theta
    phi = (np.arange(n_phi) + 0.5) * 2 * math.pi / n_phi
    ct, ph = np.meshgrid(x, phi, indexing="ij")
    st = np.sqrt(1 - ct**2)
    p = np.stack([st * np.cos(ph), st * np.sin(ph), ct], axis=-1).reshape(-1, 3)
    weights = np.repeat(w * 2 * math.pi / n_phi, n_phi)
    return p, weights


def smooth_double_layer(p):
    """f = w·u(y) on the unit sphere with equal weights 4π/N and the smooth u of tests/fmm/points.hpp
    (surface_double_layer)."""
    u = np.stack([p[:, 0] * p[:, 1], np.sin(2 * p[:, 2]), p[:, 0] - p[:, 2] ** 2], axis=1)
    return u * (4 * math.pi / len(p))


@pytest.mark.parametrize("tolerance", [1e-3, 1e-6])
@pytest.mark.parametrize("separate", [False, True], ids=["self", "separate"])
@pytest.mark.parametrize("kind", ["cube", "sphere"])
def test_fmm_error_is_within_the_tolerance(kind, separate, tolerance):
    src = make_points(kind, 3000, 1)
    trg = make_points(kind, 1000, 2) if separate else None
    if kind == "cube":  # random forces and random "normals": any two vectors work
        f, n = forces(3000, 3), forces(3000, 4)
    else:  # the double layer's use: n the outward unit normal, f = w·u(y) for a smooth u
        f, n = smooth_double_layer(src), src.copy()
    # small leaves: several levels, so every translation operator takes part (as test_fmm.py)
    u = fmm.StressletFmm(src, trg, tolerance=tolerance, leaf_size=48).evaluate(f, n)
    ref = fmm.stresslet_direct(src, f, n, trg)
    err = rel_l2(u, ref)
    print(f"stresslet {kind} {'separate' if separate else 'self'} tol {tolerance:g}: rel L2 error {err:.3g}")
    # the FMM's contract (fmm/calibration.hpp, the stresslet's own table): relative L2 error against
    # the direct sum <= tolerance
    assert err <= tolerance


@pytest.mark.parametrize("tolerance", [1e-3, 1e-6])
def test_random_forces_with_surface_normals_at_the_default_leaves(tolerance):
    # random (non-smooth) f with the outward normals, targets = sources, the leaves the calibration
    # chose (the defaults of stresslet() and StressletFmm)
    src = make_points("sphere", 3000, 1)
    f, n = forces(3000, 3), src.copy()
    err = rel_l2(fmm.stresslet(src, f, n, tolerance=tolerance), fmm.stresslet_direct(src, f, n))
    print(f"stresslet sphere random f, normals, default leaves, tol {tolerance:g}: rel L2 error {err:.3g}")
    # the FMM's contract, as above
    assert err <= tolerance


def test_stresslet_function_equals_the_object():
    src, f, n = make_points("sphere", 2000, 5), forces(2000, 6), make_points("sphere", 2000, 7)
    # same points, order and leaves: the same arithmetic (1e-14: the last bits)
    np.testing.assert_allclose(fmm.stresslet(src, f, n, tolerance=1e-6),
                               fmm.StressletFmm(src, tolerance=1e-6)(f, n), rtol=1e-14, atol=1e-14)


def test_direct_sum_matches_the_formula():
    rng = np.random.default_rng(8)
    src, f, n, trg = (rng.normal(size=(50, 3)) for _ in range(4))
    # 1e-12: rounding of a 50-term sum of O(1)..O(10³) terms (close pairs), summed in another order
    np.testing.assert_allclose(fmm.stresslet_direct(src, f, n, trg), stresslet_formula(src, f, n, trg),
                               rtol=1e-12, atol=1e-12 * np.abs(stresslet_formula(src, f, n, trg)).max())
    # targets = sources: the coincident pair is skipped, as in the formula
    np.testing.assert_allclose(fmm.stresslet_direct(src, f, n), stresslet_formula(src, f, n, src),
                               rtol=1e-12, atol=1e-12 * np.abs(stresslet_formula(src, f, n, src)).max())


def test_a_single_pair_by_hand():
    src = np.array([[0.0, 0, 0]])
    trg = np.array([[2.0, 0, 0]])
    # r = (2, 0, 0), f = n = e_x: −6 (r·f)(r·n) r/|r|⁵ = −6·2·2·(2, 0, 0)/32 = (−1.5, 0, 0), over 8π
    u = fmm.stresslet_direct(src, [[1.0, 0, 0]], [[1.0, 0, 0]], trg)
    np.testing.assert_allclose(u, [[-1.5 / (8 * math.pi), 0, 0]], rtol=1e-15, atol=0)
    # f ⟂ r: no velocity; the sum is bilinear, so f and n play symmetric roles
    assert not fmm.stresslet_direct(src, [[0.0, 1, 0]], [[1.0, 0, 0]], trg).any()
    np.testing.assert_array_equal(fmm.stresslet_direct(src, [[1.0, 2, 3]], [[4.0, 5, 6]], trg),
                                  fmm.stresslet_direct(src, [[4.0, 5, 6]], [[1.0, 2, 3]], trg))


def test_constant_double_layer_on_a_closed_sphere():
    """f = c·dS, n = outward unit normal over the unit sphere: u = c inside, 0 outside (the identity
    of stresslet.hpp in its sign convention, r = target − source), and c/2 on the surface (the
    principal value, the mean of the two sides) — +c/2 with this kernel, not −c/2."""
    c = np.array([0.3, -0.5, 0.8])
    p, w = sphere_rule(24)
    rng = np.random.default_rng(9)
    d = rng.normal(size=(40, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    inside = d[:20] * 0.6 * rng.uniform(size=(20, 1)) ** (1 / 3)  # |x| <= 0.6
    outside = d[20:] * (1.6 + rng.uniform(size=(20, 1)))          # 1.6 <= |x| <= 2.6
    u_in = fmm.stresslet_direct(p, w[:, None] * c, p, inside)
    u_out = fmm.stresslet_direct(p, w[:, None] * c, p, outside)
    # 1e-8: the 24 × 48 product rule integrates this smooth integrand (targets >= 0.4 from the
    # surface) to ~5e-10 (measured with numpy's sum of the formula); 20x margin
    np.testing.assert_allclose(u_in, np.tile(c, (20, 1)), rtol=0, atol=1e-8)
    np.testing.assert_allclose(u_out, 0, rtol=0, atol=1e-8)
    # On the surface (targets = the nodes, each node's own pair skipped) the integrand is bounded
    # but not smooth at the target, so the point rule converges to c/2 only at first order in the
    # spacing: relative L2 error 0.044 at 24 × 48 and 0.022 at 48 × 96 (numpy, the same sum).
    errors = []
    for n_theta in (24, 48):
        p, w = sphere_rule(n_theta)
        u = fmm.stresslet_direct(p, w[:, None] * c, p)
        errors.append(rel_l2(u, np.tile(c / 2, (len(p), 1))))
    print(f"on-surface relative L2 error against c/2: {errors}")
    # 0.06: the first-order error above with margin; with −c/2 (the other sign) it would be ~2
    assert errors[0] < 0.06
    # halving the spacing at least nearly halves the error (0.6: margin on the ratio 0.5), so the
    # limit is c/2 and not a nearby value
    assert errors[1] < 0.6 * errors[0]


def test_a_stressletfmm_is_reused_over_density_sets_and_points():
    src, trg = make_points("cube", 3000, 10), make_points("cube", 500, 11)
    f1, f2, n1, n2 = forces(3000, 12), forces(3000, 13), forces(3000, 14), forces(3000, 15)
    obj = fmm.StressletFmm(src, trg, tolerance=1e-6)
    assert obj.order == fmm.order_for_tolerance(1e-6, "stresslet")
    u1, u2 = obj.evaluate(f1, n1), obj(f2, n2)
    stacked = obj.evaluate(np.stack([f1, f2]), np.stack([n1, n2]))
    assert stacked.shape == (2, 500, 3)
    # several densities in one pass: "results equal separate calls to rounding" (fmm/fmm.hpp)
    np.testing.assert_allclose(stacked, np.stack([u1, u2]), rtol=1e-12, atol=1e-14)
    moved = src + 0.5
    obj.move(moved, trg)
    # the contract at the new points (relative L2 against the direct sum <= tolerance)
    assert rel_l2(obj.evaluate(f1, n1), fmm.stresslet_direct(moved, f1, n1, trg)) <= 1e-6
    assert (obj.n_sources, obj.n_targets) == (3000, 500)
    assert repr(obj).startswith("StressletFmm(n_sources=3000, n_targets=500")


def test_lists_and_non_contiguous_arrays_give_the_same_result():
    src, f, n = make_points("sphere", 200, 16), forces(200, 17), forces(200, 18)
    ref = fmm.stresslet_direct(src, f, n)
    # exact: the same numbers reach the same arithmetic, whichever container held them
    assert np.array_equal(fmm.stresslet_direct(src.tolist(), f.tolist(), n.tolist()), ref)
    assert np.array_equal(fmm.stresslet_direct(src, np.asfortranarray(f), np.asfortranarray(n)), ref)


def test_c_contiguous_float64_input_is_not_copied_in_python():
    n = 20_000
    src, f, nv = make_points("sphere", n, 21), forces(n, 22), forces(n, 23)
    obj = fmm.StressletFmm(src, tolerance=1e-3)
    out_bytes = n * 3 * 8
    # the only array the call makes is its output (the C++ interleaving buffer is not traced); a
    # Python copy of any (N, 3) input would add another out_bytes. 0.25·out_bytes of slack
    assert traced_peak(lambda: obj.evaluate(f, nv)) < 1.25 * out_bytes
    # the check can fail: Fortran-ordered normals are copied into C order, and that copy shows
    assert traced_peak(lambda: obj.evaluate(f, np.asfortranarray(nv))) >= 2 * out_bytes


SRC = np.random.default_rng(19).normal(size=(50, 3))
F = np.random.default_rng(20).normal(size=(50, 3))

CALLS = {
    "stresslet": lambda s, f, n, t=None: fmm.stresslet(s, f, n, t),
    "stresslet_direct": lambda s, f, n, t=None: fmm.stresslet_direct(s, f, n, t),
    "StressletFmm": lambda s, f, n, t=None: fmm.StressletFmm(s, t).evaluate(f, n),
}


@pytest.mark.parametrize("call", CALLS.values(), ids=CALLS.keys())
def test_normals_are_checked_like_forces(call):
    with pytest.raises(ValueError, match="normals must have 50 rows"):
        call(SRC, F, F[:49])
    with pytest.raises(ValueError, match=r"normals must have shape"):
        call(SRC, F, F.ravel())
    with pytest.raises(TypeError, match="normals must be a float64 array, got dtype float32"):
        call(SRC, F, F.astype(np.float32))
    bad = F.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match=r"normals\[3, 1\] is nan"):
        call(SRC, F, bad)
    with pytest.raises(ValueError, match=r"normals must have shape \(N, 3\)"):
        call(SRC, F, None)


def test_stacked_forces_and_normals_must_match():
    obj = fmm.StressletFmm(SRC)
    with pytest.raises(ValueError, match=r"normals must have the shape of forces \(2, 50, 3\), got \(50, 3\)"):
        obj.evaluate(np.stack([F, F]), F)
    with pytest.raises(ValueError, match=r"normals must have the shape of forces \(2, 50, 3\), got \(3, 50, 3\)"):
        obj.evaluate(np.stack([F, F]), np.stack([F, F, F]))
    # stacking is only for evaluate: the direct sum takes one set
    with pytest.raises(ValueError, match=r"forces must have shape \(N, 3\), got"):
        fmm.stresslet_direct(SRC, np.stack([F, F]), np.stack([F, F]))


def test_empty_sets_and_the_kernel_name():
    empty = np.zeros((0, 3))
    for call in CALLS.values():
        # no sources: exactly zero at every target; no targets: an empty result
        u = call(empty, empty, empty, SRC)
        assert u.shape == (50, 3) and not u.any()
        assert call(SRC, F, F, empty).shape == (0, 3)
    with pytest.raises(ValueError, match="kernel must be one of"):
        fmm.order_for_tolerance(1e-6, "laplace")
