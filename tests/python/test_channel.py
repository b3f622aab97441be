"""A capsule in a channel seen from Python: capsflow.Scene reads and sets the [channel] keys and
describes the wall (info), and
read_run gives the run's speed U/V, added pressure drop and wall gap (docs/channel.md §5) as the
command line wrote them (the CSV text and summary.json read here directly)."""
import csv
import json

import numpy as np

import capsflow
from conftest import run_cli

# An 80-element Skalak sphere in a tube of radius 1.6, to t = 0.1 ℓ/V: a few seconds.
SCENE = """
[mesh]
base = "icosahedron"
level = 1
shape = "sphere"

[wall]
model = "membrane"
law = "skalak"

[flow]
type = "poiseuille"
ca_s = 0.05

[time]
t_end = 0.1

[output]
every = 0.05

[channel]
shape = "tube"
radius = 1.6
length = 9
element_size = 0.4
"""


def test_scene_keys_round_trip(tmp_path):
    path = tmp_path / "tube.toml"
    path.write_text(SCENE, encoding="utf-8")
    scene = capsflow.Scene(path)
    channel = scene.to_dict()["channel"]
    assert channel == {"shape": "tube", "radius": 1.6, "length": 9.0, "element_size": 0.4,
                       # a constriction's keys, at their defaults (unused by a tube)
                       "constriction_height": 0.5, "constriction_width": 1.0, "constriction_length": 1.0,
                       "constriction_center": 2.0, "constriction_taper": "auto"}
    assert scene.copy().set("channel.radius", 2.0).get("channel.radius") == 2.0
    wall = scene.info()["channel"]  # the wall as the run builds it
    assert wall["wall_nodes"] > 0 and wall["element_size"] == 0.4


def test_run_reports_the_capsules_speed_and_pressure_drop(capsflow_exe, tmp_path):
    scene = tmp_path / "tube.toml"
    scene.write_text(SCENE, encoding="utf-8")
    run_cli(capsflow_exe, "run", scene, "-o", tmp_path / "out")
    run = capsflow.read_run(tmp_path / "out")
    with open(tmp_path / "out" / "timeseries.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    for name in ("velocity_ratio", "pressure_drop", "rear_curvature", "wall_gap"):
        assert np.array_equal(run.timeseries[name], np.array([float(r[name]) for r in rows])), name
    summary = json.loads((tmp_path / "out" / "summary.json").read_text(encoding="utf-8"))
    assert run.summary["velocity_ratio"] == summary["velocity_ratio"] == summary["channel"]["velocity_ratio"]
    # Confined, slower than Poiseuille's mean over the unconfined sphere (2(1 − 2/(5·1.6²)) = 1.69)
    # and faster than the mean flow.
    assert 1.0 < run.summary["velocity_ratio"] < 1.69
    assert run.summary["channel"]["wall_nodes"] > 0
