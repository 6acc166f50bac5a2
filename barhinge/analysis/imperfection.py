"""Initial geometric imperfections: a model whose stress-free reference is moved along a
shape (usually the first linear buckling mode), for the nonlinear check of structures whose
perfect path passes near a bifurcation.

The imperfect model keeps the stiffnesses and connectivity of the perfect one; its bar rest
lengths and hinge rest angles are those of the moved reference, so it is stress-free there.
This is the "equivalent geometric imperfection" of design codes: the shape of the relevant
buckling mode with an amplitude set by fabrication tolerances (EN 1993-1-5:2006, Annex C,
C.5: ``min(a, b) / 200`` for the local buckling of a plate panel of sides ``a, b``;
EN 1993-1-6:2007, 8.7 for shells). A scene asks for one with ``[imperfection]``
(:class:`barhinge.scene.Imperfection`); :func:`seed_imperfection` applies it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from barhinge.errors import ConfigError
from barhinge.kernels.geometry import hinge_angle
from barhinge.model.model import BarHingeModel
from barhinge.scene import Scene

__all__ = ["amplitude_length", "imperfect", "panel_side", "seed_imperfection", "span"]


def imperfect(
    model: BarHingeModel,
    shape: np.ndarray,
    amplitude: float,
    loads: np.ndarray | None = None,
) -> BarHingeModel:
    """The model with its stress-free reference moved to ``X0 + a s``.

    Parameters
    ----------
    model : BarHingeModel
        The perfect model.
    shape : (n_nodes, 3) float
        Imperfection shape (e.g. ``linear_buckling(...).modes[0]``); scaled here so that its
        largest nodal displacement is ``amplitude``.
    amplitude : float
        Largest nodal displacement of the imperfection, in the model's length unit (>= 0).
    loads : (n_nodes, 3) float, optional
        With loads, the shape's sign is chosen so that they do positive work on it
        (``P . s > 0``): the imperfection lies the way the loads push the structure, the
        unfavourable sign for a mode that the loads excite.

    Returns
    -------
    BarHingeModel
        Same stiffnesses and connectivity; ``X0``, ``bar_L0`` and ``rest_angle`` of the moved
        reference (so it carries no stress there); ``meta["imperfection"]`` records the
        amplitude.

    Raises
    ------
    ConfigError
        The shape has the wrong size, is not finite or is zero, or the amplitude is negative
        or not finite.
    """
    n = model.n_nodes
    s = np.asarray(shape, dtype=float)
    if s.shape != (n, 3):
        raise ConfigError(f"imperfection shape must have shape ({n}, 3), got {s.shape}")
    if not np.all(np.isfinite(s)):
        raise ConfigError("imperfection shape has non-finite entries")
    if not (np.isfinite(amplitude) and amplitude >= 0):
        raise ConfigError(f"imperfection amplitude = {amplitude!r}; expected a length >= 0")
    size = float(np.linalg.norm(s, axis=1).max(initial=0.0))
    if size == 0.0:
        raise ConfigError("imperfection shape is zero everywhere")
    s = s / size
    if loads is not None:
        P = np.asarray(loads, dtype=float)
        if P.shape != (n, 3):
            raise ConfigError(f"loads must have shape ({n}, 3), got {P.shape}")
        if float(np.sum(P * s)) < 0.0:
            s = -s
    X0 = np.asarray(model.X0) + amplitude * s
    bars = np.asarray(model.bars)
    L0 = np.linalg.norm(X0[bars[:, 1]] - X0[bars[:, 0]], axis=1)
    rest = hinge_angle(X0, np.asarray(model.hinges))
    meta = {**model.meta, "imperfection": {"amplitude": float(amplitude)}}
    return model.with_(X0=X0, bar_L0=L0, rest_angle=rest, meta=meta)


def panel_side(pattern: Any) -> float:
    """Median over the pattern's facets of each facet's shortest side, in its length unit
    (the ``b`` of EN 1993-1-5:2006, Annex C, C.5 for a folded plate)."""
    V = np.asarray(pattern.vertices, dtype=float)
    shortest = [
        float(np.linalg.norm(np.roll(V[f], -1, axis=0) - V[f], axis=1).min())
        for f in (np.asarray(face) for face in pattern.faces)
    ]
    if not shortest:
        raise ConfigError("the pattern has no facets to take a panel side from")
    return float(np.median(shortest))


def span(X: np.ndarray, fixed: np.ndarray, lines: np.ndarray | None = None) -> float:
    """Twice the largest plan (x-y) distance from a node to the supports, in the model's
    length unit: the span of a roof on two supported edges, twice the length of a
    cantilever.

    Parameters
    ----------
    X : (n_nodes, 3) float
        Coordinates.
    fixed : (n_nodes, 3) bool
        Supported DOFs; a node with any of them fixed is supported.
    lines : (k, 2) int, optional
        Node pairs (pattern edges) whose segments are support lines where both ends are
        supported; without them the supports are the supported nodes alone.
    """
    X = np.asarray(X, dtype=float)[:, :2]
    held = np.asarray(np.asarray(fixed, dtype=bool).any(axis=1), dtype=bool)
    if not held.any():
        raise ConfigError("a span needs supported nodes; the scene has none")
    E = np.zeros((0, 2), np.int64) if lines is None else np.asarray(lines, np.int64)
    E = E[held[E[:, 0]] & held[E[:, 1]]]
    i = np.flatnonzero(held)
    A = np.vstack([X[i], X[E[:, 0]]])  # segments A -> B (a supported node: A = B)
    B = np.vstack([X[i], X[E[:, 1]]])
    D = B - A
    dd = np.maximum(np.einsum("kj,kj->k", D, D), np.finfo(float).tiny)
    far = 0.0
    for chunk in np.array_split(np.arange(len(X)), max(1, len(X) * len(A) // 4_000_000 + 1)):
        R = X[chunk, None, :] - A[None]  # (c, k, 2)
        t = np.clip(np.einsum("ckj,kj->ck", R, D) / dd, 0.0, 1.0)
        gap = np.linalg.norm(R - t[..., None] * D[None], axis=2).min(axis=1)
        far = max(far, float(gap.max(initial=0.0)))
    return 2.0 * far


def amplitude_length(scene: Scene) -> float:
    """The scene's imperfection amplitude as a length (model units): the length given, or
    the ``panel/N`` or ``span/N`` rule evaluated on the scene (:class:`Imperfection`)."""
    imp = scene.imperfection
    if imp is None:
        raise ConfigError("the scene asks for no imperfection")
    rule = imp.rule()
    if rule is None:
        return float(imp.amplitude)
    what, n = rule
    if what == "panel":
        pattern = getattr(scene.model, "pattern", None)
        if pattern is None:
            raise ConfigError("imperfection amplitude 'panel/N' needs the model's crease pattern")
        return panel_side(pattern) / n
    if scene.auto_restrained:
        raise ConfigError(
            "imperfection amplitude 'span/N' needs supports; the automatic 3-2-1 restraint has "
            "no span"
        )
    pattern = getattr(scene.model, "pattern", None)
    lines = None if pattern is None else np.asarray(pattern.edges)  # vertices are nodes 0..
    return span(np.asarray(scene.model.X0), scene.fixed, lines) / n


def seed_imperfection(scene: Scene, amplitude: float | None = None) -> Scene:
    """The scene with its model made stress-free in the imperfection the scene asks for.

    The shape is the ``scene.imperfection.mode``-th linear buckling mode of the model under
    ``scene.loads`` at its reference state (:func:`barhinge.analysis.buckling.linear_buckling`),
    on the sign the loads push (:func:`imperfect`). A scene without an imperfection is
    returned as it is.

    Parameters
    ----------
    scene : Scene
    amplitude : float, optional
        The amplitude as a length (model units); default :func:`amplitude_length` of the
        scene (give it to keep the amplitude of another model of the same structure, e.g. a
        refined one).

    Returns
    -------
    Scene
        Same scene, seeded model: ``model.meta["imperfection"]`` holds ``mode``,
        ``buckling_factor``, ``amplitude`` (a length) and ``rule`` (``"panel/N"`` or
        ``"span/N"`` as given, None for a length).

    Raises
    ------
    ConfigError
        A bad amplitude, or fewer positive buckling factors than ``mode``.
    BucklingError
        No buckling factor at all (a mechanism, nothing in compression).
    """
    from barhinge.analysis.buckling import linear_buckling

    imp = scene.imperfection
    if imp is None:
        return scene
    a = amplitude_length(scene) if amplitude is None else float(amplitude)
    b = linear_buckling(scene.model, scene.loads, scene.fixed, n_modes=imp.mode)
    if len(b.factors) < imp.mode:
        raise ConfigError(
            f"imperfection.mode = {imp.mode}, but the loads have only {len(b.factors)} "
            "positive buckling factors"
        )
    model = imperfect(scene.model, b.modes[imp.mode - 1], a, loads=scene.loads)
    record = {
        "mode": imp.mode,
        "buckling_factor": float(b.factors[imp.mode - 1]),
        "amplitude": a,
        "rule": imp.amplitude if isinstance(imp.amplitude, str) else None,
    }
    return scene.with_(model=model.with_(meta={**model.meta, "imperfection": record}))
