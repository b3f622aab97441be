"""The scripts of examples/python run from a fresh interpreter, as a user would start them, and
draw their figures."""
import os
import subprocess
import sys

from conftest import SOURCE_DIR

EXAMPLES = SOURCE_DIR / "examples" / "python"


def run_example(name: str, *args) -> subprocess.CompletedProcess:
    env = dict(os.environ, MPLBACKEND="Agg")
    p = subprocess.run([sys.executable, str(EXAMPLES / name), *map(str, args)], capture_output=True, text=True, env=env)
    assert p.returncode == 0, p.stdout + p.stderr
    assert p.stderr == ""  # no warning either
    return p


def test_fmm_against_direct(tmp_path):
    png = tmp_path / "fmm.png"
    out = run_example("fmm_vs_direct.py", "--n", 3000, "--plot", png).stdout
    # one line per tolerance, each error within its tolerance (the script prints them)
    errors = [float(line.split("relative L2 error ")[1].split(",")[0]) for line in out.splitlines() if "error" in line]
    assert errors and all(e <= tol for e, tol in zip(errors, (1e-3, 1e-6, 1e-8)))
    assert png.stat().st_size > 10_000  # a figure, not an empty file
