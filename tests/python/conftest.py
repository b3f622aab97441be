"""Shared fixtures of the Python tests: the capsflow executable, and small finished runs and studies
made with it (so that reading them checks the package against files the command line wrote).

ctest sets PYTHONPATH (the built package), CAPSFLOW_EXE and CAPSFLOW_CACHE_DIR; by hand:
    PYTHONPATH=build/python CAPSFLOW_EXE=build/bin/capsflow python3 -m pytest tests/python
"""
import os
import subprocess
from pathlib import Path

import pytest

SOURCE_DIR = Path(__file__).resolve().parents[2]

# A run of a second: the built-in scene (GSMB, RKC) at 320 elements to γ̇t = 0.3, velocity and
# load stored at the output times.
SMALL_RUN = ["--set", "mesh.level=2", "--set", "time.t_end=0.3", "--set", 'output.fields=["velocity","load"]']


@pytest.fixture(scope="module")
def capsflow_exe() -> Path:
    exe = Path(os.environ.get("CAPSFLOW_EXE", SOURCE_DIR / "build" / "bin" / "capsflow"))
    if not exe.is_file():
        pytest.fail(f"no capsflow executable at {exe} (set CAPSFLOW_EXE)")
    return exe


def run_cli(exe: Path, *args, check: bool = True) -> subprocess.CompletedProcess:
    """`capsflow ARGS...`, output captured; fails the test with the log on an unexpected exit code."""
    p = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True)
    if check and p.returncode != 0:
        pytest.fail(f"capsflow {' '.join(map(str, args))} exited {p.returncode}:\n{p.stdout}\n{p.stderr}")
    return p


@pytest.fixture(scope="module")
def finished_run(capsflow_exe, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("run") / "out"
    run_cli(capsflow_exe, "run", *SMALL_RUN, "-o", out)
    return out


@pytest.fixture(scope="module")
def finished_study(capsflow_exe, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("study") / "study"
    run_cli(capsflow_exe, "study", "--levels", "1,2,3", "--set", "time.t_end=0.2", "-o", out)
    return out
