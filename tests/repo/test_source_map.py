"""The maps of the source stay true: src/README.md's concept table names every file under src/
(as the key table's test does for scene keys), and the include order that src/README.md states
holds for every #include of src/, as do the two libraries' independence (fmm/ and shell/ never
include each other)."""
import re

from repo_files import ROOT

SRC = ROOT / "src"
README = SRC / "README.md"
HEADERS = SRC / "include" / "capsflow" / "core"


def concept_table_names():
    """Every `path` named in the rows of the concept table ("## Where each concept lives")."""
    text = README.read_text()
    table = text.split("## Where each concept lives", 1)[1].split("\n## ", 1)[0]
    names = set()
    for line in table.splitlines():
        if line.startswith("|"):
            for token in re.findall(r"`([^`]+)`", line):
                for part in re.split(r",\s*", token):
                    names.add(part.strip())
    return names


def source_units():
    """src/ files by the name the table uses: 'group/stem' for a .cpp (with its public header),
    'group/name.hpp' for a header without a .cpp, 'include/capsflow/core/name.hpp' at the top."""
    units = {}
    for cpp in SRC.glob("*/*.cpp"):
        units[f"{cpp.parent.name}/{cpp.stem}"] = cpp
    for hpp in SRC.glob("*/*.hpp"):  # private headers of a folder
        if f"{hpp.parent.name}/{hpp.stem}" not in units:
            units[f"{hpp.parent.name}/{hpp.name}"] = hpp
    for hpp in HEADERS.glob("*/*.hpp"):
        if f"{hpp.parent.name}/{hpp.stem}" not in units:
            units[f"{hpp.parent.name}/{hpp.name}"] = hpp
    for hpp in HEADERS.glob("*.hpp"):
        units[f"include/capsflow/core/{hpp.name}"] = hpp
    for inc in SRC.glob("*/*.inc"):  # generated tables, named with the file that includes them
        units[f"{inc.parent.name}/{inc.name}"] = inc
    return units


def named(unit, names):
    variants = {unit, unit + ".cpp", unit + ".hpp"}
    if unit.endswith(".hpp"):
        variants.add(unit[:-4])
    folder = unit.split("/")[0]
    if (SRC / folder / "README.md").exists() and f"{folder}/" in names:  # a folder with its own map
        return unit.split("/", 1)[1].split(".")[0] in (SRC / folder / "README.md").read_text()
    return bool(variants & names)


def test_the_concept_table_names_every_source_file():
    names = concept_table_names()
    missing = sorted(u for u in source_units() if not named(u, names))
    assert not missing, "src/README.md's concept table does not name: " + ", ".join(missing)


def test_the_concept_table_names_no_file_that_is_gone():
    units = source_units()
    known = set(units) | {u + ".cpp" for u in units} | {u + ".hpp" for u in units}
    known |= {u[:-4] for u in units if u.endswith(".hpp")}
    stale = sorted(n for n in concept_table_names()
                   if re.fullmatch(r"[a-z_]+/[a-z_0-9.]+", n) and not n.endswith("/") and n not in known)
    assert not stale, "src/README.md names files that do not exist: " + ", ".join(stale)


# The stated order (src/README.md, "Which folder includes which"): a folder includes only itself and
# the folders before it; scene/scene.hpp may also include the enum headers that name a scene's choices.
ORDER = ["geometry", "theory", "io", "bie", "scene", "mesh", "rhs", "stepping", "health", "driver", "info", "study", "app"]
SCENE_ENUM_HEADERS = {"mesh/generation.hpp", "stepping/time_scheme.hpp", "health/health_conditions.hpp"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"capsflow/core/([a-z_]+)/([a-z_0-9.]+)"', re.M)


def include_violations():
    bad = []
    files = list(SRC.glob("*/*.cpp")) + list(SRC.glob("*/*.hpp")) + list(HEADERS.glob("*/*.hpp"))
    for path in files:
        folder = path.parent.name
        if folder not in ORDER:
            bad.append(f"{path.relative_to(ROOT)}: folder {folder}/ is not in the stated order")
            continue
        allowed = set(ORDER[: ORDER.index(folder) + 1])
        for group, name in INCLUDE.findall(path.read_text()):
            if group in allowed:
                continue
            if path.name == "scene.hpp" and folder == "scene" and f"{group}/{name}" in SCENE_ENUM_HEADERS:
                continue
            bad.append(f"{path.relative_to(ROOT)} includes {group}/{name}")
    return bad


def test_the_stated_include_order_holds():
    bad = include_violations()
    assert not bad, "includes against src/README.md's order:\n" + "\n".join(bad)


def test_the_readme_states_the_order_this_test_checks():
    text = README.read_text().split("## Which folder includes which", 1)[1]
    stated = re.findall(r"([a-z_]+)/", text.split("—", 1)[0])
    assert stated == ORDER, f"src/README.md states {stated}, the test checks {ORDER}"


def test_fmm_and_shell_never_include_each_other():
    bad = []
    for lib, other in (("fmm", "shell"), ("shell", "fmm")):
        for path in (ROOT / lib).rglob("*.[ch]pp"):
            if re.search(rf'#\s*include\s+"capsflow/{other}/', path.read_text()):
                bad.append(str(path.relative_to(ROOT)))
    assert not bad, "fmm/ and shell/ include each other: " + ", ".join(bad)


def test_the_include_check_can_fail():
    # A made-up file of mesh/ that includes driver/ is caught; one of driver/ including mesh/ is not.
    allowed_mesh = set(ORDER[: ORDER.index("mesh") + 1])
    assert "driver" not in allowed_mesh and "geometry" in allowed_mesh
