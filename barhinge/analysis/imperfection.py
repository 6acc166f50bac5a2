"""Initial geometric imperfections: a model whose stress-free reference is moved along a
shape (usually the first linear buckling mode), for the nonlinear check of structures whose
perfect path passes near a bifurcation.

The imperfect model keeps the stiffnesses and connectivity of the perfect one; its bar rest
lengths and hinge rest angles are those of the moved reference, so it is stress-free there.
This is the "equivalent geometric imperfection" of design codes: the shape of the relevant
buckling mode with an amplitude set by fabrication tolerances (EN 1993-1-5:2006, Annex C,
C.5: ``min(a, b) / 200`` for the local buckling of a plate panel of sides ``a, b``;
EN 1993-1-6:2007, 8.7 for shells).
"""

from __future__ import annotations

import numpy as np

from barhinge.errors import ConfigError
from barhinge.kernels.geometry import hinge_angle
from barhinge.model.model import BarHingeModel

__all__ = ["imperfect"]


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
