"""capsflow.bie.single_layer against the exact flow of two uniform-traction spheres (each one's own
2c/3 plus the other's exterior flow), near contact and far apart, and its argument checks."""
import numpy as np
import pytest

import capsflow


def icosphere(level: int):
    """The unit icosphere: an icosahedron split 4-to-1 `level` times, projected onto the sphere,
    triangles counter-clockwise seen from outside."""
    p = (1 + 5 ** 0.5) / 2
    v = [(-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0), (0, -1, p), (0, 1, p), (0, -1, -p), (0, 1, -p),
         (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    verts = [np.array(x, float) / np.linalg.norm(x) for x in v]
    for _ in range(level):
        mid, faces = {}, []

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                m = verts[a] + verts[b]
                verts.append(m / np.linalg.norm(m))
                mid[key] = len(verts) - 1
            return mid[key]

        for a, b, c in f:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            faces += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = faces
    x, t = np.array(verts), np.array(f, dtype=np.int32)
    n = np.cross(x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]])
    assert (np.einsum("ij,ij->i", n, x[t].mean(axis=1)) > 0).all(), "outward orientation"
    return x, t


def uniform_traction_sphere(r, c):
    """The flow of a unit sphere carrying the uniform traction c: 2c/3 on it, outside a Stokeslet of
    force 4πc plus a potential dipole (r from the centre, rows)."""
    d = np.linalg.norm(r, axis=1)[:, None]
    rc = (r @ c)[:, None]
    out = 0.5 * (c / d + rc * r / d ** 3) + (c / d ** 3 - 3 * rc * r / d ** 5) / 6
    return np.where(d <= 1 + 1e-12, 2 * c / 3, out)


def test_two_spheres_near_contact_are_the_sum_of_their_exact_flows():
    x, t = icosphere(3)
    h = max(np.linalg.norm(x[t[:, k]] - x[t[:, (k + 1) % 3]], axis=1).max() for k in range(3))
    c1, c2 = np.array([0.4, -0.3, 1.0]), np.array([-0.7, 0.2, 0.5])
    direction = x[0] / np.linalg.norm(x[0])
    errors = {}
    for gap in (0.1 * h, 10.0):
        o2 = (2 + gap) * direction
        r = capsflow.bie.single_layer([(x, t), (x + o2, t)], [np.tile(c1, (len(x), 1)), np.tile(c2, (len(x), 1))],
                                      geometry="curved", backend="direct")
        exact1 = uniform_traction_sphere(x, c1) + uniform_traction_sphere(x - o2, c2)
        exact2 = uniform_traction_sphere(x + o2, c1) + uniform_traction_sphere(x, c2)
        err = max(np.abs(r["velocities"][0] - exact1).max(), np.abs(r["velocities"][1] - exact2).max())
        errors[gap] = err / (2 / 3 * np.linalg.norm(c1))
        if gap < 1:
            assert r["cross_pairs"] > 0 and r["inside_nodes"] == 0
            assert r["closest"]["distance"] == pytest.approx(gap, abs=1e-12)  # two vertices face each other
        else:
            assert r["closest"] is None and r["cross_pairs"] == 0
    # 1 280 curved elements: one sphere alone errs by O(h³), 2.7e-5 here (far apart); a tenth of an
    # element from the other sphere the error must stay of that size (tests/core/bie/test_multi_surface.cpp
    # measures 1.1× at 5 120 elements; 1.6× here: 4.2e-5), so at most twice it.
    assert errors[10.0] < 1e-4, errors
    assert errors[0.1 * h] < 2 * errors[10.0], errors


def test_arguments_are_checked_and_named():
    x, t = icosphere(1)
    q = np.zeros_like(x)
    with pytest.raises(ValueError, match="one array per surface"):
        capsflow.bie.single_layer([(x, t), (x + 3, t)], [q])
    bad = t.copy()
    bad[0, 0] = len(x)
    with pytest.raises(ValueError, match=r"surfaces\[0\] triangles has a node index outside"):
        capsflow.bie.single_layer([(x, bad)], [q])
    with pytest.raises(ValueError, match=r"loads\[0\] must have 42 rows"):
        capsflow.bie.single_layer([(x, t)], [q[:-1]])
    with pytest.raises(ValueError, match="geometry must be one of"):
        capsflow.bie.single_layer([(x, t)], [q], geometry="smooth")
