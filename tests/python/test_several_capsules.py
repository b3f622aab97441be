"""RunFolder's capsule readers (capsules, capsule_timeseries, capsule_triangles, capsule_positions,
capsule_field) on folders the command line wrote: a pair of capsules and a single capsule of the
same scene. Values are checked against the CSV text, the union mesh and summary.json."""
import csv

import numpy as np
import pytest

import capsflow
from conftest import run_cli

# Level-2 spheres (162 nodes, 320 triangles each), Skalak membrane in simple shear, to γ̇t = 0.5:
# about a second. The pair is point-symmetric: capsule 1 at (2, −0.25, 0), capsule 2 at (−2, 0.25, 0).
SCENE = """
[mesh]
base = "icosahedron"
level = 2
shape = "sphere"

[wall]
model = "membrane"
law = "skalak"
skalak_c = 1

[flow]
type = "simple_shear"
ca_s = 0.05

[time]
t_end = 0.5

[output]
every = 0.1
fields = ["velocity", "load"]
"""
PAIR = SCENE + """
[layout]
count = 2
dx = -4
dy = 0.5
"""
NODES, ELEMENTS = 162, 320  # per capsule


def run_scene(exe, tmp_path_factory, name: str, text: str):
    folder = tmp_path_factory.mktemp(name)
    scene = folder / "scene.toml"
    scene.write_text(text, encoding="utf-8")
    run_cli(exe, "run", scene, "-o", folder / "out")
    return folder / "out"


@pytest.fixture(scope="module")
def pair_run(capsflow_exe, tmp_path_factory) -> capsflow.RunFolder:
    return capsflow.read_run(run_scene(capsflow_exe, tmp_path_factory, "pair", PAIR))


@pytest.fixture(scope="module")
def single_run(capsflow_exe, tmp_path_factory) -> capsflow.RunFolder:
    return capsflow.read_run(run_scene(capsflow_exe, tmp_path_factory, "single", SCENE))


def enclosed_volume(x: np.ndarray, tri: np.ndarray) -> float:
    """Volume of a closed, outward-oriented triangulated surface (divergence theorem)."""
    a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


def csv_column(folder, name: str) -> np.ndarray:
    """A column of timeseries.csv, read from the text here rather than by the package."""
    with open(folder / "timeseries.csv", newline="", encoding="utf-8") as f:
        return np.array([float(row[name]) for row in csv.DictReader(f)])


def test_pair_counts_and_columns(pair_run):
    assert pair_run.stop_reason == "t_end"
    assert pair_run.capsules == 2 == pair_run.metadata["capsules"] == len(pair_run.summary["capsules"])
    ts2 = pair_run.capsule_timeseries(2)
    assert np.array_equal(ts2["D12"], csv_column(pair_run.folder, "c2.D12"))
    assert np.array_equal(pair_run.capsule_timeseries(1)["centroid1"], csv_column(pair_run.folder, "c1.centroid1"))
    # every c2. column, and nothing else: no prefix left, none of the run's columns
    expected = {name[3:] for name in pair_run.timeseries if name.startswith("c2.")}
    assert set(ts2) == expected and "t" not in ts2 and "surface_gap" not in ts2
    assert len(ts2["D12"]) == len(pair_run.timeseries["t"])
    # the arrays are copies: changing one changes neither the folder's series nor a later read
    ts2["D12"][:] = 7
    assert not np.any(pair_run.timeseries["c2.D12"] == 7)
    # summary.json's capsule entries are the last row of each capsule's series
    for k in (1, 2):
        assert pair_run.summary["capsules"][k - 1]["D12"] == pair_run.capsule_timeseries(k)["D12"][-1]


