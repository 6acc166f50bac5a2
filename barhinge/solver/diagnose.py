"""Pre-solve diagnosis of a scene: what would make the tangent singular from the start.

Run by :func:`barhinge.solve` before the first increment (and callable on its own):

* the model's arrays are finite (coordinates, bar and hinge stiffnesses, loads);
* the connected parts of the bar graph (a pattern of two separate sheets is two parts);
* the rigid-body motions of each part that the supports and prescribed displacements leave
  free, named ("translation in y and rotation about z"). Actuators cannot hold a rigid-body
  motion (a rigid motion changes no fold angle), so only fixed DOFs count.

Tolerances are relative: rotations act on coordinates relative to a part's centroid over the
pattern's size, so a sheet of size 1e12 and one of size 1e-12 are judged alike.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from barhinge.errors import ConfigError
from barhinge.linalg.backends import SingularMatrixError

if TYPE_CHECKING:
    from barhinge.scene import Scene

__all__ = ["Diagnosis", "check_finite_tangent", "diagnose", "free_rigid_motions"]

#: relative singular-value tolerance of the rank tests
RANK_TOL = 1e-9

_AXES = "xyz"


@dataclasses.dataclass(frozen=True)
class Diagnosis:
    """What :func:`diagnose` found.

    Attributes
    ----------
    parts : list of (k,) int arrays
        Node ids of each connected part of the bar graph (one part for a sound model).
    free : list of str
        Per part, the rigid-body motions left free ("" when the part is held).
    problems : list of str
        One line per problem; empty when the scene can be solved.
    """

    parts: list[np.ndarray]
    free: list[str]
    problems: list[str]

    @property
    def ok(self) -> bool:
        return not self.problems


def _ranges(ids: np.ndarray, limit: int = 4) -> str:
    """``0..14, 20, 22..30`` (at most ``limit`` runs, then ``...``)."""
    ids = np.sort(np.asarray(ids, np.int64))
    runs: list[str] = []
    start = prev = int(ids[0])
    for v in [*ids[1:].tolist(), None]:
        if v is not None and v == prev + 1:
            prev = v
            continue
        runs.append(f"{start}" if start == prev else f"{start}..{prev}")
        if v is not None:
            start = prev = v
    if len(runs) > limit:
        runs = [*runs[:limit], "..."]
    return ", ".join(runs)


def _join(words: list[str]) -> str:
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def free_rigid_motions(X: np.ndarray, fixed: np.ndarray, size: float | None = None) -> str:
    """Name the rigid-body motions of the points ``X`` that the fixed DOFs leave free.

    Parameters
    ----------
    X : (k, 3) float
        Coordinates of one connected part.
    fixed : (k, 3) bool
        Fixed DOFs of those points.
    size : float, optional
        Length scale of the rotations (default: the part's bounding-box diagonal).

    Returns
    -------
    str
        ``""`` when every rigid-body motion is held, else e.g. ``"translation in y and
        rotation about z"``.
    """
    X = np.asarray(X, float)
    c = X.mean(0)
    L = size if size else float(np.linalg.norm(np.ptp(X, axis=0)))
    L = L if L > 0 and np.isfinite(L) else 1.0
    r = (X - c) / L
    # R[3 i + a, m]: velocity component a of point i under mode m = (tx, ty, tz, wx, wy, wz)
    R = np.zeros((len(X), 3, 6))
    R[:, :, :3] = np.eye(3)
    R[:, 0, 4], R[:, 0, 5] = r[:, 2], -r[:, 1]  # w x r
    R[:, 1, 3], R[:, 1, 5] = -r[:, 2], r[:, 0]
    R[:, 2, 3], R[:, 2, 4] = r[:, 1], -r[:, 0]
    R = R.reshape(-1, 6)
    F = R[np.asarray(fixed, bool).ravel()]
    rank_all = _rank(R)
    if _rank(F) >= rank_all:
        return ""
    # free motions: null space of F (in the 6 mode parameters), less the motions that move
    # nothing (rotation about the line of a collinear part)
    N = _null(F)
    N = N[:, [np.linalg.norm(R @ N[:, j]) > RANK_TOL * np.sqrt(len(X)) for j in range(N.shape[1])]]
    if N.shape[1] == 0:
        return ""
    names: list[str] = []
    # pure translations: combinations of N with no rotation part
    W = N[3:]
    T = N[:3] @ _null(W) if W.any() else N[:3]
    trans = [a for a in range(3) if T.size and _in_span(np.eye(3)[a], T)]
    if trans:
        names.append("translation in " + _join([_AXES[a] for a in trans]))
    elif T.size and _rank(T) > 0:
        names.append(f"translation along {_direction(T[:, 0])}")
    rots = [a for a in range(3) if _in_span(np.eye(3)[a], W)]
    if rots:
        names.append("rotation about " + _join([_AXES[a] for a in rots]))
    elif _rank(W) > 0:
        names.append(f"rotation about the axis {_direction(_null(F)[3:, 0])}")
    counted = len(trans) + len(rots)
    total = _rank(R @ N)
    if counted < total and not names:
        names.append(f"{total} rigid-body motions")
    return _join(names)


def _rank(A: np.ndarray) -> int:
    if A.size == 0:
        return 0
    s = np.linalg.svd(A, compute_uv=False)
    return int((s > RANK_TOL * max(1.0, float(s[0]))).sum())


def _null(A: np.ndarray) -> np.ndarray:
    """(n, k) orthonormal basis of the null space of A (m, n)."""
    n = A.shape[1]
    if A.shape[0] == 0:
        return np.eye(n)
    _, s, vt = np.linalg.svd(A)
    r = int((s > RANK_TOL * max(1.0, float(s[0]) if s.size else 1.0)).sum())
    return vt[r:].T


def _in_span(v: np.ndarray, B: np.ndarray) -> bool:
    if B.size == 0:
        return False
    coef, *_ = np.linalg.lstsq(B, v, rcond=None)
    return bool(np.linalg.norm(B @ coef - v) < 1e-6)


def _direction(v: np.ndarray) -> str:
    v = v / np.linalg.norm(v)
    return "(" + ", ".join(f"{x:.3g}" for x in v) + ")"


def diagnose(scene: Scene) -> Diagnosis:
    """Diagnose ``scene`` without solving it (see the module docstring).

    Returns
    -------
    Diagnosis
        ``problems`` lists one line per problem; :func:`check` raises on the first.
    """
    model = scene.model
    problems: list[str] = []
    for what in ("X0", "bar_EA", "bar_L0", "hinge_k", "rest_angle"):
        arr = getattr(model, what, None)
        if arr is not None and not np.all(np.isfinite(np.asarray(arr, float))):
            problems.append(f"the model's {what} has non-finite entries")
    if not np.all(np.isfinite(scene.loads)):
        problems.append("the loads have non-finite entries")
    X = np.asarray(model.X0, float)
    n = len(X)
    bars = np.asarray(model.bars, np.int64).reshape(-1, 2)
    A = sp.coo_matrix((np.ones(len(bars)), (bars[:, 0], bars[:, 1])), shape=(n, n))
    n_parts, label = connected_components(A, directed=False)
    parts = [np.flatnonzero(label == k) for k in range(n_parts)]
    nv = model.pattern.n_vertices if hasattr(model, "pattern") else n
    Vv = X[:nv]
    size = float(np.linalg.norm(np.ptp(Vv, axis=0))) if nv else 1.0
    fixed = scene.fixed
    free = [free_rigid_motions(X[p], fixed[p], size) for p in parts]
    if not problems and any(free):
        if n_parts == 1:
            problems.append(
                f"{free[0]} {'is' if ' and ' not in free[0] else 'are'} free: add supports "
                "(the supports and prescribed displacements leave the model a rigid-body "
                "motion)"
            )
        else:
            named = " and ".join(f"nodes {_ranges(_vertex_ids(p, nv))}" for p in parts[:4])
            more = f" and {n_parts - 4} more" if n_parts > 4 else ""
            loose = "; ".join(f"part {k + 1}: {f} free" for k, f in enumerate(free) if f)
            problems.append(
                f"the model has {n_parts} separate parts: {named}{more}; {loose}: "
                "join the parts or support each of them"
            )
    return Diagnosis(parts=parts, free=free, problems=problems)


def _vertex_ids(part: np.ndarray, nv: int) -> np.ndarray:
    """The pattern vertices of a part (its centre nodes only if it has no vertex)."""
    v = part[part < nv]
    return v if v.size else part


def check(scene: Scene) -> Diagnosis:
    """:func:`diagnose` and raise :class:`ConfigError` with the first problem found."""
    d = diagnose(scene)
    if d.problems:
        raise ConfigError(d.problems[0])
    return d


def check_finite_tangent(K: Any) -> None:
    """Last guard before a factorisation: a tangent with NaN or inf entries is reported as
    singular (the Newton driver then cuts the increment back) instead of reaching the
    sparse direct solver, which may crash on it."""
    data = K.data if sp.issparse(K) else np.asarray(K)
    if not np.all(np.isfinite(data)):
        raise SingularMatrixError("the tangent has non-finite entries")
