#!/usr/bin/env python3
"""Same-numbers check for refactors that must not change results (the project's same-numbers rule).

  run:     same_numbers.py run EXE OUTDIR [CASE...]
                                             every scene in scenes/ to γ̇t = 0.3 and the built-in
                                             scene to γ̇t = 2, one at a time, on one thread (so no
                                             reduction order can differ between the two builds)
  compare: same_numbers.py compare DIR_A DIR_B [--expect KEY ...]
                                             every run folder of either (so also folders of runs
                                             made by hand with other --set values)

compare reads each run's summary.json and checks every numeric value, nested ones included, to a
relative 1e-13 (|a − b| ≤ 1e-13 max(|a|, |b|)), and the integer counts (steps, evaluations,
iterations, rejected steps, stages) exactly. Values that measure the machine, not the numerics
(every key ending in _seconds, phase times, memory, run id, version and git strings, the command
line) are skipped. --expect KEY (repeatable) names keys that a change is meant to alter: each is
reported, and the check passes when only they differ.
"""
import json
import math
import pathlib
import subprocess
import sys

REL_TOL = 1e-13
# Keys whose values depend on the machine or the build, not on the numerics.
SKIP = {"wall_seconds", "total_seconds", "seconds_per_evaluation", "seconds_per_step", "phases", "cpu_seconds", "total_cpu_seconds",
        "peak_rss_mb", "run_id", "version", "git", "git_hash", "command_line", "build", "threads"}
# Integer counts that must match exactly (booleans and strings must match exactly too).
EXACT = {"steps", "rhs_evaluations", "rejected_steps", "stages_max", "spectral_radius_evaluations",
         "newton", "rotation_cg", "mass_cg", "rotation_fresh_starts", "elements", "nodes", "fmm_order", "fmm_leaf_size"}


def cases(root):
    for scene in sorted((root / "scenes").glob("*.toml")):
        yield scene.stem, [str(scene), "--set", "time.t_end=0.3"]
    yield "builtin", ["--set", "time.t_end=2"]


def run(exe, outdir, only=()):
    root = pathlib.Path(__file__).resolve().parents[2]
    outdir = pathlib.Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    for name, args in cases(root):
        if only and name not in only:
            continue
        cmd = [exe, "run", *args, "-o", str(outdir / name), "--overwrite", "--threads", "1"]
        print(" ".join(cmd), flush=True)
        rc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode
        print(f"  exit {rc}", flush=True)


MAX_REL = [0.0]  # the largest relative difference seen among the compared floats


def compare_values(a, b, path, problems):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k in SKIP or k.endswith("_seconds"):  # every duration measures the machine
                continue
            if k not in a or k not in b:
                problems.append(f"{path}/{k}: only in {'B' if k not in a else 'A'}")
                continue
            compare_values(a[k], b[k], f"{path}/{k}", problems)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            problems.append(f"{path}: lengths {len(a)} and {len(b)}")
        for i, (x, y) in enumerate(zip(a, b)):
            compare_values(x, y, f"{path}[{i}]", problems)
    elif isinstance(a, bool) or isinstance(b, bool) or isinstance(a, str) or isinstance(b, str) or a is None:
        if a != b:
            problems.append(f"{path}: {a!r} != {b!r}")
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)):
        key = path.rsplit("/", 1)[-1]
        if key in EXACT or (isinstance(a, int) and isinstance(b, int)):
            if a != b:
                problems.append(f"{path}: {a} != {b} (exact)")
        elif not (a == b or (math.isnan(a) and math.isnan(b))):
            rel = abs(a - b) / max(abs(a), abs(b))
            MAX_REL[0] = max(MAX_REL[0], rel)
            if rel > REL_TOL:
                problems.append(f"{path}: {a!r} != {b!r} (rel {rel:.1e})")
    elif a != b:
        problems.append(f"{path}: {a!r} != {b!r}")


def expected(problem, expect):
    """A difference at a key the change is meant to alter: '/scene/time/scheme: ...' for --expect scene/time/scheme."""
    where = problem.split(":", 1)[0].lstrip("/")
    return any(where == e or where.startswith(e + "/") or where.startswith(e + "[") for e in expect)


def compare(dir_a, dir_b, expect=()):
    bad = 0
    names = sorted({d.name for d in pathlib.Path(dir_a).iterdir() if d.is_dir()} |
                   {d.name for d in pathlib.Path(dir_b).iterdir() if d.is_dir()})
    for name in names:
        fa, fb = pathlib.Path(dir_a, name, "summary.json"), pathlib.Path(dir_b, name, "summary.json")
        if not fa.exists() or not fb.exists():
            print(f"{name}: missing summary.json ({fa.exists()=}, {fb.exists()=})")
            bad += 1
            continue
        problems = []
        compare_values(json.loads(fa.read_text()), json.loads(fb.read_text()), "", problems)
        meant = [p for p in problems if expected(p, expect)]
        problems = [p for p in problems if not expected(p, expect)]
        sa = json.loads(fa.read_text())
        print(f"{name}: {'same' if not problems else 'DIFFERENT'} (stop {sa['stop_reason']}, t {sa['t']:g}, "
              f"{sa['steps']} steps, {sa['rhs_evaluations']} evaluations)")
        for p in meant:
            print("    expected:", p)
        for p in problems:
            print("   ", p)
        bad += bool(problems)
    print(f"{bad} of the runs differ; largest relative difference of a float: {MAX_REL[0]:.1e}")
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) >= 4 and sys.argv[1] == "run":
        run(sys.argv[2], sys.argv[3], sys.argv[4:])
    elif len(sys.argv) >= 4 and sys.argv[1] == "compare":
        args, expect = sys.argv[2:], []
        while "--expect" in args:
            i = args.index("--expect")
            expect.append(args[i + 1].strip("/"))
            del args[i:i + 2]
        sys.exit(compare(args[0], args[1], expect))
    else:
        sys.exit(__doc__)