def test_pair_mesh_rows(pair_run):
    run = pair_run
    s = run.summary
    assert s["nodes"] == 2 * NODES and s["elements"] == 2 * ELEMENTS
    tri = run.triangles
    for step in (0, 1, -1):
        parts = [run.capsule_positions(k, step) for k in (1, 2)]
        assert [p.shape for p in parts] == [(NODES, 3), (NODES, 3)]
        # the capsules' rows, in order, are the union's rows
        assert np.array_equal(np.vstack(parts), run.positions(step))
        velocity = [run.capsule_field("velocity", k, step) for k in (1, 2)]
        assert np.array_equal(np.vstack(velocity), run.field("velocity", step))
    assert np.array_equal(run.capsule_positions(2, 0), run.reference_positions[NODES:])
    for k in (1, 2):
        local = run.capsule_triangles(k)
        assert local.shape == (ELEMENTS, 3) and local.dtype == np.int32
        assert local.min() == 0 and local.max() == NODES - 1
        # local indices plus the capsule's first node are the union's triangles
        assert np.array_equal(local + (k - 1) * NODES, tri[(k - 1) * ELEMENTS:k * ELEMENTS])
        # each capsule's surface, closed on its own rows, encloses the volume its summary entry
        # reports (computed by the C++ code from the same positions: 1e-12 covers the summation order)
        x = run.capsule_positions(k)
        assert enclosed_volume(x, local) == pytest.approx(s["capsules"][k - 1]["volume"], rel=1e-12)


def test_point_symmetric_pair(pair_run):
    # Simple shear u = γ̇ x2 e1 is odd under x → −x, and the layout puts capsule 2 at minus capsule 1's
    # centre, with the same (centrally symmetric) icosahedral mesh: x → −x maps the problem onto
    # itself with capsule 1 and 2 exchanged. So D12 (quadratic in x) is the same for both and the
    # centroids are opposite, exactly in exact arithmetic. The floating-point sums over the two
    # capsules run in different orders, so the two differ by rounding accumulated over the run's
    # steps (about 1e-15 here); 1e-10 leaves room for that on other machines and thread counts and is
    # far below any physical difference (the pair's interaction changes D12 by 2e-3 from the single
    # capsule's by γ̇t = 0.5).
    ts1, ts2 = pair_run.capsule_timeseries(1), pair_run.capsule_timeseries(2)
    np.testing.assert_allclose(ts1["D12"], ts2["D12"], rtol=0, atol=1e-10)
    for i in (1, 2, 3):
        np.testing.assert_allclose(ts1[f"centroid{i}"], -ts2[f"centroid{i}"], rtol=0, atol=1e-10)
    assert ts1["centroid1"][0] == pytest.approx(2) and ts2["centroid1"][0] == pytest.approx(-2)
    # the stored surfaces too: each capsule's node set is the other's reflected, so their means are
    # opposite (to rounding as above)
    x1, x2 = pair_run.capsule_positions(1), pair_run.capsule_positions(2)
    np.testing.assert_allclose(x1.mean(axis=0), -x2.mean(axis=0), rtol=0, atol=1e-10)


def test_single_capsule(single_run, pair_run):
    run = single_run
    assert run.capsules == 1 == run.metadata["capsules"]
    assert np.array_equal(run.capsule_triangles(1), run.triangles)
    assert np.array_equal(run.capsule_positions(1), run.positions())
    assert np.array_equal(run.capsule_positions(1, 0), run.reference_positions)
    assert np.array_equal(run.capsule_field("load", 1, 2), run.field("load", 2))
    ts = run.capsule_timeseries(1)
    assert np.array_equal(ts["D12"], csv_column(run.folder, "D12"))
    # the capsule's columns are those a capsule of a pair has, unprefixed (but its velocity, which a
    # one-capsule run does not compute); the run's are left out
    assert set(ts) == set(pair_run.capsule_timeseries(1)) - {"velocity1", "velocity2", "velocity3"}
    assert not {"t", "step", "dt", "steady_measure", "wall_seconds"} & set(ts)
    # the one-capsule layout keeps its top-level summary keys next to the `capsules` list
    assert run.summary["D12"] == run.summary["capsules"][0]["D12"] == ts["D12"][-1]


@pytest.mark.parametrize("k", [0, 3, -1])
def test_pair_bad_capsule_numbers(pair_run, k):
    for read in (pair_run.capsule_timeseries, pair_run.capsule_triangles, pair_run.capsule_positions,
                 lambda k: pair_run.capsule_field("velocity", k)):
        with pytest.raises(ValueError, match=rf"no capsule k={k}: the run has 2 capsules, numbered 1 … 2"):
            read(k)


def test_single_bad_capsule_numbers(single_run):
    with pytest.raises(ValueError, match=r"no capsule k=2: the run has 1 capsule, numbered 1 … 1"):
        single_run.capsule_positions(2)
    with pytest.raises(TypeError, match=r"capsule number k=1.0 is not an integer"):
        single_run.capsule_timeseries(1.0)
    with pytest.raises(TypeError, match=r"capsule number k=True is not an integer"):
        single_run.capsule_triangles(True)
