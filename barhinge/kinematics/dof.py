"""Degrees of freedom of rigid origami: counting, rank, redundancy, local DOF, actuators.

* Counting estimate (Tachi 2010, "Geometric considerations for the design of rigid origami
  structures", Proc. IASS): ``E_in - 3 V_in - sum_panels (n - 3)`` where ``E_in`` counts the
  interior creases of the triangulated pattern and ``V_in`` the interior vertices; each n-gon
  panel adds ``n - 3`` diagonals and ``n - 3`` planarity conditions, so the count equals
  (creases) - 3 (interior vertices) in the angle formulation; each hole subtracts 6 more
  (the closure of the chain of panels around it, :mod:`barhinge.kinematics.holes`).
* True (first-order) DOF: ``n_var - rank J`` with ``J`` the loop-closure Jacobian
  (:mod:`barhinge.kinematics.constraints`) at the given state; the number of redundant
  constraints is ``rank deficiency of the rows = DOF - count``. The flat state is special:
  every crease axis lies in the plane, so each vertex block has rank 2, not 3, and the
  first-order DOF exceeds the finite one (the flat state is a bifurcation point). The report
  therefore also evaluates a folded state near the flat one (``report.folded``).
* Local DOF of a vertex: ``degree - rank`` of its 3 x degree block (``degree - 3`` at a folded
  generic vertex); of a region (the vertex and its neighbouring interior vertices):
  ``(creases touching the region) - rank`` of the region's rows.
* Actuators: creases whose fold angles determine the configuration to first order = columns
  of the null-space basis ``N`` (n_var, dof) with ``N[A, :]`` invertible and well conditioned,
  chosen by column-pivoted QR of ``(N * w).T`` (Businger & Golub 1965), with weights ``w``
  that steer the choice.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from barhinge.errors import ConfigError, PatternError
from barhinge.kinematics.constraints import RigidConstraints
from barhinge.kinematics.holes import hole_loops
from barhinge.linalg.nullspace import DENSE_LIMIT, NullSpace, RankError, null_space
from barhinge.linalg.threads import single_threaded_dense
from barhinge.pattern.crease import CreasePattern

__all__ = ["DofReport", "dof", "select_actuators", "folded_sample", "system", "closure_errors"]

log = logging.getLogger(__name__)

#: a state whose largest |fold angle| is below this (rad) is reported as flat
FLAT_TOL = 1e-6
#: up to this many columns a Gauss-Newton step of the folded-state search is a dense
#: least-squares solve; above, one sparse factorisation of the damped normal matrix
STEP_DENSE_LIMIT = DENSE_LIMIT
#: at a flat state whose first-order null space is wider than this, the null vectors are not
#: formed (n_var x nullity² flops): rank and gap from the inertia, no actuators (the folded
#: state nearby, whose null space is small, gives them)
FLAT_BASIS_LIMIT = 512


@dataclasses.dataclass(frozen=True, eq=False)
class DofReport:
    """Degrees of freedom of a rigid-origami pattern at one state.

    Attributes
    ----------
    global_dof : int
        First-order DOF ``n_variables - rank`` at this state.
    counted_dof : int
        Tachi (2010) count ``E_in - 3 V_in - 6 holes - sum(n - 3)``.
    redundant : int
        Redundant constraints ``global_dof - counted_dof`` (= n_equations - rank).
    rank : int
        Numerical rank of the loop-closure Jacobian.
    tolerance : float
        Absolute singular-value threshold used for the rank.
    sigma_gap : float
        Smallest singular value counted as non-zero (compare with ``tolerance`` to judge how
        clear-cut the rank is; NaN if unknown).
    method : str
        ``"svd"`` (dense) or ``"sparse-inertia"`` (inertia of ``JᵀJ − τ²I``).
    sigma_below : float
        Largest singular value counted as zero (0.0 if none).
    gap_ratio : float
        ``sigma_gap / sigma_below`` (the latter floored at the method's noise level, see
        :mod:`barhinge.linalg.nullspace`): how clear-cut the rank is.
    certain : bool
        ``gap_ratio >= 1e3``; else the DOF is only known to lie in ``dof_range``.
    dof_range : (int, int)
        Smallest and largest plausible DOF (equal when ``certain``).
    n_variables, n_equations, n_interior_vertices : int
    flat : bool
        True when the state is flat (first-order DOF overestimates the finite DOF).
    local : (n_vertices,) int
        Local DOF of each constrained interior vertex (-1 elsewhere).
    region : (n_vertices,) int
        DOF of the region made of each vertex and its neighbouring interior vertices (-1 at
        unconstrained vertices).
    actuators : (k,) int
        Pattern edge ids whose fold angles determine the configuration (first order).
    triangulated : bool
    closure : float
        Largest loop-closure error ``|F - I|`` of the state (0 for an exact rigid state).
    folded : DofReport or None
        For a flat state: the same analysis at a rigidly folded state nearby (None if none was
        found, see ``note``).
    note : str
    fold_angles_deg : (n_edges,) float
        Fold angles of the analysed state per pattern edge.
    """

    global_dof: int
    counted_dof: int
    redundant: int
    rank: int
    tolerance: float
    sigma_gap: float
    method: str
    n_variables: int
    n_equations: int
    n_interior_vertices: int
    flat: bool
    local: np.ndarray
    region: np.ndarray
    actuators: np.ndarray
    triangulated: bool
    closure: float
    folded: DofReport | None = None
    note: str = ""
    sigma_below: float = 0.0
    gap_ratio: float = float("inf")
    certain: bool = True
    dof_range: tuple[int, int] = (0, 0)
    fold_angles_deg: np.ndarray | None = None

    @property
    def mechanism(self) -> DofReport:
        """The report that describes the finite mechanism: ``folded`` for a flat state (when
        found), else this one."""
        return self.folded if (self.flat and self.folded is not None) else self

    def summary(self) -> dict[str, Any]:
        """JSON-serialisable summary (what ``barhinge dof --json`` prints)."""

        def one(r: DofReport) -> dict[str, Any]:
            loc = r.local[r.local >= 0]
            reg = r.region[r.region >= 0]
            return {
                "global_dof": r.global_dof,
                "counted_dof": r.counted_dof,
                "redundant": r.redundant,
                "rank": r.rank,
                "tolerance": r.tolerance,
                "sigma_gap": r.sigma_gap,
                "method": r.method,
                "sigma_below": r.sigma_below,
                "gap_ratio": r.gap_ratio if np.isfinite(r.gap_ratio) else None,
                "certain": r.certain,
                "dof_range": list(r.dof_range),
                "n_variables": r.n_variables,
                "n_equations": r.n_equations,
                "n_interior_vertices": r.n_interior_vertices,
                "flat": r.flat,
                "closure": r.closure,
                "local_dof_histogram": {
                    int(k): int(v) for k, v in zip(*np.unique(loc, return_counts=True), strict=True)
                },
                "region_dof_histogram": {
                    int(k): int(v) for k, v in zip(*np.unique(reg, return_counts=True), strict=True)
                },
                "actuators": r.actuators.tolist(),
                "note": r.note,
            }

        out = {"triangulated": self.triangulated, "state": one(self)}
        if self.folded is not None:
            out["folded_state"] = one(self.folded)
        return out


# ------------------------------------------------------------------------- public API
@single_threaded_dense
def dof(
    cp: CreasePattern,
    state: np.ndarray | Sequence[float] | None = None,
    *,
    triangulated: bool = False,
    prefer: str | Sequence[int] | None = None,
    tol: float | None = None,
    folded_check: bool = True,
    progress: Callable[[str, int, int], None] | None = None,
) -> DofReport:
    """Global and local degrees of freedom of ``cp`` as a rigid origami.

    Parameters
    ----------
    cp : CreasePattern
        The pattern; its geometry is the reference state (flat or folded).
    state : None, (n_edges,) float or (n_vertices, 3) float
        The state to analyse: None = the pattern's own geometry; fold angles in degrees per
        pattern edge (valley > 0); or vertex coordinates.
    triangulated : bool
        Split non-triangular panels by diagonals that may fold (else panels are rigid).
    prefer : None, "boundary", "interior", "spread" or sequence of edge ids
        Steers the actuator choice: creases near the boundary, near the centre, spread out
        (neighbours of a chosen crease are penalised), or inside a given region (edge ids).
    tol : float, optional
        Relative singular-value threshold for the rank (default 1e-8 dense SVD, 1e-6 sparse).
    folded_check : bool
        At a flat state, also analyse a folded state nearby (``report.folded``).
    progress : callable, optional
        Called as ``progress(stage, done, total)`` before each stage of the work (the rank,
        local DOF, actuators, the folded-state search, ...) and once at the end with
        ``done == total`` (the CLI draws a progress bar from it).

    Returns
    -------
    DofReport
    """
    if state is not None:
        s = np.asarray(state, dtype=float)
        if s.ndim == 2 and s.shape == (cp.n_vertices, 3):
            cp = cp.replaced(vertices=s, validate=False)
            state = None
    tick = _Ticker(progress, 4)
    tick("loop-closure constraints")
    rc = RigidConstraints.from_pattern(cp, triangulated=triangulated)
    rho = _state_angles(rc, state)
    if folded_check and rc.n_var > 0 and np.max(np.abs(rho), initial=0.0) < FLAT_TOL:
        tick.total = 8
    rep = _report(rc, rho, prefer=prefer, tol=tol, tick=tick)
    hl = hole_loops(rc)
    if hl.n_holes:
        rep = dataclasses.replace(
            rep,
            note=_join(
                rep.note,
                f"the pattern has {hl.n_holes} hole(s): the chain of panels around each adds "
                "6 closure conditions",
            ),
        )
    missing = rc.holes - hl.n_holes
    if missing > 0:
        rep = dataclasses.replace(
            rep,
            note=_join(
                rep.note,
                f"{missing} hole(s) whose boundary touches another boundary loop are not "
                "constrained, so the DOF may be over-estimated",
            ),
        )
    if rep.flat and folded_check and rc.n_var > 0:
        tick("folded state nearby")
        try:
            rho_f = folded_sample(rc)
        except PatternError as exc:
            tick.finish()
            msg = str(exc)
            n_poly = sum(len(f) > 3 for f in rc.pattern.faces)
            if n_poly and not rc.triangulated:
                msg += (
                    f"; {n_poly} non-triangular panel(s) are held rigid and flat "
                    "(triangulated=True / --triangulated lets them fold along a diagonal)"
                )
            return dataclasses.replace(rep, note=_join(rep.note, msg))
        folded = _report(rc, rho_f, prefer=prefer, tol=tol, tick=tick)
        wrong = _against_assignment(rc, rho_f)
        if wrong:
            folded = dataclasses.replace(
                folded,
                note=_join(
                    folded.note,
                    f"this folded state disagrees with the M/V assignment at {wrong} creases "
                    "(the assigned mode may not be rigidly foldable)",
                ),
            )
        rep = dataclasses.replace(
            rep,
            folded=folded,
            note=_join(
                rep.note,
                f"flat state: first-order DOF {rep.global_dof} overestimates the finite DOF; "
                f"at a folded state nearby the DOF is {folded.global_dof}",
            ),
        )
    tick.finish()
    return rep


class _Ticker:
    """Counts the stages of :func:`dof` for a ``progress(stage, done, total)`` callback."""

    def __init__(self, progress: Callable[[str, int, int], None] | None, total: int) -> None:
        self.progress, self.total, self.done = progress, total, 0

    def __call__(self, stage: str) -> None:
        if self.progress is not None:
            self.progress(stage, self.done, self.total)
        self.done += 1

    def finish(self) -> None:
        if self.progress is not None:
            self.progress("done", self.total, self.total)


def _against_assignment(rc: RigidConstraints, rho: np.ndarray) -> int:
    """Number of M/V creases folded (> 1e-6 rad) against their assignment."""
    src = rc.var_source_edge
    ok = src >= 0
    asg = rc.source.assignment[src[ok]]
    r = rho[ok]
    return int(np.sum(((asg == "V") & (r < -1e-6)) | ((asg == "M") & (r > 1e-6))))


def _join(a: str, b: str) -> str:
    return f"{a}; {b}" if a else b


def _state_angles(rc: RigidConstraints, state: Any) -> np.ndarray:
    """(n_var,) radians from a state given per pattern edge in degrees (None: reference)."""
    if state is None:
        return rc.rho0.copy()
    s = np.asarray(state, dtype=float).ravel()
    if len(s) != rc.source.n_edges:
        raise ConfigError(
            f"state must be fold angles per edge ({rc.source.n_edges},) or coordinates "
            f"({rc.source.n_vertices}, 3); got shape {np.shape(state)}"
        )
    rho = np.zeros(rc.n_var)
    vs = rc.var_source_edge
    rho[vs >= 0] = np.radians(s[vs[vs >= 0]])
    return rho


def system(rc: RigidConstraints, rho: np.ndarray) -> tuple[np.ndarray, sp.csr_matrix]:
    """Residual and Jacobian of all the closure conditions at ``rho`` (n_var,) radians:
    the vertex loops (3 rows each) followed by the chains around holes (6 rows each)."""
    r, J = rc.evaluate(rho)
    hl = hole_loops(rc)
    if hl.n_holes == 0:
        return r, J
    rh, Jh = hl.evaluate(rho)
    return np.concatenate([r, rh]), sp.vstack([J, Jh], format="csr")


def closure_errors(rc: RigidConstraints, rho: np.ndarray) -> np.ndarray:
    """Closure error ``|F - I|`` of every vertex loop followed by that of every hole chain
    (``|R - I| + |t| / size``)."""
    return np.concatenate([rc.closure_error(rho), hole_loops(rc).closure_error(rho)])


def _report(
    rc: RigidConstraints,
    rho: np.ndarray,
    *,
    prefer: Any,
    tol: float | None,
    tick: Callable[[str], None] = lambda stage: None,
) -> DofReport:
    tick(f"rank of the {rc.n_var}-crease Jacobian")
    r, J = system(rc, rho)
    flat = bool(np.max(np.abs(rho), initial=0.0) < FLAT_TOL)
    ns = null_space(J, tol, basis_limit=FLAT_BASIS_LIMIT if flat else None)
    n_faces_extra = 0 if rc.triangulated else sum(len(f) - 3 for f in rc.pattern.faces)
    e_in_tri = rc.n_var + n_faces_extra
    n_holes = hole_loops(rc).n_holes
    counted = e_in_tri - 3 * len(rc.vertices) - 6 * n_holes - n_faces_extra
    g = rc.n_var - ns.rank
    closure = float(closure_errors(rc, rho).max(initial=0.0))
    try:  # a failing library (an SVD or QR that does not converge) is a named error
        tick("local and region DOF")
        local, region = local_dof(rc, rho, tol=tol)
        tick("actuators")
        acts = select_actuators(rc, ns, prefer=prefer)
    except (np.linalg.LinAlgError, MemoryError) as exc:
        raise RankError(
            f"local DOF or actuator choice failed: {type(exc).__name__}: {exc}"
        ) from exc
    note = ""
    if closure > 1e-8:
        note = (
            f"the state does not close (max |F - I| = {closure:.2e}): the rank is that of the "
            "linearisation at a non-rigid state"
        )
    lo, hi = (rc.n_var - ns.rank_candidates[1], rc.n_var - ns.rank_candidates[0])
    if not ns.certain:
        note = _join(
            note,
            f"uncertain rank: gap ratio {ns.gap_ratio:.1e} < 1e3 at the cut (σ {ns.sigma_below:.2e}"
            f" counted zero, {ns.sigma_gap:.2e} non-zero); the DOF is between {lo} and {hi}",
        )
    if ns.basis is None:
        note = _join(
            note,
            f"no actuators chosen at this flat state: its first-order null space has {g} "
            "vectors (a bifurcation point); the folded state nearby, when found, gives them",
        )
    elif len(acts) < g:
        note = _join(
            note,
            f"only {len(acts)} of {g} DOF can be driven by pattern creases "
            "(the others move panel diagonals)",
        )
    return DofReport(
        global_dof=g,
        counted_dof=int(counted),
        redundant=int(g - counted),
        rank=ns.rank,
        tolerance=ns.tolerance,
        sigma_gap=ns.sigma_gap,
        method=ns.method,
        n_variables=rc.n_var,
        n_equations=J.shape[0],
        n_interior_vertices=len(rc.vertices),
        flat=flat,
        local=local,
        region=region,
        actuators=acts,
        triangulated=rc.triangulated,
        closure=closure,
        note=note,
        fold_angles_deg=rc.angles_of_edges(rho),
        sigma_below=ns.sigma_below,
        gap_ratio=ns.gap_ratio,
        certain=ns.certain,
        dof_range=(int(lo), int(hi)),
    )


# ------------------------------------------------------------------------- local DOF
def _vertex_blocks(rc: RigidConstraints, rho: np.ndarray) -> np.ndarray:
    """(n_cv, 3, D) dense Jacobian block of each vertex (zero columns at padding)."""
    F, A = rc.loop_products(rho)
    tr = np.trace(F, axis1=1, axis2=2)
    G = 0.5 * (tr[:, None, None] * np.eye(3) - F)
    B = np.einsum("vij,vdj->vid", G, A)
    B[np.broadcast_to((rc.loop_var < 0)[:, None, :], B.shape)] = 0.0
    return B


def local_dof(
    rc: RigidConstraints, rho: np.ndarray, *, tol: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Local DOF per vertex and per one-ring region.

    Returns
    -------
    local : (n_vertices,) int
        ``degree - rank(block)`` at constrained vertices, -1 elsewhere.
    region : (n_vertices,) int
        ``(creases touching the region) - rank(rows of the region)`` for the region made of
        the vertex and its neighbouring constrained vertices, -1 elsewhere.
    """
    n = rc.pattern.n_vertices
    local = -np.ones(n, dtype=np.int64)
    region = -np.ones(n, dtype=np.int64)
    nv = len(rc.vertices)
    if nv == 0:
        return local, region
    rel = 1e-8 if tol is None else tol
    B = _vertex_blocks(rc, rho)
    deg = (rc.loop_var >= 0).sum(1)
    s = np.linalg.svd(B, compute_uv=False)  # (nv, min(3, D))
    rank_v = (s > rel * np.maximum(s.max(1, keepdims=True), 1e-300)).sum(1)
    local[rc.vertices] = deg - rank_v
    region[rc.vertices] = _region_dof(rc.loop_var, B, rel)
    return local, region


