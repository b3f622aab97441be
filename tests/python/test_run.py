"""capsflow.run and capsflow.Simulation against the command line: the same folder and summary.json,
stepping and checkpoint/restart equivalent to one run, Ctrl-C and the progress callback, the
exceptions (ValueError, OSError, SolverError) and the argument checks.

Every run is small: the built-in scene (GSMB, RKC) at level 2 (320 elements) to γ̇t = 0.3, one
thread, well under a second each.

Tolerance of "the same numbers": 1e-13 relative. Python and the command line run the same
compiled library code on the same scene with one thread (no reduction order depends on the
schedule), so the numbers are expected to be bit-identical; 1e-13 is the bound the driver's
same-numbers check (perf/same_numbers) uses for "the same computation", a few hundred ulp, far
below any change of the physics (a changed step or iteration count moves D12 by > 1e-8).
"""
import json
import math
import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

import capsflow
from conftest import run_cli

SAME = 1e-13  # relative; see the module docstring

# Values of the machine, not of the computation: they differ between any two runs.
MACHINE_KEYS = {"wall_seconds", "peak_rss_mb", "run_id", "timing"}

# Numerical stops: the command line's exit code 3 (driver/stop_reason.hpp, docs/scene-and-output.md §3).
EXIT_3_REASONS = ("blow_up", "solver_failure", "no_progress", "mesh_scale_buckling", "unresolved_folds",
                  "element_quality", "no_equilibrium")

SMALL = {"mesh.level": 2, "time.t_end": 0.3}


def small_scene(**more) -> capsflow.Scene:
    scene = capsflow.Scene()
    for key, value in {**SMALL, **{k.replace("__", "."): v for k, v in more.items()}}.items():
        scene.set(key, value)
    return scene


def cli_sets(**more) -> list:
    args = []
    for key, value in {**SMALL, **{k.replace("__", "."): v for k, v in more.items()}}.items():
        args += ["--set", f"{key}={value}"]
    return args


