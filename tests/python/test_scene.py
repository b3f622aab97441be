"""capsflow.Scene against the command line: the same resolved scene as `capsflow info`, and set()
refusing what --set refuses with the same one-line message."""
import numpy as np
import pytest

import capsflow
from conftest import SOURCE_DIR, run_cli


def cli_resolved_toml(exe, *args) -> str:
    """The resolved scene `capsflow info` prints: the lines after '# resolved scene (...)' up to
    the next '# ' heading."""
    out = run_cli(exe, "info", *args).stdout
    block = out.split("\n", 1)[1]
    return block.split("\n# ", 1)[0]


def cli_error(exe, *args) -> str:
    """The one-line message of `capsflow info ARGS` exiting 1 ('capsflow: error: ' removed)."""
    p = run_cli(exe, "info", *args, check=False)
    assert p.returncode == 1, p.stdout + p.stderr
    line = p.stderr.strip()
    assert line.startswith("capsflow: error: ") and "\n" not in line
    return line[len("capsflow: error: "):]


def test_the_default_scene_is_the_command_lines(capsflow_exe):
    assert capsflow.Scene().to_toml().strip() == cli_resolved_toml(capsflow_exe).strip()
    assert capsflow.Scene().source == "<built-in default>"


def test_a_file_with_sets_is_resolved_as_by_the_command_line(capsflow_exe):
    path = SOURCE_DIR / "scenes" / "sphere_simple_shear.toml"
    scene = capsflow.Scene(path).set("mesh.level", 2).set("wall.law", "nh").set("time.stop_on", ["element_quality"])
    cli = cli_resolved_toml(capsflow_exe, path, "--set", "mesh.level=2", "--set", "wall.law=nh",
                            "--set", 'time.stop_on=["element_quality"]')
    assert scene.to_toml().strip() == cli.strip()
    assert scene.get("mesh.level") == 2 and scene.get("wall.law") == "nh"
    assert scene.overrides == ["mesh.level=2", 'wall.law="nh"', 'time.stop_on=["element_quality"]']


@pytest.mark.parametrize("key, value, cli_value", [
    ("mesh.level", 12, "12"),
    ("mesh.levle", 3, "3"),
    ("meshes.level", 3, "3"),
    ("wall.law", "rubber", "rubber"),
    ("time.t_end", "soon", "soon"),
    ("time.t_end", -1.0, "-1.0"),
    ("flow.ca_s", float("inf"), "inf"),
    ("time.stop_on", ["no_such_condition"], '["no_such_condition"]'),
    ("level", 3, "3"),
])
def test_bad_sets_raise_the_command_lines_message(capsflow_exe, key, value, cli_value):
    scene = capsflow.Scene()
    before = scene.to_toml()
    with pytest.raises(ValueError) as e:
        scene.set(key, value)
    assert str(e.value) == cli_error(capsflow_exe, "--set", f"{key}={cli_value}")
    assert scene.to_toml() == before and scene.overrides == []  # unchanged


def test_python_values_become_toml_values():
    scene = capsflow.Scene()
    scene.set("time.stop_at_steady", True).set("flow.ca_s", np.float64(0.25)).set("mesh.level", np.int64(2))
    scene.set("output.fields", ["velocity", "load"]).set("time.dt", "auto")
    assert scene.get("time.stop_at_steady") is True
    assert scene.get("flow.ca_s") == 0.25 and scene.get("mesh.level") == 2
    assert scene.get("output.fields") == ["velocity", "load"]
    with pytest.raises(TypeError, match="a scene value must be a bool, number, string or list of them, got dict"):
        scene.set("mesh.level", {"a": 1})


def test_numpy_scalars_and_zero_dimensional_arrays_are_values():
    # docs/python.md: numpy scalars and arrays are values; a 0-d array was refused as no sequence.
    scene = capsflow.Scene()
    scene.set("time.t_end", np.array(0.5)).set("flow.ca_s", np.float32(0.25)).set("mesh.level", np.array(2))
    scene.set("time.stop_at_steady", np.bool_(False)).set("wall.law", np.str_("nh"))
    assert scene.get("time.t_end") == 0.5 and scene.get("flow.ca_s") == 0.25 and scene.get("mesh.level") == 2
    assert scene.get("time.stop_at_steady") is False and scene.get("wall.law") == "nh"
    assert scene.overrides[:3] == ["time.t_end=0.5", "flow.ca_s=0.25", "mesh.level=2"]


