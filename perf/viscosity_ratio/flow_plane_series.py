#!/usr/bin/python3
"""In-plane Taylor parameter, inclination and tank-treading rate of a run, from the positions stored in
run.h5 (a reimplementation of docs/conventions.md §5.6 in numpy: an independent check of
geometry/flow_plane and the way to read these observables from runs made before they were output).

    perf/viscosity_ratio/flow_plane_series.py RUN_DIR [RUN_DIR ...] [--last N]

Prints per output time t, D_flow, theta (degrees) and the tank-treading rate since the previous output.
The flow plane is taken from the run's scene (simple shear: x1x2; planar hyperbolic: x1x3).
Needs h5py and numpy (Debian: python3-h5py, python3-numpy).
"""
import sys

import h5py
import numpy as np


def volume_moments(x, tri):
    o = x.mean(axis=0)
    v0, v1, v2 = x[tri[:, 0]] - o, x[tri[:, 1]] - o, x[tri[:, 2]] - o
    vt = np.einsum('ij,ij->i', v0, np.cross(v1, v2)) / 6
    s = v0 + v1 + v2
    V = vt.sum()
    c = (vt[:, None] * s).sum(axis=0) / 4 / V
    outer = lambda a: np.einsum('i,ij,ik->jk', vt / 20, a, a)
    M2 = outer(v0) + outer(v1) + outer(v2) + outer(s)
    return V, c + o, M2 - V * np.outer(c, c)


def in_plane(x, tri, e1, e2):
    V, c, S = volume_moments(x, tri)
    E = np.stack([e1, e2], axis=1)
    w, vec = np.linalg.eigh(E.T @ S @ E)
    a, b = np.sqrt(5 * w[1] / V), np.sqrt(5 * w[0] / V)
    th = np.arctan2(vec[1, 1], vec[0, 1])
    if th > np.pi / 2: th -= np.pi
    if th <= -np.pi / 2: th += np.pi
    return (a - b) / (a + b), th, a, b, c


def phases(x, tri, e1, e2):
    D, th, a, b, c = in_plane(x, tri, e1, e2)
    d = x - c
    p, q = d @ e1, d @ e2
    xi = (np.cos(th) * p + np.sin(th) * q) / a
    eta = (-np.sin(th) * p + np.cos(th) * q) / b
    return th + np.arctan2(eta, xi), xi**2 + eta**2


def main():
    args = [a for a in sys.argv[1:] if not a.startswith('--')]
    last = int(sys.argv[sys.argv.index('--last') + 1]) if '--last' in sys.argv else 0
    for run in args:
        if run.isdigit(): continue
        f = h5py.File(run + '/run.h5', 'r')
        scene = f['metadata/scene_toml'][()].decode()
        shear = 'simple_shear' in scene
        e1, e2, sense = np.array([1., 0, 0]), (np.array([0., 1, 0]) if shear else np.array([0., 0, -1])), (-1 if shear else 1)
        tri = f['mesh/triangles'][()]
        steps = sorted(f['steps'].keys())
        rows, prev = [], None
        for k in steps:
            g = f['steps/' + k]
            t, x = g.attrs['time'], g['positions'][()]
            D, th, *_ = in_plane(x, tri, e1, e2)
            ph, w = phases(x, tri, e1, e2)
            rate = float('nan')
            if prev is not None and t > prev[0]:
                d = np.remainder(ph - prev[1] + np.pi, 2 * np.pi) - np.pi
                ww = w * prev[2]
                rate = sense * (ww * d).sum() / ww.sum() / (t - prev[0])
            prev = (t, ph, w)
            rows.append((t, D, np.degrees(th), rate))
        print(f'# {run}')
        print('t D_flow theta_deg tank_treading')
        for r in rows[-last:] if last else rows:
            print(f'{r[0]:.4f} {r[1]:.5f} {r[2]:.3f} {r[3]:.5f}')


if __name__ == '__main__':
    main()
