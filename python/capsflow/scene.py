"""capsflow.Scene: a scene (docs/scene-and-output.md §2) built from a TOML file, TOML text or a
dict, changed key by key with set() — validated exactly as the command line's --set, with the
same one-line errors (ValueError) — and written back as canonical TOML."""
from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path

from . import _core, _toml

__all__ = ["Scene"]


class Scene:
    """A resolved scene: every key has its value (defaults filled in, derived ones computed).

        Scene()                          the built-in default scene (what `capsflow run` runs)
        Scene("scenes/quick.toml")       a scene file (a relative mesh.file is relative to its folder)
        Scene({"mesh": {"level": 2}})    a dict {section: {key: value}}: the keys not given take their defaults
        Scene.from_toml(text)            TOML text

    `scene.set("mesh.level", 5)` changes one key as `--set mesh.level=5` does (the other keys keep
    their values; setting flow.ca_s drops a flow.ca_v given before, and vice versa); a bad key or
    value raises ValueError with the command line's message and leaves the scene unchanged.
    """

    def __init__(self, source: str | os.PathLike | Mapping | None = None):
        if source is None:
            self._base = ("text", _core.default_scene_toml(), "<built-in default>")
        elif isinstance(source, Mapping):
            self._base = ("text", _toml.document(source), "<dict>")
        elif isinstance(source, (str, os.PathLike)):
            self._base = ("file", os.fspath(source), None)
        else:
            raise TypeError(f"a Scene is made from a file path, a dict or None, got {type(source).__name__} "
                            f"(TOML text: Scene.from_toml)")
        self._overrides: list[str] = []
        self._resolved = self._resolve(self._overrides)

    @classmethod
    def from_toml(cls, text: str, name: str = "<string>") -> "Scene":
        """A scene from TOML text; `name` stands for the file in error messages."""
        scene = cls.__new__(cls)
        scene._base = ("text", text, name)
        scene._overrides = []
        scene._resolved = scene._resolve([])
        return scene

    def _resolve(self, overrides: list[str]):
        kind, what, name = self._base
        if kind == "file":
            return _core.load_scene(what, overrides)
        return _core.parse_scene(what, name, overrides)

    @staticmethod
    def keys() -> list[dict]:
        """Every scene key as a dict: 'key' ('mesh.level'), 'type', 'default', 'accepted', 'meaning'
        (markdown, as the tables of docs/scene-and-output.md §2 and `capsflow info --keys`)."""
        return _core.scene_key_docs()

    def set(self, key: str, value) -> "Scene":
        """Set `key` ('section.key') to `value` (bool, number, string or list; numpy scalars and
        arrays, 0-d ones included) as --set does; returns the scene, so calls chain. ValueError (the
        scene unchanged) for a bad key or value; a key holding '=', '#' or a line break is refused."""
        overrides = self._overrides + [_toml.assignment(key, value)]
        self._resolved = self._resolve(overrides)
        self._overrides = overrides
        return self

    def get(self, key: str):
        """The resolved value of `key` ('section.key'), as in to_dict()."""
        section, _, name = key.partition(".")
        d = self.to_dict()
        if section not in d or name not in d[section]:
            raise KeyError(f"no scene key {key!r}")
        return d[section][name]

    def info(self, probe: bool = False) -> dict:
        """What `capsflow info` prints after the resolved scene, as a dict (docs/python.md §3):
        'source', 'scene_toml', 'note'; 'mesh' (elements, nodes, edges, edge_length, angle_deg,
        valence, volume, equivalent_radius, area, sphere_area, Le, L, D12, D13, D23); 'run' (backend,
        backend_reason, fmm_order_warning, stable_dt, spectral_radius, seconds_per_evaluation,
        threads, scheme, time_plan, time_step, memory_mb, memory_double_layer_mb). Up to 20 480
        elements (or with probe=True) the right-hand side is evaluated, as `capsflow info` does: the
        time per evaluation (measured, NaN otherwise) and the spectral radius by power iteration."""
        if not isinstance(probe, bool):
            raise TypeError(f"probe must be True or False, got {type(probe).__name__}")
        return _core.scene_info(self._resolved, probe)

    def to_dict(self) -> dict:
        """The resolved scene as {section: {key: value}} (summary.json's 'scene')."""
        return json.loads(self._resolved.to_json())

    def to_toml(self) -> str:
        """Canonical TOML of the resolved scene, every key explicit (what checkpoints store)."""
        return self._resolved.to_toml()

    @property
    def source(self) -> str:
        """The file the scene came from, '<built-in default>', '<dict>' or from_toml's name."""
        return self._resolved.source

    @property
    def overrides(self) -> list[str]:
        """The set() calls so far, as the command line's --set assignments."""
        return list(self._overrides)

    def copy(self) -> "Scene":
        """An independent copy (set() on it leaves this one alone)."""
        other = Scene.__new__(Scene)
        other._base, other._overrides, other._resolved = self._base, list(self._overrides), self._resolved
        return other

    def __repr__(self) -> str:
        sets = "".join(f".set({o.split('=', 1)[0]!r}, {o.split('=', 1)[1]})" for o in self._overrides)
        return f"Scene({self.source!r}){sets}"