@pytest.mark.parametrize("key", ["time.t_end=0.5#", "time.t_end#", "time.t_end\nmesh.level", "time.t_end=1"])
def test_a_key_that_would_change_the_assignment_is_refused_naming_it(key):
    # 'time.t_end=0.5#' with 2 became the assignment time.t_end=0.5#=2, which TOML read as
    # t_end = 0.5 and a comment: a silent wrong value.
    scene = capsflow.Scene()
    before = scene.to_toml()
    with pytest.raises(ValueError) as e:
        scene.set(key, 2)
    message = str(e.value)
    assert message.startswith(f"scene key {key!r}: a key is 'section.key'") and "\n" not in message, message
    assert scene.to_toml() == before and scene.overrides == []
    with pytest.raises(ValueError, match="a key is 'section.key'"):  # the restart's overrides too
        capsflow.run(None, None, restart="never-read.h5", overrides={key: 2}, log=False)


def test_values_the_command_line_would_misread_are_refused_in_one_line(capsflow_exe):
    scene = capsflow.Scene()
    # An integer beyond 64 bits: "out of range", not "expected an integer, got a string".
    with pytest.raises(ValueError) as e:
        scene.set("mesh.level", 10**30)
    assert str(e.value) == "--set mesh.level: 1000000000000000000000000000000 is out of range: integers have at most " \
                           "64 bits (magnitude below 9.2e18)"
    assert str(e.value) == cli_error(capsflow_exe, "--set", f"mesh.level={10**30}")
    # A line break in a string value is escaped in the echo: one line.
    with pytest.raises(ValueError) as e:
        scene.set("wall.law", "nh\nskalak")
    assert "\n" not in str(e.value) and "nh\\nskalak" in str(e.value), str(e.value)
    # The command line's own --set with '#' or a line break in the value.
    assert cli_error(capsflow_exe, "--set", "time.t_end=0.5#x").startswith(
        "--set time.t_end: the value 0.5#x has a '#', which TOML reads as the start of a comment")
    assert cli_error(capsflow_exe, "--set", "time.t_end=1\nmesh.level=1") == \
        "--set time.t_end: the value 1\\nmesh.level=1 has a line break: one key per --set"


def test_a_dict_gives_the_keys_it_names_and_defaults_for_the_rest():
    scene = capsflow.Scene({"mesh": {"level": 2}, "flow": {"type": "simple_shear", "ca_s": 0.3}})
    assert scene.get("mesh.level") == 2 and scene.get("flow.ca_s") == 0.3 and scene.get("flow.type") == "simple_shear"
    assert scene.source == "<dict>"
    # the rest as in a file that gives only these keys
    text = '[mesh]\nlevel = 2\n[flow]\ntype = "simple_shear"\nca_s = 0.3\n'
    assert scene.to_dict() == capsflow.Scene.from_toml(text).to_dict()
    with pytest.raises(ValueError, match=r"<dict>:2: mesh\.levle: unknown key"):
        capsflow.Scene({"mesh": {"levle": 2}})
    with pytest.raises(TypeError, match=r"scene dict: \[mesh\] must be a dict of keys, got int"):
        capsflow.Scene({"mesh": 2})


def test_files_that_cannot_be_read_are_errors(tmp_path):
    with pytest.raises(ValueError, match="nowhere.toml: scene file not found"):
        capsflow.Scene(tmp_path / "nowhere.toml")
    with pytest.raises(TypeError, match="TOML text: Scene.from_toml"):
        capsflow.Scene(42)


def test_copies_are_independent():
    a = capsflow.Scene()
    b = a.copy().set("mesh.level", 2)
    assert a.get("mesh.level") == 3 and b.get("mesh.level") == 2


def test_every_key_is_documented_and_resolved():
    keys = capsflow.Scene.keys()
    resolved = capsflow.Scene().to_dict()
    # the key table and the resolved scene name the same keys (a key missing from either is a bug)
    assert {k["key"] for k in keys} == {f"{s}.{k}" for s, d in resolved.items() for k in d}
    assert all(k["meaning"] and k["type"] for k in keys)


