#!/usr/bin/env python3
"""Compute the ROCK4-family coefficient table of src/stepping/rock4_table.inc (docs/time-integration.md §5.8).

    scripts/rock4_coefficients.py --max-stages 152 --out src/stepping/rock4_table.inc   (~30 min, one core)

Needs Debian's python3-numpy and python3-scipy. What it computes, per stage count s = 5..max:

1. The stability polynomial R_s(z) = w4(z) P_{s-4}(z) of Abdulle (2002): w4(z) = Π (1 - z/z_k)(1 - z/z̄_k)
   with two complex zeros z_1, z_2; P_j the orthogonal polynomials for the weight w4(z(x))²/√(1 - x²),
   z = L (x - 1)/2, x in [-1, 1], normalised P_j(0) = 1 (discretised Stieltjes procedure on s + 20
   Gauss-Chebyshev nodes: exact, the integrands are polynomials of degree ≤ 2s). For a given L the four
   real parameters of the zeros solve the four order conditions R_s = 1 + z + z²/2 + z³/6 + z⁴/24 + O(z⁵)
   (Gauss-Newton, continued from s - 1); L is the largest value, by bisection, for which |R_s| ≤ 1 on
   [-L, 0] (sampled at 400 000 points). Abdulle's zeros come from the optimal polynomials instead; the
   intervals agree within 1 % (+0.9 % at s = 5, −0.07 % at s = 100; test_rock4.cpp checks them against
   his Table 2.1).
2. The finishing method W (four stages, 10 coefficients) such that the composite tableau of the
   recurrence part and W satisfies all eight order-4 conditions (nonlinear problems, not only the
   linear ones), chosen among the two-parameter family by least squares on the nine order-5 defects
   plus 3e-4 × the coefficients (keeps them O(1); continued from s - 1, plus two random starts).
3. The embedded weights b̂_1..b̂_5 (W's stages and F(y_{n+1})): order 3, the free parameter set so that
   the estimate's leading linear term is z⁴/24, Kutta's third-order method's.
4. ℓ_s: the interval measured on the polynomial of the step itself (recurrence and W), 400 001 samples.
"""
import argparse
import json
import sys

import numpy as np
from numpy.polynomial import polynomial as npoly
from scipy.optimize import least_squares


def w4_coeffs(zeros):
    c = np.array([1.0])
    for z in zeros:
        m2 = abs(z) ** 2
        c = npoly.polymul(c, [1.0, -2 * z.real / m2, 1.0 / m2])
    return c


def recurrence(s, L, zeros):
    """μ_j, ν_j, κ_j (j = 1..s-4) of P_j = (μ_j z - ν_j) P_{j-1} - κ_j P_{j-2}."""
    n, m = s - 4, s + 20
    x = np.cos((2 * np.arange(1, m + 1) - 1) * np.pi / (2 * m))
    wt = npoly.polyval(L * (x - 1) / 2, w4_coeffs(zeros)) ** 2
    mu, nu, ka = np.zeros(n + 1), np.zeros(n + 1), np.zeros(n + 1)
    pm1, p = np.zeros(m), np.ones(m)
    vm1, v, norm_prev = 0.0, 1.0, None
    for j in range(n):
        norm = np.sum(wt * p * p)
        alpha = np.sum(wt * x * p * p) / norm
        beta = norm / norm_prev if norm_prev is not None else 0.0
        pn = (x - alpha) * p - beta * pm1
        vn = (1 - alpha) * v - beta * vm1
        mu[j + 1], nu[j + 1], ka[j + 1] = (2 / L) * v / vn, -(1 - alpha) * v / vn, beta * vm1 / vn
        sc = 1.0 / np.max(np.abs(pn))
        pm1, p, vm1, v, norm_prev = p * sc, pn * sc, v * sc, vn * sc, norm * sc * sc
    return mu, nu, ka


def p_series(mu, nu, ka, n, terms=5):
    pm1, p = np.zeros(terms), np.zeros(terms)
    p[0] = 1
    for j in range(1, n + 1):
        zp = np.concatenate([[0], p[:-1]])
        pm1, p = p, mu[j] * zp - nu[j] * p - ka[j] * pm1
    return p


def p_eval(mu, nu, ka, n, z):
    pm1, p = np.zeros_like(z), np.ones_like(z)
    for j in range(1, n + 1):
        pm1, p = p, (mu[j] * z - nu[j]) * p - ka[j] * pm1
    return p


