"""Distributed loads turned into nodal forces (n_nodes, 3), and factored combinations.

* :func:`pressure_load` -- a pressure ``p`` (force per unit facet area) along each facet's
  unit normal (right-hand rule on the face's vertex order: ``+z`` for a counter-clockwise
  flat pattern), fixed in direction (not a follower load);
* :func:`projected_load` -- a load ``q`` per unit area projected on the plane normal to a
  direction (snow: per unit plan area, downwards), acting along that direction;
* :func:`line_load` -- a force per unit length along pattern edges (creases or boundaries);
* :func:`combine` -- ``sum factor_c * case_c``;
* :class:`FollowerPressure` -- a pressure along each facet's *current* normal (a follower
  load: it turns with the panels), evaluated by the solver at every iterate.

Area loads are lumped: each face's resultant is shared equally by its corners (the resultant
is exact; the same rule as :func:`barhinge.scene.self_weight`). A line load's resultant on an
edge is shared equally by its two end vertices. Units are the user's.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import scipy.sparse as sp

from barhinge import _check
from barhinge.errors import ConfigError

__all__ = [
    "FollowerPressure",
    "combine",
    "face_vectors",
    "line_load",
    "pressure_load",
    "projected_load",
]


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


@dataclasses.dataclass(frozen=True, eq=False)
class FollowerPressure:
    """A pressure ``p`` (force per unit area, the user's units) along each facet's current
    normal: a follower load, which turns with the panels as they rotate.

    A facet with corners ``x_1 .. x_n`` (the pattern face's vertex order; ``+z`` for a
    counter-clockwise flat pattern) carries ``p S`` with ``S = 1/2 sum_i x_i x x_{i+1}`` its
    vector area (exact for a planar facet), shared equally by its corners, as
    :func:`pressure_load` does at the reference state. Its derivative is
    ``dS/dx_j = 1/2 [x_{j-1} - x_{j+1}]_x`` (skew matrix of the corner's two neighbours). The
    load stiffness is not symmetric for an open surface; the solver's residual uses the exact
    load and its tangent the symmetric part of the load stiffness (its factorisations are
    symmetric), so converged states are exact while Newton converges linearly where the
    skew part matters.

    Parameters
    ----------
    p : float
        Pressure, force per unit area (times the load factor).
    faces : (k,) int, optional
        Pattern faces loaded (default all).
    """

    p: float
    faces: Any = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "p", _check.number(self.p, "follower pressure"))
        object.__setattr__(self, "_cache", {})

    def _groups(self, model: Any) -> list[np.ndarray]:
        """:meth:`_face_groups`, built once per pattern."""
        return self._cached("groups", model, self._face_groups)

    def _pattern(self, model: Any) -> tuple[np.ndarray, np.ndarray]:
        """(rows, cols) of every entry of the load stiffness, in the order of its values
        (built once per pattern)."""
        return self._cached("pattern", model, self._stiffness_pattern)

    def _cached(self, name: str, model: Any, build: Any) -> Any:
        """``build(model)``, kept while the model's pattern is the same object."""
        cache: dict = self._cache  # type: ignore[attr-defined]
        hit = cache.get(name)
        if hit is None or hit[0] is not model.pattern:
            hit = cache[name] = (model.pattern, build(model))
        return hit[1]

    def _stiffness_pattern(self, model: Any) -> tuple[np.ndarray, np.ndarray]:
        rows, cols = [], []
        for F in self._groups(model):
            ri = 3 * F[:, :, None, None, None] + np.arange(3)[None, None, None, :, None]
            cj = 3 * F[:, None, :, None, None] + np.arange(3)[None, None, None, None, :]
            ri, cj = np.broadcast_arrays(ri, cj)
            rows.append(ri.ravel())
            cols.append(cj.ravel())
        empty = np.zeros(0, np.int64)
        return (
            np.concatenate(rows) if rows else empty,
            np.concatenate(cols) if cols else empty,
        )

    def _face_groups(self, model: Any) -> list[np.ndarray]:
        """Face corner arrays (k_n, n), one per corner count n."""
        cp = model.pattern
        ids = (
            np.arange(cp.n_faces)
            if self.faces is None
            else _check.int_array(self.faces, "faces", 0, cp.n_faces - 1)
        )
        by_n: dict[int, list[list[int]]] = {}
        for f in ids:
            face = list(cp.faces[int(f)])
            by_n.setdefault(len(face), []).append(face)
        return [np.asarray(v, np.int64) for v in by_n.values()]

    def force(self, model: Any, X: np.ndarray) -> np.ndarray:
        """(n_dof,) nodal forces at coordinates ``X`` (n_nodes, 3), force."""
        X = np.asarray(X, float).reshape(-1, 3)
        out = np.zeros_like(X)
        for F in self._groups(model):
            P = X[F]  # (k, n, 3)
            S = 0.5 * np.cross(P, np.roll(P, -1, axis=1)).sum(axis=1)  # (k, 3)
            share = (self.p / F.shape[1]) * S
            np.add.at(out, F.ravel(), np.repeat(share, F.shape[1], axis=0))
        return out.ravel()

    def stiffness(self, model: Any, X: np.ndarray) -> sp.csr_matrix:
        """(n_dof, n_dof) load stiffness ``d force / dX`` (not symmetric), force / length."""
        X = np.asarray(X, float).reshape(-1, 3)
        n = X.size
        vals = []
        for F in self._groups(model):
            k, m = F.shape
            P = X[F]
            d = 0.5 * (np.roll(P, 1, axis=1) - np.roll(P, -1, axis=1))  # x_{j-1} - x_{j+1}
            # skew matrix [d]_x: [d]_x v = d x v, per corner j: (k, m, 3, 3)
            W = np.zeros((k, m, 3, 3))
            W[..., 0, 1], W[..., 0, 2] = -d[..., 2], d[..., 1]
            W[..., 1, 0], W[..., 1, 2] = d[..., 2], -d[..., 0]
            W[..., 2, 0], W[..., 2, 1] = -d[..., 1], d[..., 0]
            W *= self.p / m
            # every corner i of the face gets dS/dx_j: blocks (i, j) for all i, j
            vals.append(np.broadcast_to(W[:, None, :, :, :], (k, m, m, 3, 3)).ravel())
        if not vals:
            return sp.csr_matrix((n, n))
        rows, cols = self._pattern(model)
        return sp.csr_matrix((np.concatenate(vals), (rows, cols)), shape=(n, n))
