"""A small valid scene that uses every table of the TOML format, and a TOML writer for it."""

from __future__ import annotations

import copy
import json
import math
from typing import Any

#: 2 x 2 Miura sheet (25 vertices); edge 21 is a crease at -40 deg in the pattern state
BASE: dict[str, Any] = {
    "name": "base",
    "pattern": {
        "family": "miura",
        "params": {"nx": 2, "ny": 2, "a": 1.0, "b": 1.0, "alpha": 60.0, "fold": 20.0},
    },
    "model": {
        "scheme": "N5B8",
        "material": {"E": 1.0e6, "nu": 0.3, "t": 0.01},
        "fold_stiffness": 1.0,
    },
    "supports": [{"where": "bottom", "dofs": "z"}, {"vertices": [0], "dofs": "xyz"}],
    "loads": [
        {"self_weight": {"area_density": 0.1, "g": [0.0, 0.0, -9.81]}},
        {"vertices": [12], "force": [0.0, 0.0, -1.0]},
    ],
    "prescribed": [{"vertices": [24], "displacement": [0.0, 0.0, 0.0], "dofs": "x"}],
    "actuators": {"edges": [21], "targets_deg": [-50.0]},
    "solve": {"steps": 3, "control": "fold_angle", "options": {"tol_force": 1e-8}},
}


def base() -> dict[str, Any]:
    return copy.deepcopy(BASE)


def mutated(path: tuple[Any, ...], value: Any) -> dict[str, Any]:
    """BASE with the item at ``path`` (keys and list indices) replaced by ``value``
    (``DELETE``: removed)."""
    d = base()
    node = d
    for k in path[:-1]:
        node = node[k]
    if value is DELETE:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return d


DELETE = object()


def to_toml(d: dict[str, Any]) -> str:
    """TOML text of a mapping (top-level keys; tables written inline)."""
    return "".join(f"{_key(k)} = {_value(v)}\n" for k, v in d.items())


def _key(k: str) -> str:
    return k if k.replace("_", "").isalnum() else json.dumps(k)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(type(v))