def zeros_of(q):
    return [complex(q[0], abs(q[1])), complex(q[2], abs(q[3]))]


def order_defect(s, L, q):
    zs = zeros_of(q)
    mu, nu, ka = recurrence(s, L, zs)
    r = npoly.polymul(p_series(mu, nu, ka, s - 4), w4_coeffs(zs))[:5]
    return np.array([r[1] - 1, r[2] - 1 / 2, r[3] - 1 / 6, r[4] - 1 / 24])


def stable(s, L, q):
    mu, nu, ka = recurrence(s, L, zeros_of(q))
    z = -np.linspace(0, L, 400000)
    return np.max(np.abs(npoly.polyval(z, w4_coeffs(zeros_of(q))) * p_eval(mu, nu, ka, s - 4, z))) <= 1 + 1e-12


def solve_zeros(s, L, q0):
    r = least_squares(lambda q: order_defect(s, L, q), q0, xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return r.x, np.max(np.abs(r.fun))


def polynomial(s, L_guess, q):
    """The largest stable L near L_guess and its zeros."""
    lo, hi = 0.9 * L_guess, 1.1 * L_guess
    for _ in range(30):
        q_lo, r = solve_zeros(s, lo, q)
        if r < 1e-10 and stable(s, lo, q_lo):
            break
        hi, lo = lo, 0.95 * lo
    else:
        sys.exit(f"s = {s}: no stable polynomial below L = {lo}")
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        qm, r = solve_zeros(s, mid, q_lo)
        if r < 1e-10 and stable(s, mid, qm):
            lo, q_lo = mid, qm
        else:
            hi = mid
        if hi - lo < 1e-7 * lo:
            break
    return lo, q_lo


def recurrence_tableau(mu, nu, ka, n):
    rows = [np.zeros(n)]
    r1 = np.zeros(n)
    r1[0] = mu[1]
    rows.append(r1)
    for j in range(2, n + 1):
        r = -nu[j] * rows[j - 1] - ka[j] * rows[j - 2]
        r[j - 1] += mu[j]
        rows.append(r)
    return np.array(rows[:n]), rows[n]


def unpack(x):
    aw = np.zeros((4, 4))
    aw[1, 0], aw[2, 0], aw[2, 1], aw[3, 0], aw[3, 1], aw[3, 2] = x[:6]
    return aw, x[6:10]


def composite(ap, bp, aw, bw):
    n = len(bp)
    a = np.zeros((n + 4, n + 4))
    a[:n, :n], a[n:, :n], a[n:, n:] = ap, bp[None, :], aw
    return a, np.concatenate([bp, bw])


def order4(a, b):
    c = a.sum(1)
    ac = a @ c
    return np.array([b.sum() - 1, b @ c - 1 / 2, b @ (c * c) - 1 / 3, b @ ac - 1 / 6, b @ c ** 3 - 1 / 4,
                     b @ (c * ac) - 1 / 8, b @ (a @ (c * c)) - 1 / 12, b @ (a @ ac) - 1 / 24])


def order5(a, b):
    c = a.sum(1)
    ac = a @ c
    aac = a @ ac
    return np.array([b @ c ** 4 - 1 / 5, b @ (c * c * ac) - 1 / 10, b @ (c * (a @ (c * c))) - 1 / 15,
                     b @ (c * aac) - 1 / 30, b @ (ac * ac) - 1 / 20, b @ (a @ c ** 3) - 1 / 20,
                     b @ (a @ (c * ac)) - 1 / 40, b @ (a @ (a @ (c * c))) - 1 / 60, b @ (a @ aac) - 1 / 120])


def finishing(ap, bp, x0):
    def f(x, weight):
        a, b = composite(ap, bp, *unpack(x))
        return np.concatenate([weight * order4(a, b), order5(a, b), 3e-4 * x])

    x = least_squares(lambda x: f(x, 1e3), x0, xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=5000).x

    def g(x):
        return order4(*composite(ap, bp, *unpack(x)))

    for _ in range(8):  # the order-4 conditions exactly (minimum-norm Newton steps)
        jac = np.array([(g(x + 1e-7 * e) - g(x - 1e-7 * e)) / 2e-7 for e in np.eye(10)]).T
        x = x - np.linalg.lstsq(jac, g(x), rcond=None)[0]
    return x, np.max(np.abs(g(x))), np.linalg.norm(f(x, 0)[8:17])


def embedded(ap, bp, aw, bw):
    n = len(bp)
    a = np.zeros((n + 5, n + 5))
    a[:n, :n], a[n:, :n], a[n:n + 4, n:n + 4], a[n + 4, n:n + 4] = ap, bp[None, :], aw, bw
    c = a.sum(1)
    rows = np.array([np.ones(n + 5), c, c * c, a @ c])

    def weights(b5):
        rhs = np.array([1, 1 / 2, 1 / 3, 1 / 6]) - rows[:, :n] @ bp - rows[:, n + 4] * b5
        return np.linalg.solve(rows[:, n:n + 4], rhs)

    one = np.ones(4)
    a2, a3 = aw @ aw @ one, aw @ aw @ aw @ one
    # z⁴ coefficient of R - R̂ (the lower ones vanish: order 3), from W's own polynomial.
    e = lambda b5: bw @ a3 - weights(b5) @ a3 - b5 * (bw @ a2)
    b5 = (1 / 24 - e(0.0)) / (e(1.0) - e(0.0))
    return np.concatenate([weights(b5), [b5]])


def measured_interval(mu, nu, ka, n, aw, bw, L):
    z = -np.linspace(0, L, 400001)
    u2 = 1 + z * aw[1, 0]
    u3 = 1 + z * (aw[2, 0] + aw[2, 1] * u2)
    u4 = 1 + z * (aw[3, 0] + aw[3, 1] * u2 + aw[3, 2] * u3)
    r = p_eval(mu, nu, ka, n, z) * (1 + z * (bw[0] + bw[1] * u2 + bw[2] * u3 + bw[3] * u4))
    bad = np.nonzero(np.abs(r) > 1 + 1e-10)[0]
    return -z[bad[0] - 1] if len(bad) else L


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--max-stages", type=int, default=152)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    # Start: s = 10 from zeros found by a random search (any start converging to these gives them).
    poly = {}
    q, L = np.array([-0.2584, 3.3789, -2.3700, 1.2636]), 32.5
    for s in list(range(10, 4, -1)) + list(range(11, a.max_stages + 1)):
        near = s + 1 if s < 10 else s - 1
        if near in poly:
            L, q = poly[near][0] * (s / near) ** 2, poly[near][1]
        poly[s] = polynomial(s, L, q)
        print(f"s = {s}: L = {poly[s][0]:.6f} ({poly[s][0] / s / s:.5f} s²)", file=sys.stderr, flush=True)
    rng = np.random.default_rng(0)
    x = None
    lines = []
    for s in range(5, a.max_stages + 1):
        L, q = poly[s]
        zs = zeros_of(q)
        mu, nu, ka = recurrence(s, L, zs)
        apt, bpt = recurrence_tableau(mu, nu, ka, s - 4)
        best = None
        for x0 in ([x] if x is not None else []) + [rng.normal(0, 0.7, 10) for _ in range(12 if x is None else 2)]:
            xs, r4, r5 = finishing(apt, bpt, x0)
            if r4 < 1e-13 and (best is None or r5 < best[2] - 1e-12):
                best = (xs, r4, r5)
        if best is None:
            sys.exit(f"s = {s}: no finishing method found")
        x = best[0]
        aw, bw = unpack(x)
        bh = embedded(apt, bpt, aw, bw)
        ell = measured_interval(mu, nu, ka, s - 4, aw, bw, L)
        print(f"s = {s}: ℓ = {ell:.6f}, order-5 defects {best[2]:.2e}, max |a|, |b| {np.abs(x).max():.2f}, b̂5 {bh[4]:.3f}",
              file=sys.stderr, flush=True)
        f = lambda v: ", ".join(f"{t:.17g}" for t in v)
        lines.append(f"{{{s}, {ell:.17g}, {L:.17g}, {{{f([zs[0].real, zs[0].imag, zs[1].real, zs[1].imag])}}}, "
                     f"{{{f(x[:6])}}}, {{{f(x[6:])}}}, {{{f(bh)}}}}},\n")
    with open(a.out, "w") as out:
        out.write(f"// Generated by scripts/rock4_coefficients.py --max-stages {a.max_stages}: do not edit.\n")
        out.write("// s, ℓ_s, L (orthogonality), {Re z1, Im z1, Re z2, Im z2}, {a21 a31 a32 a41 a42 a43}, {b1..b4}, "
                  "{b̂1..b̂5}\n")
        out.writelines(lines)


if __name__ == "__main__":
    main()
