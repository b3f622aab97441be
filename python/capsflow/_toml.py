"""Python values as TOML text: the right-hand side of a --set assignment, and a two-level scene
dict ({section: {key: value}}) as a scene file."""
from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence

import numpy as np


def value(v) -> str:
    """A TOML value: bool, int, float, str, or a (nested) sequence of them (numpy scalars and arrays,
    0-d arrays included, too)."""
    if isinstance(v, np.ndarray) and v.ndim == 0:
        v = v.item()  # np.array(0.5): a scalar, not a sequence
    elif isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        f = float(v)
        if math.isnan(f):
            return "nan"
        if math.isinf(f):
            return "inf" if f > 0 else "-inf"
        return repr(f)
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a TOML basic string (same escapes)
    if isinstance(v, np.ndarray):
        v = v.tolist()
    if isinstance(v, Sequence):
        return "[" + ", ".join(value(x) for x in v) + "]"
    raise TypeError(f"a scene value must be a bool, number, string or list of them, got {type(v).__name__}")


def assignment(key, v) -> str:
    """`key=value` as the command line's --set takes it. The key is refused (ValueError, one line)
    when it holds what would change the assignment's meaning: '=' (the value would start there),
    '#' (a TOML comment) or a line break (a second assignment)."""
    if not isinstance(key, str):
        raise TypeError(f"a scene key is a string 'section.key', got {type(key).__name__}")
    bad = [c for c in ("=", "#", "\n", "\r") if c in key]
    if bad:
        raise ValueError(f"scene key {key!r}: a key is 'section.key' (e.g. 'time.t_end') and has no {bad[0]!r}; "
                         f"the value goes in the second argument")
    return f"{key}={value(v)}"


def document(sections: Mapping) -> str:
    """{section: {key: value}} as TOML text."""
    out = []
    for section, keys in sections.items():
        if not isinstance(keys, Mapping):
            raise TypeError(f"scene dict: [{section}] must be a dict of keys, got {type(keys).__name__} "
                            f"(write {{'{section}': {{'key': value}}}})")
        out.append(f"[{section}]")
        out += [f"{k} = {value(v)}" for k, v in keys.items()]
        out.append("")
    return "\n".join(out)