def assert_same_json(a, b, path="summary", skip=()):
    """Equal structure, equal ints, strings and bools; floats within SAME relative (NaN = NaN).
    The summary's MACHINE_KEYS and `skip` are not compared."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), f"{path}: keys differ: {set(a) ^ set(b)}"
        for k in a:
            if path == "summary" and (k in MACHINE_KEYS or k in skip):
                continue
            assert_same_json(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: lengths differ"
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same_json(x, y, f"{path}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        if math.isnan(a) and math.isnan(b):
            return
        assert a == pytest.approx(b, rel=SAME, abs=1e-300), f"{path}: {a!r} != {b!r}"
    else:
        assert a == b and type(a) is type(b), f"{path}: {a!r} != {b!r}"


def summary(folder) -> dict:
    return json.loads((Path(folder) / "summary.json").read_text())


def test_run_writes_what_the_command_line_writes(capsflow_exe, tmp_path):
    fields = ["velocity", "load"]
    run_cli(capsflow_exe, "run", *cli_sets(), "--set", 'output.fields=["velocity","load"]', "--threads", "1",
            "-o", tmp_path / "cli")
    result = capsflow.run(small_scene(output__fields=fields), tmp_path / "py", threads=1, log=False)
    assert isinstance(result, capsflow.RunFolder) and Path(result.folder) == tmp_path / "py"
    cli = summary(tmp_path / "cli")
    assert result.summary == summary(tmp_path / "py")  # the result is the folder, read back
    assert_same_json(result.summary, cli)
    assert result.stop_reason == "t_end"
    # The same files (names; run.h5's content below).
    assert sorted(p.name for p in (tmp_path / "py").iterdir()) == sorted(p.name for p in (tmp_path / "cli").iterdir())
    # The time series, every column (floats of the same computation: SAME).
    ts_cli = capsflow.read_run(tmp_path / "cli").timeseries
    assert set(result.timeseries) == set(ts_cli)
    for name, column in ts_cli.items():
        if name in ("wall_seconds",):
            continue
        np.testing.assert_allclose(result.timeseries[name], column, rtol=SAME, atol=0, equal_nan=True, err_msg=name)
    # The stored states and fields of run.h5.
    cli_run = capsflow.read_run(tmp_path / "cli")
    assert np.array_equal(result.times, cli_run.times)
    for k in (0, -1):
        for name in ("positions", "velocity", "load"):
            np.testing.assert_allclose(result.field(name, k), cli_run.field(name, k), rtol=SAME, atol=1e-300)


def test_the_folder_restarts_with_the_command_line(capsflow_exe, tmp_path):
    capsflow.run(small_scene(), tmp_path / "py", log=False)
    run_cli(capsflow_exe, "run", "--restart", tmp_path / "py", "--set", "time.t_end=0.4", "--threads", "1")
    s = summary(tmp_path / "py")
    # continued in its own folder to the new end (times land exactly on t_end: 1e-12 for rounding)
    assert s["stop_reason"] == "t_end" and s["t"] == pytest.approx(0.4, abs=1e-12)


def test_stepping_is_the_run(tmp_path):
    whole = capsflow.run(small_scene(), tmp_path / "run", threads=1, log=False)
    times = []
    with capsflow.Simulation(small_scene(), tmp_path / "steps", threads=1, log=False) as sim:
        assert sim.t == 0 and sim.steps == 0 and sim.stop_reason is None
        while (reason := sim.step()) is None:
            times.append(sim.t)
        assert reason == "t_end" and sim.stop_reason == "t_end"
        assert sim.step() == "t_end"  # a stopped run stays stopped, and takes no step
        assert sim.steps == len(times) + 1
        # the state is the last stored one (run.h5 is written by other code: exactly equal)
        last_positions = sim.positions
    assert sim.finished and sim.result is not None
    assert_same_json(sim.result.summary, whole.summary)
    assert np.array_equal(last_positions, sim.result.positions(-1))
    assert all(b > a for a, b in zip(times, times[1:]))  # time moves forward at every accepted step


def test_attributes_views_and_copies(tmp_path):
    with capsflow.Simulation(small_scene(), tmp_path / "out", threads=1, log=False) as sim:
        ref = sim.reference_positions
        tri = sim.triangles
        n = ref.shape[0]
        assert ref.shape == (n, 3) and tri.shape[1] == 3 and tri.dtype == np.int32
        # Euler's formula for a closed genus-0 triangulation: V − E + F = 2 with E = 3F/2
        assert n - 3 * tri.shape[0] // 2 + tri.shape[0] == 2
        assert not ref.flags.writeable and not tri.flags.writeable  # views of the reference: read-only
        with pytest.raises(ValueError):
            ref[0, 0] = 1.0
        assert np.array_equal(sim.positions, ref)  # t = 0: the reference state
        sim.step()
        x = sim.positions
        x[:] = 0  # a copy: the run's state is not changed
        assert not np.array_equal(sim.positions, x)
        v = sim.velocity()
        assert v.shape == (n, 3) and np.isfinite(v).all()
        # shear flow u = γ̇ y e_x with a freely suspended capsule: the mean node velocity's x
        # component has the sign of the mean y, which is 0 by symmetry — but |v| is nonzero
        assert np.abs(v).max() > 0
        assert sim.load.shape == (n, 3)
        h = sim.health
        assert h["status"] == "ok" and h["active"] == []
        # the health columns are those of timeseries.csv (written by other code)
        header = (tmp_path / "out" / "timeseries.csv").read_text().splitlines()[0].split(",")
        assert h["columns"] and set(h["columns"]) <= set(header)
        assert isinstance(h["summary"], dict)
        assert sim.dt > 0 and sim.rhs_evaluations > 0 and Path(sim.folder) == tmp_path / "out"
    with pytest.raises(RuntimeError, match="finished"):
        sim.step()


def test_checkpoint_and_restart_continue_the_run(capsflow_exe, tmp_path):
    checkpoint = tmp_path / "mid.h5"
    with capsflow.Simulation(small_scene(), tmp_path / "whole", threads=1, log=False) as sim:
        for _ in range(2):  # of 4 (ROCK4, the default on this wall and mesh)
            assert sim.step() is None
        t_mid = sim.t
        sim.checkpoint(checkpoint)
        while sim.step() is None:
            pass
    whole = sim.result.summary
    # From Python, into a new folder: every value the same but the count of evaluations, which
    # counts work — the restart evaluates the right-hand side at the checkpoint's state again.
    again = capsflow.run(None, tmp_path / "py", restart=checkpoint, threads=1, log=False)
    assert_same_json(again.summary, whole, skip=("rhs_evaluations",))
    assert again.summary["rhs_evaluations"] >= whole["rhs_evaluations"]
    assert again.timeseries["t"][0] == t_mid  # the new folder starts at the checkpoint (stored exactly)
    # From the command line: the same.
    run_cli(capsflow_exe, "run", "--restart", checkpoint, "-o", tmp_path / "cli", "--threads", "1")
    assert_same_json(summary(tmp_path / "cli"), again.summary)


def test_a_restart_may_change_keys(tmp_path):
    capsflow.run(small_scene(), tmp_path / "a", log=False)
    result = capsflow.run(None, None, restart=tmp_path / "a", overrides={"time.t_end": 0.4}, log=False)
    assert Path(result.folder) == tmp_path / "a"  # out=None: the checkpoint's own folder
    assert result.summary["t"] == pytest.approx(0.4, abs=1e-12)  # output times are landed on exactly


def test_a_numerical_stop_is_a_solver_error(capsflow_exe, tmp_path):
    # Heun with a fixed step 5× its stability limit on this mesh blows up within a few steps.
    unstable = dict(time__scheme="heun", time__dt=0.05, time__t_end=2)
    cli = run_cli(capsflow_exe, "run", *cli_sets(**unstable), "--threads", "1", "-o", tmp_path / "cli", check=False)
    assert cli.returncode == 3, cli.stderr
    with pytest.raises(capsflow.SolverError) as e:
        capsflow.run(small_scene(**unstable), tmp_path / "py", threads=1, log=False)
    assert e.value.stop_reason.split(":")[0] in EXIT_3_REASONS
    assert e.value.stop_reason == summary(tmp_path / "cli")["stop_reason"]
    # the folder is complete: summary and checkpoint written (last healthy state)
    assert e.value.run.stop_reason == e.value.stop_reason
    assert (tmp_path / "py" / "checkpoint.h5").is_file()
    assert isinstance(e.value, RuntimeError)
    # step by step: step() returns the reason, finish() raises
    sim = capsflow.Simulation(small_scene(**unstable), tmp_path / "steps", threads=1, log=False)
    while (reason := sim.step()) is None:
        pass
    assert reason == e.value.stop_reason
    with pytest.raises(capsflow.SolverError):
        sim.finish()
    assert sim.finished


def test_bad_input_is_a_value_error_with_the_command_lines_message(capsflow_exe, tmp_path):
    capsflow.run(small_scene(), tmp_path / "a", log=False)
    # a restart may not change the mesh: the command line's refusal, word for word
    cli = run_cli(capsflow_exe, "run", "--restart", tmp_path / "a", "--set", "mesh.level=3", check=False)
    assert cli.returncode == 1
    message = cli.stderr.strip().splitlines()[-1].removeprefix("capsflow: error: ")
    with pytest.raises(ValueError) as e:
        capsflow.run(None, None, restart=tmp_path / "a", overrides={"mesh.level": 3}, log=False)
    assert str(e.value) == message and "\n" not in message
    # an unknown key in the overrides: --set's message
    cli = run_cli(capsflow_exe, "run", "--restart", tmp_path / "a", "--set", "mesh.nope=3", check=False)
    message = cli.stderr.strip().splitlines()[-1].removeprefix("capsflow: error: ")
    with pytest.raises(ValueError) as e:
        capsflow.run(None, None, restart=tmp_path / "a", overrides={"mesh.nope": 3}, log=False)
    assert str(e.value) == message
    assert summary(tmp_path / "a")["t"] == pytest.approx(0.3, abs=1e-12)  # the refused restarts changed nothing


def test_files_are_os_errors(capsflow_exe, tmp_path):
    busy = tmp_path / "busy"
    busy.mkdir()
    (busy / "notes.txt").write_text("mine")
    cli = run_cli(capsflow_exe, "run", *cli_sets(), "-o", busy, check=False)
    assert cli.returncode == 1
    message = cli.stderr.strip().splitlines()[-1].removeprefix("capsflow: error: ")
    with pytest.raises(OSError) as e:
        capsflow.run(small_scene(), busy, log=False)
    assert str(e.value) == message
    assert sorted(p.name for p in busy.iterdir()) == ["notes.txt"]  # nothing was written
    with pytest.raises(OSError):
        capsflow.run(None, tmp_path / "new", restart=tmp_path / "no-such-checkpoint.h5", log=False)


def test_argument_checks(tmp_path):
    scene = small_scene()
    out = tmp_path / "never"
    with pytest.raises(TypeError, match="capsflow.Scene"):
        capsflow.run({"mesh": {"level": 2}}, out)
    with pytest.raises(TypeError, match="path"):
        capsflow.run(scene, 3)
    with pytest.raises(ValueError, match="empty"):
        capsflow.run(scene, "")
    with pytest.raises(TypeError, match="callable"):
        capsflow.run(scene, out, progress="print")
    with pytest.raises(ValueError, match="threads = 0"):
        capsflow.run(scene, out, threads=0)
    with pytest.raises(TypeError, match="threads"):
        capsflow.run(scene, out, threads=1.5)
    with pytest.raises(TypeError, match="overwrite"):
        capsflow.run(scene, out, overwrite="yes")
    with pytest.raises(ValueError, match="progress_interval"):
        capsflow.run(scene, out, progress_interval=float("nan"))
    with pytest.raises(ValueError, match="restart takes the scene"):
        capsflow.run(scene, out, restart=tmp_path / "x.h5")
    with pytest.raises(ValueError, match="overwrite"):
        capsflow.run(None, out, overwrite=True, restart=tmp_path / "x.h5")
    with pytest.raises(ValueError, match="overrides are for a restart"):
        capsflow.run(scene, out, overrides={"time.t_end": 1})
    with pytest.raises(ValueError, match="log"):
        capsflow.run(scene, out, log="loud")
    assert not out.exists()  # every refusal came before anything was written


def test_progress_at_every_status_line(tmp_path):
    seen = []
    result = capsflow.run(small_scene(), tmp_path / "out", progress=seen.append, progress_interval=0, log=False)
    # interval 0: a status line after every accepted step, and one at the end (finish)
    assert len(seen) == result.summary["steps"] + 1
    assert [p.step for p in seen[:-1]] == list(range(1, len(seen)))
    assert all(isinstance(p, capsflow.Progress) and p.t_end == 0.3 for p in seen)
    assert seen[-1].t == result.summary["t"] and seen[-1].rhs_evaluations == result.summary["rhs_evaluations"]
    assert all(b.t > a.t for a, b in zip(seen[:-2], seen[1:-1]))
    # the default interval (2 s of wall time): at least the closing line
    fewer = []
    capsflow.run(small_scene(), tmp_path / "default", progress=fewer.append, log=False)
    assert 1 <= len(fewer) <= len(seen)


def test_keyboard_interrupt_from_the_progress_callback(capsflow_exe, tmp_path):
    def interrupt_at_step_3(p):
        if p.step == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        capsflow.run(small_scene(), tmp_path / "out", progress=interrupt_at_step_3, progress_interval=0, threads=1,
                     log=False)
    s = summary(tmp_path / "out")
    # the callback runs after step 3's status line; the stop request is honoured before step 4
    assert s["stop_reason"] == "interrupted" and s["steps"] == 3
    assert (tmp_path / "out" / "checkpoint.h5").is_file()
    # the command line continues it to the same end as an uninterrupted run
    run_cli(capsflow_exe, "run", "--restart", tmp_path / "out", "--threads", "1")
    whole = capsflow.run(small_scene(), tmp_path / "whole", threads=1, log=False)
    continued = summary(tmp_path / "out")
    for key in ("t", "steps", "D12", "D13", "D23", "L", "Le", "volume", "volume_drift", "steady_measure"):
        assert_same_json(continued[key], whole.summary[key], key)


def test_any_exception_of_the_callback_stops_the_run_and_goes_on(tmp_path):
    def fail(p):
        raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError, match="from the callback"):
        capsflow.run(small_scene(), tmp_path / "out", progress=fail, progress_interval=0, log=False)
    s = summary(tmp_path / "out")
    assert s["stop_reason"] == "interrupted" and s["steps"] == 1


def test_sigint_stops_a_run_as_on_the_command_line(tmp_path):
    # A long run (t_end 1000, hours at this size) that a SIGINT sent by another thread, while C++
    # computes with the GIL released, stops: Python's own handler sets the flag, the binding polls it.
    sent = threading.Event()

    def send_sigint_once(p):
        if not sent.is_set():
            sent.set()
            threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGINT)).start()

    with pytest.raises(KeyboardInterrupt):
        capsflow.run(small_scene(time__t_end=1000), tmp_path / "out", progress=send_sigint_once, progress_interval=0,
                     threads=1, log=False)
    s = summary(tmp_path / "out")
    assert sent.is_set() and s["stop_reason"] == "interrupted" and s["t"] < 1000
    assert (tmp_path / "out" / "checkpoint.h5").is_file()


def test_an_exception_in_a_with_block_stops_the_run_as_interrupted(tmp_path):
    with pytest.raises(LookupError, match="mine"):
        with capsflow.Simulation(small_scene(), tmp_path / "out", log=False) as sim:
            sim.step()
            sim.step()
            raise LookupError("mine")
    s = summary(tmp_path / "out")
    assert s["stop_reason"] == "interrupted" and s["steps"] == 2
    assert sim.finished and sim.result.stop_reason == "interrupted"
    # finish() before the end stops the run the same way, and it can be continued
    sim = capsflow.Simulation(small_scene(), tmp_path / "early", log=False)
    sim.step()
    assert sim.finish().stop_reason == "interrupted"
    assert capsflow.run(None, None, restart=tmp_path / "early", log=False).stop_reason == "t_end"


def test_request_stop_ends_the_run_as_interrupted(tmp_path):
    sim = capsflow.Simulation(small_scene(), tmp_path / "out", log=False)
    assert sim.step() is None
    sim.request_stop()
    assert sim.step() == "interrupted" and sim.steps == 1  # the request is honoured before any attempt
    assert sim.finish().summary["stop_reason"] == "interrupted"


def test_the_log_is_the_command_lines_or_silent(capfd, tmp_path):
    capsflow.run(small_scene(), tmp_path / "loud", log=True)
    out = capfd.readouterr().out
    assert "stopped: t_end" in out and "D12" in out  # the command line's closing lines, from C++ on stdout
    capsflow.run(small_scene(), tmp_path / "quiet", log=False)
    assert capfd.readouterr().out == ""
    capsflow.run(small_scene(), tmp_path / "loud again")  # the level is restored after log=False
    assert "stopped: t_end" in capfd.readouterr().out


def test_the_progress_callback_cannot_reenter_the_run(tmp_path):
    # A callback that finishes the run it reports on (even guarded by `not sim.finished`, which is
    # still False while finish() runs) called finish() from finish()'s own closing status line,
    # again and again: a RecursionError, or (with a higher recursion limit, or deeper frames) a
    # segfault mid-checkpoint that left checkpoint.h5.tmp.PID behind. It runs in a child
    # interpreter, so that a crash fails this test and no other.
    script = f"""
