"""The stub capsflow/_core.pyi names exactly what the compiled module defines, so that editors
complete what exists and nothing else; every public name of the package has a docstring."""
import ast
import inspect
from pathlib import Path

import capsflow
from capsflow import _core


def stub_names() -> dict:
    """{name: None for a function or variable, set of member names for a class} from the stub."""
    tree = ast.parse(Path(capsflow.__file__).with_name("_core.pyi").read_text())
    names = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            names[node.name] = None
        elif isinstance(node, ast.ClassDef):
            names[node.name] = {n.name for n in node.body if isinstance(n, ast.FunctionDef) and not n.name.startswith("_")}
        elif isinstance(node, ast.AnnAssign) and not node.target.id.startswith("_F"):
            names[node.target.id] = None
    return names


def module_names() -> dict:
    names = {}
    for name, value in vars(_core).items():
        if name.startswith("__") and name != "__version__":
            continue
        if inspect.isclass(value):
            names[name] = {m for m in vars(value) if not m.startswith("_")}
        else:
            names[name] = None
    return names


def test_the_stub_matches_the_module():
    assert stub_names() == module_names()


def test_every_public_name_has_a_docstring():
    missing = []
    for module in (capsflow, capsflow.fmm, capsflow.results, capsflow.scene, capsflow.simulation):
        for name in getattr(module, "__all__"):
            value = getattr(module, name)
            if callable(value) and not inspect.getdoc(value):
                missing.append(f"{module.__name__}.{name}")
            if inspect.isclass(value):
                missing += [f"{module.__name__}.{name}.{m}" for m, v in vars(value).items()
                            if not m.startswith("_") and (callable(v) or isinstance(v, property)) and not inspect.getdoc(v)]
    assert missing == []
