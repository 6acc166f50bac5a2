"""Results a structural engineer reads first, at one state of a bar-and-hinge model.

* **Reactions** ``R = f_int(X) - lambda P`` at the fixed (supported or prescribed) DOFs, per
  node, per support group (connected runs of supported vertices along pattern edges, or
  groups the caller names) and in total, with the equilibrium error
  ``|sum R + sum lambda P| / |sum lambda P|`` (forces) and the same for moments about the
  origin (current geometry).
* **Bar axial forces** ``N = (dW/d eps) |d eps/dx|`` (tension > 0): the force a bar exerts on
  its end nodes in the current geometry. For Green strain this is ``EA eps L / L0`` (the
  ``Evaluation.bar_force`` ``EA eps`` is the second Piola-Kirchhoff force); for engineering
  strain ``EA eps``.
* **Membrane stress resultants per panel** (force per length): the panel's mean in-plane
  Green strain ``E`` is the least-squares fit of its bars' strains ``eps_b = e_b^T E e_b``
  (``e_b`` the reference unit bar direction; exact for every homogeneous deformation), and
  ``N = t C E`` with the plane-stress stiffness ``C`` of the material (Voigt
  ``N_xx, N_yy, N_xy`` in the panel frame ``e1, e2`` of
  :func:`barhinge.model.calibrate.face_frames` at the reference state). The bars' own
  calibration error does not enter: the strain comes from kinematics, the stress from the
  continuum law.
* **Hinge moments** ``M = dW/d rho`` (the hinge law; ``k (rho - rho0)`` for the linear law),
  rho in the FOLD convention (valley > 0): ``M > 0`` when the hinge is folded further valley
  than its rest angle; it then pulls back towards mountain. Per crease (pattern edge) also per
  unit crease length.
* **Maximum displacement** ``|x - X0|`` with its node.

Units are the user's: forces in the load's unit, lengths in the pattern's.
"""

from __future__ import annotations

import dataclasses
import weakref
from typing import Any

import numpy as np

from barhinge.errors import ConfigError
from barhinge.model.calibrate import face_frames
from barhinge.model.topology import build_topology
from barhinge.model.triangulate import triangulate

__all__ = [
    "StateResults",
    "state_results",
    "scene_state_results",
    "path_state_results",
    "support_groups",
    "panel_membrane_resultants",
    "bar_axial_forces",
    "results_summary",
]


@dataclasses.dataclass(frozen=True, eq=False)
class StateResults:
    """Forces and displacements of one state (user's units).

    Attributes
    ----------
    displacement : (n_nodes, 3) float
        ``X - X0``.
    max_displacement : float
        Largest ``|X - X0|`` over the nodes.
    max_displacement_node : int
    reactions : (n_nodes, 3) float
        Support reactions (force on the structure), zero at free DOFs.
    reaction_groups : dict str -> (3,) float
        Resultant reaction of each support group.
    reaction_group_nodes : dict str -> (k,) int
    reaction_total : (3,) float
    applied_total : (3,) float
        Resultant of the applied loads ``lambda P``.
    equilibrium_error : float
        ``|reaction_total + applied_total| / |applied_total|`` (absolute if no load).
    moment_error : float
        Same for the moments about the origin, over ``|moment of the loads| + |moment of
        the reactions|``.
    bar_force : (n_bars,) float
        Axial force, tension > 0.
    panel_N : (n_faces, 3) float
        ``N_xx, N_yy, N_xy`` per panel in its frame (force per length).
    panel_N_tensor : (n_faces, 3, 3) float
        The same as a tensor in global axes (for VTU/XDMF cell data).
    hinge_moment : (n_hinges,) float
        ``dW/d rho``, force x length.
    crease_moment : (n_edges,) float
        Moment of the fold hinge of each pattern edge (NaN where none).
    crease_moment_per_length : (n_edges,) float
    load_factor : float
    """

    displacement: np.ndarray
    max_displacement: float
    max_displacement_node: int
    reactions: np.ndarray
    reaction_groups: dict[str, np.ndarray]
    reaction_group_nodes: dict[str, np.ndarray]
    reaction_total: np.ndarray
    applied_total: np.ndarray
    equilibrium_error: float
    moment_error: float
    bar_force: np.ndarray
    panel_N: np.ndarray
    panel_N_tensor: np.ndarray
    hinge_moment: np.ndarray
    crease_moment: np.ndarray
    crease_moment_per_length: np.ndarray
    load_factor: float