def _region_members(loop_var: np.ndarray) -> np.ndarray:
    """(n_cv, R) int: each constrained vertex followed by the constrained vertices that share
    a crease with it (-1 padding); a crease variable lies in at most two vertex loops."""
    nv, D = loop_var.shape
    ok = loop_var >= 0
    owner = np.broadcast_to(np.arange(nv)[:, None], (nv, D))[ok]
    var = loop_var[ok]
    order = np.argsort(var, kind="stable")
    var, owner = var[order], owner[order]
    same = np.flatnonzero(var[1:] == var[:-1])  # the two loops of a shared crease
    a, b = owner[same], owner[same + 1]
    src = np.concatenate([a, b])
    dst = np.concatenate([b, a])
    pairs = np.unique(np.column_stack([src, dst]), axis=0)  # sorted by src
    cnt = np.bincount(pairs[:, 0], minlength=nv)
    R = 1 + int(cnt.max(initial=0))
    members = -np.ones((nv, R), dtype=np.int64)
    members[:, 0] = np.arange(nv)
    start = np.concatenate([[0], np.cumsum(cnt)[:-1]])
    slot = 1 + np.arange(len(pairs)) - start[pairs[:, 0]]
    members[pairs[:, 0], slot] = pairs[:, 1]
    return members


def _region_dof(
    loop_var: np.ndarray, B: np.ndarray, rel: float, chunk_bytes: float = 64e6
) -> np.ndarray:
    """(n_cv,) DOF of each one-ring region: ``(creases of the region) - rank`` of its stacked
    vertex blocks ``B`` (n_cv, 3, D), all regions at once (batched SVD, in chunks that keep
    the stacked matrices below ``chunk_bytes``)."""
    nv, D = loop_var.shape
    members = _region_members(loop_var)
    R = members.shape[1]
    # variables of every (region, member, slot); -1 where the member or slot is padding
    V = np.where(members[:, :, None] >= 0, loop_var[np.maximum(members, 0)], -1)  # (nv, R, D)
    flat = V.reshape(nv, R * D)
    big = np.iinfo(np.int64).max
    key = np.where(flat >= 0, flat, big)
    order = np.argsort(key, axis=1, kind="stable")
    srt = np.take_along_axis(key, order, axis=1)
    new = np.ones_like(srt, dtype=bool)
    new[:, 1:] = srt[:, 1:] != srt[:, :-1]
    pos_sorted = np.cumsum(new, axis=1) - 1
    pos = np.empty_like(pos_sorted)
    np.put_along_axis(pos, order, pos_sorted, axis=1)  # column of each entry in its region
    nvar = np.sum(new & (srt != big), axis=1)
    C = int(nvar.max(initial=0))
    out = np.zeros(nv, dtype=np.int64)
    per = max(1, int(chunk_bytes // (8 * 3 * R * max(C, 1))))
    rows3 = np.arange(3)
    for lo in range(0, nv, per):  # a few chunks, not a loop over vertices
        hi = min(nv, lo + per)
        n = hi - lo
        M = np.zeros((n, R, 3, C))
        Vc = V[lo:hi]
        i, r, d = np.nonzero(Vc >= 0)
        p = pos[lo:hi].reshape(n, R, D)[i, r, d]
        w = members[lo:hi][i, r]
        M[i[:, None], r[:, None], rows3[None, :], p[:, None]] = B[w, :, d]
        s = np.linalg.svd(M.reshape(n, 3 * R, C), compute_uv=False)
        smax = np.maximum(s.max(1, initial=0.0), 1e-300)
        out[lo:hi] = nvar[lo:hi] - (s > rel * smax[:, None]).sum(1)
    return out


# ------------------------------------------------------------------------- actuators
def _edge_hops_to_boundary(cp: CreasePattern) -> np.ndarray:
    """(n_edges,) int: graph distance (in vertices) from each edge to the boundary."""
    n = cp.n_vertices
    E = cp.edges
    A = sp.coo_matrix((np.ones(2 * len(E)), (E.ravel(), E[:, ::-1].ravel())), shape=(n, n)).tocsr()
    dist = np.full(n, np.iinfo(np.int64).max)
    front = np.zeros(n, bool)
    front[cp.boundary_vertices] = True
    d = 0
    seen = front.copy()
    while front.any():
        dist[front] = d
        nxt = (A @ front.astype(float)) > 0
        front = nxt & ~seen
        seen |= front
        d += 1
    dist[dist == np.iinfo(np.int64).max] = d
    return np.minimum(dist[E[:, 0]], dist[E[:, 1]])


def select_actuators(
    rc: RigidConstraints, ns: NullSpace, *, prefer: str | Sequence[int] | None = None
) -> np.ndarray:
    """Pattern edge ids of creases whose fold angles determine the configuration.

    Column-pivoted QR of the weighted null-space basis ``(N * w).T``: the k pivots have an
    invertible, well conditioned ``N[A, :]``, so fixing their increments fixes the whole first
    order motion. Panel diagonals (triangulated mode) are never chosen. None are chosen when
    the null space was not formed (``ns.basis`` is None).

    Parameters
    ----------
    prefer : None, "boundary", "interior", "spread" or sequence of edge ids
        See :func:`dof`.
    """
    N = ns.basis
    if N is None or N.shape[1] == 0:
        return np.zeros(0, dtype=np.int64)
    src = rc.var_source_edge
    w = np.ones(rc.n_var)
    spread = False
    if prefer is None:
        pass
    elif isinstance(prefer, str):
        if prefer not in ("boundary", "interior", "spread"):
            raise ConfigError(
                f"prefer = {prefer!r}; expected 'boundary', 'interior', 'spread' or edge ids"
            )
        if prefer == "spread":
            spread = True
        else:
            hops = _edge_hops_to_boundary(rc.source)[np.maximum(src, 0)].astype(float)
            w = 0.5**hops if prefer == "boundary" else 0.5 ** (hops.max() - hops)
    else:
        ids = np.asarray(list(prefer), dtype=np.int64)
        if ids.size and (ids.min() < 0 or ids.max() >= rc.source.n_edges):
            raise ConfigError(
                f"prefer lists edge ids outside 0..{rc.source.n_edges - 1}: {ids.tolist()[:5]}"
            )
        w = np.full(rc.n_var, 1e-3)
        v = rc.var_of_source_edge[ids]
        w[v[v >= 0]] = 1.0
    w = np.where(src >= 0, w, 0.0)
    W = (N * w[:, None]).T  # (k, n_var)
    if spread:
        piv = _greedy_spread(rc, W)
    else:
        _, R, P = sla.qr(W, mode="economic", pivoting=True)
        d = np.abs(np.diag(R))
        good = d > 1e-8 * max(d[0], 1e-300) if len(d) else np.zeros(0, bool)
        piv = P[: int(good.sum())]
    return np.sort(src[piv]).astype(np.int64)


def _greedy_spread(rc: RigidConstraints, W: np.ndarray) -> np.ndarray:
    """Pivoted Gram-Schmidt on the columns of W (k, n) that damps the neighbours (creases
    sharing a vertex) of every chosen crease by 0.1, spreading the actuators out."""
    k, n = W.shape
    E = rc.pattern.edges[rc.crease_edge]
    inc = sp.coo_matrix(
        (np.ones(2 * n), (np.repeat(np.arange(n), 2), E.ravel())), shape=(n, rc.pattern.n_vertices)
    ).tocsr()
    nbr = (inc @ inc.T).tocsr()
    R = W.copy()
    damp = np.ones(n)
    norms0 = np.linalg.norm(W, axis=0)
    ref = norms0.max() if n else 1.0
    chosen: list[int] = []
    for _ in range(k):
        norms = np.linalg.norm(R, axis=0)
        score = norms * damp
        j = int(np.argmax(score))
        if norms[j] <= 1e-8 * ref:
            break
        chosen.append(j)
        q = R[:, j] / norms[j]
        R -= np.outer(q, q @ R)
        damp[nbr[j].indices] *= 0.1
    return np.asarray(chosen, dtype=np.int64)


# ------------------------------------------------------------------------- folded sample
def _branch_direction(rc: RigidConstraints) -> np.ndarray:
    """(n_var,) direction to leave the flat state: the pattern's target fold angles where
    given, else the assignment signs (V +1, M -1)."""
    src = rc.var_source_edge
    tgt = np.zeros(rc.n_var)
    ok = src >= 0
    tgt[ok] = np.radians(np.asarray(rc.source.fold_angles)[src[ok]])
    if np.any(tgt != 0.0):
        return tgt
    asg = np.where(ok, rc.source.assignment[np.maximum(src, 0)], "F")
    return np.where(asg == "V", 1.0, np.where(asg == "M", -1.0, 0.0))


def folded_sample(
    rc: RigidConstraints, *, magnitude: float = 0.3, max_iter: int = 50
) -> np.ndarray:
    """A rigidly folded state near the flat one.

    The branch direction (target angles, else M/V signs; unassigned ``U`` and ``F`` creases
    have no sign and start at 0, free to fold either way) is scaled to ``magnitude`` rad; the
    crease with the largest component is held there and the others are projected onto the
    constraints by minimum-norm Gauss-Newton (holding one crease keeps the projection from
    collapsing onto the flat apex of the configuration cone). When full steps from that guess
    do not close, the hold is raised in steps (magnitude / 8, / 4, / 2, 1, each predicted
    from the last) and a step is halved until the closure error ``sum |F - I|²`` falls: the
    residual ``vee(skew F)`` also vanishes at loops turned by 180°, which an unguarded step
    can land on. Raises PatternError if no folded state is found (e.g. a pattern that is not
    rigidly foldable).
    """
    d = _branch_direction(rc)
    if not np.any(d):
        raise PatternError("no folded state: the pattern has no assignment or target angles")
    d = d / np.max(np.abs(d))
    hold = int(np.argmax(np.abs(d)))
    free = np.ones(rc.n_var, bool)
    free[hold] = False
    backend = None
    if rc.n_var > STEP_DENSE_LIMIT:
        from barhinge.linalg.backends import get_backend

        backend = get_backend("auto")

    def merit(x: np.ndarray) -> float:
        return float(np.sum(closure_errors(rc, x) ** 2))

    def project(rho: np.ndarray, cols: np.ndarray, guarded: bool) -> np.ndarray:
        m = merit(rho)
        slow = 0
        for _ in range(max_iter):
            r, J = system(rc, rho)
            if np.max(np.abs(r), initial=0.0) < 1e-13 and m < 1e-20:
                break
            step = np.zeros(rc.n_var)
            step[cols] = _min_norm_step(J[:, cols], -r, backend)
            lam = 1.0
            if guarded and m > 1e-8:  # near a solution full steps converge quadratically
                while lam > 1e-4 and merit(rho + lam * step) >= m:
                    lam *= 0.5
                if lam <= 1e-4:
                    break  # no descent: a local minimum of the closure error
            rho = rho + lam * step
            m_old, m = m, merit(rho)
            # stalled (5 steps in a row gaining < 1 %: a local minimum or a singular point)
            slow = slow + 1 if m > 0.99 * m_old else 0
            if slow >= 5:
                break
        return rho

    best: tuple[float, np.ndarray | None] = (np.inf, None)
    collapsed = False
    for guarded in (False, True):
        for fix in (True, False):
            cols = np.flatnonzero(free) if fix else np.arange(rc.n_var)
            ts = magnitude * (np.array([0.125, 0.25, 0.5, 1.0]) if guarded else np.ones(1))
            rho = np.zeros(rc.n_var)
            t_prev = 0.0
            for t in ts:
                # predictor: the last state scaled (a cone through the flat state), else d
                rho = rho * (t / t_prev) if t_prev > 0 else t * d
                rho[hold] = t * d[hold]
                t_prev = t
                rho = project(rho, cols, guarded)
            err = float(closure_errors(rc, rho).max(initial=0.0))
            if err <= 1e-9:
                if np.max(np.abs(rho)) >= 1e-3 * magnitude:
                    return rho
                collapsed = True
            elif err < best[0]:
                best = (err, rho)
    if collapsed:
        raise PatternError(
            "the projection of the M/V direction onto the constraints collapses to the flat "
            "state: the pattern is not rigidly foldable (with rigid panels)"
        )
    raise PatternError(
        f"no rigidly folded state found near the flat one (closure error {best[0]:.1e})"
    )


def _min_norm_step(J: sp.csr_matrix, b: np.ndarray, backend: Any = None) -> np.ndarray:
    """Minimum-norm least-squares solution of ``J x = b``: dense ``gelsd`` for small ``J``,
    else ``(JᵀJ + μI) x = Jᵀb`` with ``μ = 1e-12 ‖JᵀJ‖₁`` by one sparse factorisation (the
    damping keeps ``x`` out of the null space of a rank-deficient ``J``; a Krylov
    least-squares solver needed 10⁴–10⁵ iterations on real patterns)."""
    m, n = J.shape
    if n <= STEP_DENSE_LIMIT:
        return sla.lstsq(J.toarray(), b, cond=1e-9, lapack_driver="gelsd")[0]
    from barhinge.linalg.backends import get_backend

    J = sp.csr_matrix(J)
    N = (J.T @ J).tocsr()
    mu = 1e-12 * max(float(abs(N).sum(axis=0).max()), 1e-300)
    A = (N + mu * sp.identity(n, format="csr")).tocsr()
    try:
        fac = (backend or get_backend("auto")).factorize(A)
        return np.asarray(fac.solve(J.T @ b)).ravel()
    except Exception as exc:  # a failing library must not leave a traceback
        raise RankError(f"least-squares step of the folded-state projection failed: {exc}") from exc
