"""Distributed loads turned into nodal forces (n_nodes, 3), and factored combinations.

* :func:`pressure_load` -- a pressure ``p`` (force per unit facet area) along each facet's
  unit normal (right-hand rule on the face's vertex order: ``+z`` for a counter-clockwise
  flat pattern), fixed in direction (not a follower load);
* :func:`projected_load` -- a load ``q`` per unit area projected on the plane normal to a
  direction (snow: per unit plan area, downwards), acting along that direction;
* :func:`line_load` -- a force per unit length along pattern edges (creases or boundaries);
* :func:`combine` -- ``sum factor_c * case_c``.

Area loads are lumped: each face's resultant is shared equally by its corners (the resultant
is exact; the same rule as :func:`barhinge.scene.self_weight`). A line load's resultant on an
edge is shared equally by its two end vertices. Units are the user's.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from barhinge import _check
from barhinge.errors import ConfigError

__all__ = ["pressure_load", "projected_load", "line_load", "combine", "face_vectors"]


def face_vectors(model: Any, faces: Any = None) -> tuple[np.ndarray, list[list[int]]]:
    """(area vector ``A n`` (k, 3) at ``model.X0``, vertex lists) of the faces ``faces``
    (default all)."""
    cp = model.pattern
    X = np.asarray(model.X0, float)
    if faces is None:
        ids = np.arange(cp.n_faces)
    else:
        ids = _check.int_array(faces, "faces", 0, cp.n_faces - 1)
    F = [list(cp.faces[int(f)]) for f in ids]
    An = np.array([0.5 * np.cross(X[f], np.roll(X[f], -1, axis=0)).sum(0) for f in F])
    return An.reshape(-1, 3), F


def _lump(n: int, F: list[list[int]], forces: np.ndarray) -> np.ndarray:
    out = np.zeros((n, 3))
    for f, v in zip(F, forces, strict=True):
        out[f] += v / len(f)
    return out


def pressure_load(model: Any, p: float, faces: Any = None) -> np.ndarray:
    """(n_nodes, 3) nodal forces of a pressure ``p`` (force per area) along the facet
    normals of ``faces`` (default all)."""
    p = _check.number(p, "pressure")
    An, F = face_vectors(model, faces)
    return _lump(model.n_nodes, F, p * An)


def projected_load(
    model: Any, q: float, faces: Any = None, direction: Any = (0.0, 0.0, -1.0)
) -> np.ndarray:
    """(n_nodes, 3) nodal forces of a load ``q`` per unit area projected on the plane normal
    to ``direction`` (default downwards: per unit plan area, snow), acting along
    ``direction``."""
    q = _check.number(q, "projected load")
    d = _check.float_array(direction, "direction", (3,))
    nd = float(np.linalg.norm(d))
    if not nd > 0:
        raise ConfigError("direction must be a non-zero vector")
    d = d / nd
    An, F = face_vectors(model, faces)
    return _lump(model.n_nodes, F, q * np.abs(An @ d)[:, None] * d[None, :])


def line_load(model: Any, w: Any, edges: Any) -> np.ndarray:
    """(n_nodes, 3) nodal forces of a force ``w`` (3,) per unit length along the pattern
    edges ``edges``."""
    cp = model.pattern
    w = _check.float_array(w, "line load", (3,))
    e = _check.int_array(edges, "edges", 0, cp.n_edges - 1)
    E = np.asarray(cp.edges, np.int64)[e]
    X = np.asarray(model.X0, float)
    L = np.linalg.norm(X[E[:, 1]] - X[E[:, 0]], axis=1)
    out = np.zeros((model.n_nodes, 3))
    np.add.at(out, E[:, 0], 0.5 * L[:, None] * w)
    np.add.at(out, E[:, 1], 0.5 * L[:, None] * w)
    return out


def combine(cases: dict[str, np.ndarray], factors: dict[str, float]) -> np.ndarray:
    """``sum factors[c] * cases[c]`` (a factored load combination)."""
    if not factors:
        raise ConfigError("a load combination needs at least one case")
    out = None
    for name, fac in factors.items():
        if name not in cases:
            raise ConfigError(
                f"load combination names the case {name!r}; the cases are {sorted(cases)}"
            )
        term = _check.number(fac, f"factor of {name!r}") * np.asarray(cases[name], float)
        out = term if out is None else out + term
    assert out is not None
    return out