def bar_axial_forces(model: Any, X: np.ndarray) -> np.ndarray:
    """(n_bars,) axial force of every bar at ``X`` (n_nodes, 3), tension > 0: the force the
    bar exerts on its end nodes: ``S |d eps/dx|`` with ``S = dW/deps`` (``EA L0 eps`` for a
    bar, so ``EA eps L / L0`` for Green strain and ``EA eps`` for engineering strain; with
    the CST membrane ``S`` includes the couplings ``(C eps)_b``)."""
    return model.element_states(X).bar_axial_force


_FACE_BARS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _face_bars(model: Any) -> tuple[np.ndarray, np.ndarray]:
    """(bar, face) rows of the bars each face's triangulation uses (cached per model)."""
    try:
        return _FACE_BARS[model]
    except (KeyError, TypeError):
        pass
    topo = build_topology(model.pattern, triangulate(model.pattern, model.scheme))
    if not np.array_equal(topo.bars, model.bars):
        raise ConfigError("the model's bars do not match its pattern's triangulation")
    bf = topo.bar_face_pairs
    out = (bf[:, 0].copy(), bf[:, 1].copy())
    try:
        _FACE_BARS[model] = out
    except TypeError:  # not weak-referenceable: no cache
        pass
    return out


@dataclasses.dataclass(frozen=True)
class _MembraneFit:
    """What the membrane fit of a model's panels needs that no state changes: the bar rows
    of each face (ends ``ends``, reference lengths ``L0``, face ``face``), the rows ``A`` of
    ``eps_b = A . (E_xx, E_yy, E_xy)``, the normal matrices ``AtA`` (n_faces, 3, 3) and
    the reference panel frames ``e1``, ``e2`` (n_faces, 3)."""

    ends: np.ndarray
    L0: np.ndarray
    face: np.ndarray
    A: np.ndarray
    AtA: np.ndarray
    e1: np.ndarray
    e2: np.ndarray


_MEMBRANE_FIT: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _membrane_fit(model: Any) -> _MembraneFit:
    """The state-independent part of :func:`panel_membrane_resultants` (cached per model;
    models are frozen). Raises ConfigError for a face whose bars fix no membrane strain."""
    try:
        return _MEMBRANE_FIT[model]
    except (KeyError, TypeError):
        pass
    cp = model.pattern
    X0 = np.asarray(model.X0, float)
    bars, faces = _face_bars(model)
    nf = cp.n_faces
    fids = np.arange(nf)
    e1 = np.zeros((nf, 3))
    e2 = np.zeros((nf, 3))
    sizes = np.array([len(f) for f in cp.faces])
    for k in np.unique(sizes):
        sel = np.flatnonzero(sizes == k)
        a, b, _ = face_frames(X0, cp.faces, fids[sel])
        e1[sel], e2[sel] = a, b
    ends = np.asarray(model.bars, np.int64)[bars]
    dx0 = X0[ends[:, 1]] - X0[ends[:, 0]]
    L0 = np.linalg.norm(dx0, axis=1)
    e = dx0 / L0[:, None]
    c1 = np.einsum("ni,ni->n", e, e1[faces])
    c2 = np.einsum("ni,ni->n", e, e2[faces])
    A = np.column_stack([c1 * c1, c2 * c2, 2.0 * c1 * c2])  # eps_b = A . (Exx, Eyy, Exy)
    AtA = np.zeros((nf, 3, 3))
    np.add.at(AtA, faces, A[:, :, None] * A[:, None, :])
    rank = np.linalg.matrix_rank(AtA)
    if (rank < 3).any():
        raise ConfigError(
            f"face {int(np.flatnonzero(rank < 3)[0])} has fewer than three independent bar "
            "directions: its membrane strain is undetermined"
        )
    fit = _MembraneFit(ends=ends, L0=L0, face=faces, A=A, AtA=AtA, e1=e1, e2=e2)
    try:
        _MEMBRANE_FIT[model] = fit
    except TypeError:  # not weak-referenceable: no cache
        pass
    return fit


