"""read_run and read_study on folders the command line wrote: each value read is checked against
another file, or recomputed from the mesh, rather than against the reader's own output."""
import json
import math
import shutil

import numpy as np
import pytest

import capsflow


def enclosed_volume(x: np.ndarray, tri: np.ndarray) -> float:
    """Volume of a closed, outward-oriented triangulated surface (divergence theorem)."""
    a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


def test_a_finished_run(finished_run):
    run = capsflow.read_run(finished_run)
    s = run.summary
    assert s == json.loads((finished_run / "summary.json").read_text())
    assert run.stop_reason == "t_end"
    ts = run.timeseries
    # output.every = 0.1 to t_end = 0.3: rows at 0, 0.1, 0.2, 0.3 (docs/scene-and-output.md §3.4);
    # times are landed on exactly by the stepper, 1e-12 allows their accumulated rounding
    np.testing.assert_allclose(ts["t"], [0, 0.1, 0.2, 0.3], atol=1e-12)
    assert ts["step"][-1] == s["steps"]
    # the steady-state measure is undefined during the first unit of time: empty fields, read as NaN
    assert np.isnan(ts["steady_measure"]).all()
    # the CSV and run.h5 are written by different code: the same step times, exactly
    assert np.array_equal(run.times, ts["t"])
    x, tri = run.positions(), run.triangles
    assert x.shape == (s["nodes"], 3) and tri.shape == (s["elements"], 3) and tri.dtype == np.int32
    # the final volume recomputed from the stored surface: summary.json's to rounding (1e-12)
    assert enclosed_volume(x, tri) == pytest.approx(s["volume"], rel=1e-12)
    # the first step is the reference surface
    assert np.array_equal(run.positions(0), run.reference_positions)
    assert run.field("velocity", 1).shape == (s["nodes"], 3)
    meta = run.metadata
    assert meta["run_id"] == s["run_id"] and meta["mesh_hash"] == s["mesh_hash"]
    assert meta["scene_resolved"] == s["scene"]  # JSON text in run.h5, parsed
    assert meta["schema_version"] == 1


def test_missing_things_are_named(finished_run, tmp_path):
    run = capsflow.read_run(finished_run)
    with pytest.raises(KeyError, match=r"no field 'E_bending' \(stored: load, positions, velocity\)"):
        run.field("E_bending")
    with pytest.raises(FileNotFoundError, match="no run folder"):
        capsflow.read_run(tmp_path / "nowhere")
    with pytest.raises(FileNotFoundError, match="holds no run.h5: not a capsflow run folder"):
        capsflow.read_run(tmp_path)
    with pytest.raises(FileNotFoundError, match="holds no study.json"):
        capsflow.read_study(tmp_path)


def test_a_run_without_summary_is_still_readable(finished_run, tmp_path):
    # a running or killed run has no summary.json yet
    copy = tmp_path / "copy"
    shutil.copytree(finished_run, copy)
    (copy / "summary.json").unlink()
    run = capsflow.read_run(copy)
    assert run.summary is None and run.stop_reason is None
    assert len(run.timeseries["t"]) == 4


def test_a_finished_study(finished_study):
    study = capsflow.read_study(finished_study)
    assert [v["level"] for v in study.variants] == [1, 2, 3]
    assert all(v["state"] == "finished" for v in study.variants)
    row = study.final_row("D12")
    # each level's value in the study is the final D12 in that variant's own summary.json
    for v, value in zip(study.variants, row["values"]):
        assert study.run(v["name"]).summary["D12"] == value
    # the analysis of docs/scene-and-output.md §4.2, recomputed: p = log2(e1/e2), f* = f3 + e2/(2^p − 1)
    # (1e-12: the same few operations in another order)
    f1, f2, f3 = row["values"]
    p = math.log2((f2 - f1) / (f3 - f2))
    assert row["status"] == "asymptotic"
    assert row["order"] == pytest.approx(p, rel=1e-12)
    assert row["extrapolated"] == pytest.approx(f3 + (f3 - f2) / (2**p - 1), rel=1e-12)
    with pytest.raises(KeyError, match="no final row for 'D99'"):
        study.final_row("D99")
