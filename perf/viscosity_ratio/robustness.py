#!/usr/bin/python3
"""The λ ≠ 1 robustness table (perf/RESULTS.md §3.4): the viscosity ratio λ = 0.01, 0.1, 10, 100 run to γ̇t = 5 on the sphere
and on an a/b = 2 prolate spheroid (axis along the flow, x1, so that it lies in the shear plane),
neo-Hookean membrane, simple shear, Ca_s = 0.3 (as scenes/sphere_shear_lambda5.toml), 1280 elements
(mesh.level 3), one thread. Prints one markdown row per run: how it stopped, steps, right-hand-side
evaluations, GMRES iterations per evaluation (mean over the run = timing.iterations.gmres /
rhs_evaluations; max = the largest per-row mean, summary.json viscosity_ratio.gmres_per_eval_max),
final D12 (Taylor, from the inertia ellipsoid's axes Le1, Le2), D_flow and θ (the in-plane Taylor
parameter and the major axis' inclination to the flow, docs/conventions.md §5.6), and the health warnings
(condition @ γ̇t). Exit status 1 when a run did not reach t_end.

    perf/viscosity_ratio/robustness.py [--capsflow build/bin/capsflow] [--out DIR] [--reuse]
                                       [--lambdas 0.01,0.1,10,100] [--shapes sphere,spheroid]

Runs one after the other (`--threads 1`) into DIR/<shape>_lambda<λ>; --reuse reads the folders that
already hold a summary.json instead of running them again. Run from the repository root. About 30–60
CPU seconds per run on a 2026 x86 core (the λ = 0.01 runs take twice the Heun steps of λ = 1).
"""
import argparse
import json
import os
import subprocess
import sys

SCENE = 'scenes/sphere_shear_lambda5.toml'  # NH membrane, simple shear, Ca_s = 0.3, level 3
SHAPES = {
    'sphere': ['mesh.shape="sphere"'],
    'spheroid': ['mesh.shape="spheroid"', 'mesh.aspect=2', 'mesh.axis=1'],
}


def run(capsflow, shape, lam, folder, reuse):
    summary = os.path.join(folder, 'summary.json')
    rc = None
    if not (reuse and os.path.exists(summary)):
        cmd = [capsflow, 'run', SCENE, '--threads', '1', '--overwrite', '-o', folder,
               '--set', f'fluid.viscosity_ratio={lam}', '--set', 'time.t_end=5',
               '--set', 'time.stop_at_steady=false', '--set', 'output.fields=[]']
        for s in SHAPES[shape]:
            cmd += ['--set', s]
        os.makedirs(folder, exist_ok=True)
        with open(os.path.join(folder, 'log'), 'w') as log:
            rc = subprocess.call(cmd, stdout=log, stderr=subprocess.STDOUT)
    if not os.path.exists(summary):
        return {'shape': shape, 'lam': lam, 'rc': rc, 'missing': True}
    with open(summary) as f:
        s = json.load(f)
    vr = s.get('viscosity_ratio', {})
    gm = s['timing']['iterations'].get('gmres', 0)
    warnings = [f"{w['condition']} @ {w['t']:.2f}" for w in s.get('health', {}).get('warnings', [])]
    return {'shape': shape, 'lam': lam, 'rc': rc, 'missing': False, 'stop': s['stop_reason'], 't': s['t'],
            'steps': s['steps'], 'evals': s['rhs_evaluations'], 'gm_mean': gm / max(s['rhs_evaluations'], 1),
            'gm_max': vr.get('gmres_per_eval_max', float('nan')), 'D12': s['D12'], 'D_flow': s['D_flow'], 'theta': s['theta'],
            'warn': ', '.join(warnings) or '–'}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--capsflow', default='build/bin/capsflow')
    ap.add_argument('--out', default='out-viscosity-ratio-robustness')
    ap.add_argument('--reuse', action='store_true')
    ap.add_argument('--lambdas', default='0.01,0.1,10,100')
    ap.add_argument('--shapes', default='sphere,spheroid')
    a = ap.parse_args()
    rows = []
    for shape in a.shapes.split(','):
        for lam in a.lambdas.split(','):
            r = run(a.capsflow, shape, lam, os.path.join(a.out, f'{shape}_lambda{lam}'), a.reuse)
            rows.append(r)
            print(f"# done: {shape} λ = {lam}" + (f" (exit {r['rc']})" if r['rc'] is not None else ' (reused)'),
                  file=sys.stderr, flush=True)
    print('| shape | λ | stop_reason (γ̇t) | steps | evaluations | GMRES/eval mean | max | D12 | D_flow | θ (°) | health warnings |')
    print('|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|')
    bad = 0
    for r in rows:
        if r['missing']:
            print(f"| {r['shape']} | {r['lam']} | no summary.json (exit {r['rc']}) | | | | | | | | |")
            bad += 1
            continue
        bad += r['stop'] != 't_end'
        print(f"| {r['shape']} | {r['lam']} | {r['stop']} ({r['t']:g}) | {r['steps']} | {r['evals']} | "
              f"{r['gm_mean']:.2f} | {r['gm_max']:.2f} | {r['D12']:.4f} | {r['D_flow']:.4f} | {r['theta']:.2f} | {r['warn']} |")
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