def panel_membrane_resultants(model: Any, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Membrane stress resultants of every panel (face) at ``X`` (module docstring).

    Returns
    -------
    N : (n_faces, 3) float
        ``N_xx, N_yy, N_xy`` in the panel frame at the reference state (force per length).
    N_global : (n_faces, 3, 3) float
        ``N_ab e_a (x) e_b`` in global axes.
    """
    fit = _membrane_fit(model)
    X = np.asarray(X, float)
    nf = len(fit.AtA)
    dx = X[fit.ends[:, 1]] - X[fit.ends[:, 0]]
    eps = 0.5 * (np.einsum("ni,ni->n", dx, dx) / fit.L0**2 - 1.0)  # Green strain of each row
    # normal equations per face, vectorised: (nf, 3)
    Atb = np.column_stack(
        [np.bincount(fit.face, fit.A[:, j] * eps, minlength=nf) for j in range(3)]
    )
    E = np.linalg.solve(fit.AtA, Atb[:, :, None])[:, :, 0]  # Exx, Eyy, Exy (tensor shear)
    mat = model.material
    C = (
        mat.E
        / (1.0 - mat.nu**2)
        * np.array([[1.0, mat.nu, 0.0], [mat.nu, 1.0, 0.0], [0.0, 0.0, 1.0 - mat.nu]])
    )
    N = mat.t * (E @ C.T)  # third row of C times Exy gives (1 - nu) Exy = gamma (1-nu)/2
    e1, e2 = fit.e1, fit.e2
    Ng = (
        N[:, 0, None, None] * e1[:, :, None] * e1[:, None, :]
        + N[:, 1, None, None] * e2[:, :, None] * e2[:, None, :]
        + N[:, 2, None, None] * (e1[:, :, None] * e2[:, None, :] + e2[:, :, None] * e1[:, None, :])
    )
    return N, Ng


def support_groups(model: Any, fixed: np.ndarray) -> dict[str, np.ndarray]:
    """Supported nodes grouped into runs connected through the pattern's faces (two
    supported vertices of one face are in one group; two pinned roof edges are two groups),
    named ``"support 0"``, ``"support 1"`` ... in order of their lowest node id."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    F = np.asarray(fixed, bool).any(axis=1)
    n = len(F)
    rows, cols = [], []
    for f in model.pattern.faces:
        s = [v for v in f if F[v]]
        rows += s[:-1]
        cols += s[1:]
    G = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    _, lab = connected_components(G, directed=False)
    nodes = np.flatnonzero(F)
    out: dict[str, np.ndarray] = {}
    for i, lb in enumerate(dict.fromkeys(lab[nodes].tolist())):
        out[f"support {i}"] = nodes[lab[nodes] == lb]
    return out


def state_results(
    model: Any,
    X: np.ndarray,
    fixed: np.ndarray,
    loads: np.ndarray | None = None,
    load_factor: float = 1.0,
    groups: dict[str, Any] | None = None,
    reactions: np.ndarray | None = None,
) -> StateResults:
    """Reactions, bar forces, panel stress resultants, hinge moments and the largest
    displacement at the state ``X``.

    Parameters
    ----------
    model : BarHingeModel
    X : (n_nodes, 3) float
        The state (an equilibrium state for the reactions to balance the loads).
    fixed : (n_nodes, 3) bool
        Supported and prescribed DOFs.
    loads : (n_nodes, 3) float, optional
        Reference loads ``P``; the applied loads are ``load_factor * P``.
    groups : dict name -> node ids, optional
        Support groups (default :func:`support_groups`).
    reactions : (n_nodes, 3) float, optional
        The reactions the solver recorded (``FoldPath.reactions``): needed when actuators
        act, whose constraint forces the model's internal force does not include. Default:
        ``f_int - load_factor * P`` at the fixed DOFs.

    The equilibrium errors are relative to the forces at play, ``sum |R_i| + sum |lambda P_i|
    + sum |f_int,i|`` over the nodes (times the extent of ``X`` for moments; zero when no
    force acts).
    """
    n = model.n_nodes
    X = np.asarray(X, float).reshape(n, 3)
    F = np.asarray(fixed, bool)
    if F.shape != (n, 3):
        raise ConfigError(f"fixed must have shape ({n}, 3), got {F.shape}")
    P = np.zeros((n, 3)) if loads is None else np.asarray(loads, float)
    if P.shape != (n, 3):
        raise ConfigError(f"loads must have shape ({n}, 3), got {P.shape}")
    lam = float(load_factor)
    ev = model.evaluate(X, tangent=False)
    fint = ev.force.reshape(n, 3)
    R = np.where(F, fint - lam * P, 0.0)
    if reactions is not None:
        R = np.where(F, np.asarray(reactions, float).reshape(n, 3), 0.0)
    if groups is None:
        groups = support_groups(model, F)
    gnodes = {str(k): np.asarray(v, np.int64).ravel() for k, v in groups.items()}
    for k, v in gnodes.items():
        if v.size and (v.min() < 0 or v.max() >= n):
            raise ConfigError(f"support group {k!r} names a node outside 0..{n - 1}")
    rgroups = {k: R[v].sum(axis=0) for k, v in gnodes.items()}
    Rt, Pt = R.sum(axis=0), lam * P.sum(axis=0)
    flow = float(
        np.linalg.norm(R, axis=1).sum()
        + np.linalg.norm(lam * P, axis=1).sum()
        + np.linalg.norm(fint, axis=1).sum()
    )
    eq = float(np.linalg.norm(Rt + Pt)) / flow if flow > 0 else 0.0
    mR = np.cross(X, R).sum(axis=0)
    mP = np.cross(X, lam * P).sum(axis=0)
    mscale = flow * float(np.linalg.norm(np.ptp(X, axis=0)))
    meq = float(np.linalg.norm(mR + mP)) / mscale if mscale > 0 else 0.0
    U = X - np.asarray(model.X0, float)
    u = np.linalg.norm(U, axis=1)
    imax = int(np.argmax(u))
    N, Ng = panel_membrane_resultants(model, X)
    ne = model.pattern.n_edges
    ce = np.full(ne, np.nan)
    h = np.asarray(model.fold_hinge_of_edge)
    has = h >= 0
    ce[has] = ev.hinge_moment[h[has]]
    V = np.asarray(model.pattern.vertices3d, float) if ne else np.zeros((0, 3))
    Ed = np.asarray(model.pattern.edges, np.int64)
    length = np.linalg.norm(V[Ed[:, 1]] - V[Ed[:, 0]], axis=1) if ne else np.zeros(0)
    return StateResults(
        displacement=U,
        max_displacement=float(u[imax]),
        max_displacement_node=imax,
        reactions=R,
        reaction_groups=rgroups,
        reaction_group_nodes=gnodes,
        reaction_total=Rt,
        applied_total=Pt,
        equilibrium_error=eq,
        moment_error=meq,
        bar_force=bar_axial_forces(model, X),
        panel_N=N,
        panel_N_tensor=Ng,
        hinge_moment=np.asarray(ev.hinge_moment, float),
        crease_moment=ce,
        crease_moment_per_length=ce / np.where(length > 0, length, np.nan),
        load_factor=lam,
    )