def cli_report(exe, *args) -> dict:
    """`capsflow info ARGS`'s report lines after the resolved scene, as {label: rest of the line}."""
    out = run_cli(exe, "info", *args).stdout
    report = out.split("# reference mesh\n", 1)[1]
    return {line[:16].strip(): line[16:] for line in report.splitlines() if line and not line.startswith(("#", " "))}


def test_info_is_what_the_command_line_prints(capsflow_exe):
    path = SOURCE_DIR / "scenes" / "sphere_simple_shear.toml"
    scene = capsflow.Scene(path).set("mesh.level", 2)
    info = scene.info()
    cli = cli_report(capsflow_exe, path, "--set", "mesh.level=2")
    m, r = info["mesh"], info["run"]
    assert info["scene_toml"] == scene.to_toml() and info["source"] == scene.source
    # the printed values, at the precision printed
    assert cli["elements"] == str(m["elements"]) and cli["nodes"] == str(m["nodes"]) and cli["edges"] == str(m["edges"])
    assert cli["D12 D13 D23"].split() == [f"{m[k]:.4f}" for k in ("D12", "D13", "D23")]
    assert cli["Le (inertia)"].split() == [f"{v:.4f}" for v in m["Le"]]
    assert cli["valence"].split() == [f"{v}:{n}" for v, n in m["valence"].items()]
    assert cli["back end"] == f"{r['backend']} ({r['backend_reason']})"
    # fluid.tolerance "auto": the direct sum at this size, so its 1e-6 (docs/boundary-integral.md §4.3.2)
    ft = r["far_field_tolerance"]
    assert ft["value"] == 1e-6 and ft["direct"] == 1e-6 and ft["fmm"] == 1e-5
    assert cli["far field"] == f"accurate to {ft['value']:g} of max |v| (fluid.tolerance {ft['reason']})"
    assert cli["stable dt"].startswith(f"{r['stable_dt']['limit']:.3e} at t = 0")
    # auto: ROCK4, the analytic spectral radius (205 on this wall at 320 elements) being below 800
    assert cli["time scheme"].startswith(r["scheme"]) and r["scheme"] == "rock4"
    assert cli["time step"].startswith(f"error-controlled (tolerance auto: {r['time_step']['tolerance']:g} ℓ")
    # probed at 320 elements (as the command line does up to 20 480): measured, power iteration
    assert r["spectral_radius"]["method"] == "power_iteration" and r["seconds_per_evaluation"] > 0
    assert cli["spectral radius"].startswith(f"{r['spectral_radius']['value']:.3e} by power iteration")


def test_info_numbers_agree_with_geometry():
    info = capsflow.Scene({"mesh": {"level": 2}}).info()  # the default prolate spheroid, aspect 1.4 along z
    m = info["mesh"]
    # a closed genus-0 triangulation: V − E + F = 2, and every edge has two triangles: 2E = 3F
    assert m["nodes"] - m["edges"] + m["elements"] == 2 and 2 * m["edges"] == 3 * m["elements"]
    assert sum(m["valence"].values()) == m["nodes"]
    # ℓ is the radius of the sphere of the same volume; 4πℓ² its area (rounding only: 1e-14)
    assert 4 / 3 * np.pi * m["equivalent_radius"] ** 3 == pytest.approx(m["volume"], rel=1e-14)
    assert m["sphere_area"] == pytest.approx(4 * np.pi * m["equivalent_radius"] ** 2, rel=1e-14)
    # the spheroid's semi-axes have ratio 1.4 (the mesh's inertia ellipsoid to 1e-3 at 320 elements:
    # a discretization error of the polyhedron's moments)
    assert m["Le"][2] / m["Le"][0] == pytest.approx(1.4, rel=1e-3)
    assert m["area"] > m["sphere_area"]  # a spheroid has more area than the sphere of its volume
    # its Taylor deformation in the x-z plane for a/b = 1.4 along z: (b − a)/(a + b) = −0.4/2.4
    assert m["D13"] == pytest.approx(-0.4 / 2.4, rel=1e-3)
    # a larger mesh is not evaluated unless asked: no measured time, the analytic spectral radius
    big = capsflow.Scene({"mesh": {"level": 6}}).info()
    assert big["run"]["spectral_radius"]["method"] == "analytic" and np.isnan(big["run"]["seconds_per_evaluation"])
    assert big["mesh"]["elements"] == 20 * 4 ** 6  # an icosahedron refined 6 times
    with pytest.raises(TypeError):
        capsflow.Scene().info(probe="yes")