import capsflow
scene = capsflow.Scene().set("mesh.level", 2).set("time.t_end", 0.3)
sim = None
def finish_from_the_callback(p):
    if not sim.finished:
        sim.finish()
sim = capsflow.Simulation(scene, {str(tmp_path / 'out')!r}, progress=finish_from_the_callback, progress_interval=0,
                          threads=1, log=False)
try:
    while sim.step() is None:
        pass
    print("step: no error")
except RuntimeError as e:
    print("step:", e)
try:
    sim.finish()
    print("finish: no error")
except RuntimeError as e:
    print("finish:", e)
print("finished:", sim.finished, sim.stop_reason)
"""
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, f"exit {p.returncode}\n{p.stdout}\n{p.stderr}"
    refusal = "finish() cannot be called from the progress callback"
    lines = p.stdout.splitlines()
    # The callback of step 1 is refused; that exception stops the run as interrupted (as any
    # exception of the callback does) and step() raises it.
    assert lines[0].startswith("step: " + refusal), p.stdout
    # finish() then completes the folder; the callback of its closing line is refused too, and
    # that refusal is raised once the folder is complete.
    assert lines[1].startswith("finish: " + refusal), p.stdout
    assert lines[2] == "finished: True interrupted", p.stdout
    s = summary(tmp_path / "out")
    assert s["stop_reason"] == "interrupted" and s["steps"] == 1
    capsflow.read_run(tmp_path / "out")  # the folder reads back
    assert sorted(f.name for f in (tmp_path / "out").iterdir() if ".tmp." in f.name) == []


def test_a_checkpoint_never_replaces_the_runs_own_files_nor_writes_into_a_locked_folder(tmp_path):
    own = tmp_path / "ck"
    with capsflow.Simulation(small_scene(), own, threads=1, log=False) as sim:
        assert sim.step() is None
        before = {f.name: f.read_bytes() for f in own.iterdir()}
        # Every name the run writes (or holds: the lock file), given directly, relatively and
        # through a symbolic link to the folder: refused, nothing written.
        (tmp_path / "link").symlink_to(own)
        names = ("run.h5", "run.xmf", "timeseries.csv", "summary.json", "checkpoint.h5", "checkpoint.prev.h5",
                 ".capsflow.lock")
        for name in names:
            for path in (own / name, os.path.relpath(own / name), tmp_path / "link" / name):
                with pytest.raises(ValueError, match=f"^checkpoint path '.*' is this run's own {name} in "):
                    sim.checkpoint(path)
        assert {f.name: f.read_bytes() for f in own.iterdir()} == before
        # Another run's folder, locked while that run lives (here in this process: the lock is
        # per open file, so this run's probe sees it as any other process's).
        other = capsflow.Simulation(small_scene(), tmp_path / "other", threads=1, log=False)
        with pytest.raises(OSError, match=f"^checkpoint path '.*mine.h5': its folder .* is in use by pid {os.getpid()} "):
            sim.checkpoint(tmp_path / "other" / "mine.h5")
        assert not (tmp_path / "other" / "mine.h5").exists()
        other.finish()  # releases its folder
        # Names of the user's own are the user's to choose.
        sim.checkpoint(own / "mine.h5")
        sim.checkpoint(tmp_path / "other" / "mine.h5")
        while sim.step() is None:
            pass
    assert sim.result.stop_reason == "t_end"
    for path in (own / "mine.h5", tmp_path / "other" / "mine.h5"):
        assert capsflow.run(None, tmp_path / ("from-" + path.parent.name), restart=path, log=False).stop_reason == "t_end"


def test_a_thread_count_the_machine_cannot_take_is_a_value_error_not_the_end_of_the_interpreter(tmp_path):
    # libgomp cannot report a thread it fails to start: it prints "Thread creation failed" and
    # calls exit(1), ending the interpreter. Under a 4 GB address-space limit, 4096 threads (8 MB
    # stacks: 32 GB) did that; the count is now refused first (at most 4 × the hardware threads,
    # docs/scene-and-output.md §1), before the folder is created. In a child interpreter, which
    # has the limit (and would die, not this one).
    out = tmp_path / "out"
    script = f"""
import numpy as np
import capsflow
scene = capsflow.Scene().set("mesh.level", 1).set("time.t_end", 0.02)
for call in (lambda: capsflow.Simulation(scene, {str(out)!r}, threads=4096, log=False),
             lambda: capsflow.run(scene, {str(out)!r}, threads=4096, log=False),
             lambda: capsflow.fmm.stokeslet_direct(np.zeros((2, 3)) + [[0, 0, 0], [1, 0, 0]], np.ones((2, 3)), threads=4096)):
    try:
        call()
        print("no error")
    except ValueError as e:
        print("ValueError:", e)
"""
    import resource

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (4_000_000_000, resource.RLIM_INFINITY))

    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300, preexec_fn=limit, env=env)
    assert p.returncode == 0, f"exit {p.returncode}\n{p.stdout}\n{p.stderr}"
    lines = p.stdout.splitlines()
    assert len(lines) == 3, p.stdout
    for line in lines:
        assert line.startswith("ValueError: threads = 4096: more than 4 × the "), p.stdout
    assert not out.exists()