def scene_state_results(
    scene: Any,
    X: np.ndarray,
    load_factor: float = 1.0,
    groups: dict[str, Any] | None = None,
    reactions: np.ndarray | None = None,
) -> StateResults:
    """:func:`state_results` of a ``Scene`` at ``X``: supports and prescribed DOFs are the
    fixed DOFs, the scene's loads the reference loads."""
    fixed = np.asarray(scene.supports, bool).copy()
    if scene.prescribed is not None:
        fixed |= np.isfinite(np.asarray(scene.prescribed, float))
    return state_results(scene.model, X, fixed, scene.loads, load_factor, groups, reactions)


def path_state_results(
    fold_path: Any, scene: Any, step: int = -1, groups: dict[str, Any] | None = None
) -> StateResults:
    """:func:`scene_state_results` at state ``step`` of a solved ``FoldPath``, with the
    reactions the solver recorded (they include the actuators' constraint forces)."""
    lam = 1.0
    if fold_path.load_factor is not None:
        lam = float(np.asarray(fold_path.load_factor)[step])
    R = None if fold_path.reactions is None else np.asarray(fold_path.reactions)[step]
    return scene_state_results(scene, np.asarray(fold_path.X)[step], lam, groups, reactions=R)


def results_summary(res: StateResults) -> dict[str, Any]:
    """JSON-ready headline numbers of :class:`StateResults` (user's units)."""

    def absmax(a: np.ndarray) -> float:
        a = np.asarray(a, float)
        a = a[np.isfinite(a)]
        return float(np.abs(a).max()) if a.size else 0.0

    return {
        "max_displacement": res.max_displacement,
        "max_displacement_node": res.max_displacement_node,
        "reaction_total": res.reaction_total.tolist(),
        "reactions_by_support": {k: v.tolist() for k, v in res.reaction_groups.items()},
        "applied_load_total": res.applied_total.tolist(),
        "equilibrium_error": res.equilibrium_error,
        "moment_equilibrium_error": res.moment_error,
        "max_tension": float(max(res.bar_force.max(initial=0.0), 0.0)),
        "max_compression": float(max(-res.bar_force.min(initial=0.0), 0.0)),
        "max_membrane_resultant": absmax(res.panel_N),
        "max_crease_moment": absmax(res.crease_moment),
        "max_crease_moment_per_length": absmax(res.crease_moment_per_length),
        "max_hinge_moment": absmax(res.hinge_moment),
        "load_factor": res.load_factor,
    }
