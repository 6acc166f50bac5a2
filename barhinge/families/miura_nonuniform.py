"""Non-uniform Miura-ori: panel lengths varying column by column and row by row.

Source: the Miura-ori with varying panel lengths but one sector angle is a first-level
derivative of Gattas, Wu & You, "Miura-base rigid origami: parameterizations of first-level
derivative and piecewise geometries", J. Mech. Des. 135(11):111011, 2013; because every
vertex keeps the sector angles (gamma, pi - gamma, pi - gamma, gamma), all vertices fold
with the same fold angles and the folded state is exact: each facet is a Schenk & Guest (2013)
Miura parallelogram of its own side lengths (see :func:`miura_grid_coords`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from barhinge.errors import PatternError
from barhinge.families._common import GridLayout, build_pattern, check_range, mv_assignment
from barhinge.families.miura import DEFAULT_TARGET_THETA, miura_fold_angles, miura_grid_coords
from barhinge.pattern.crease import CreasePattern

__all__ = ["miura_from_lengths", "miura_nonuniform"]


def _lengths(name: str, values: Sequence[float], fam: str) -> np.ndarray:
    try:
        arr = np.asarray(values, dtype=float).ravel()
    except (TypeError, ValueError):
        raise PatternError(f"{fam}: {name} must be a list of lengths, got {values!r}") from None
    if len(arr) < 2:
        raise PatternError(f"{fam}: {name} needs at least 2 panel lengths, got {len(arr)}")
    bad = ~(np.isfinite(arr) & (arr > 0))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise PatternError(f"{fam}: {name}[{k}] = {arr[k]!r} is outside the valid range (0, inf)")
    return arr


def miura_nonuniform(
    a: Sequence[float] = (1.0, 0.6, 1.0, 0.6, 1.0, 0.6),
    b: Sequence[float] = (1.0, 1.0, 0.5, 0.5, 1.0, 1.0),
    alpha: float = 60.0,
    fold: float | None = None,
    target: float = DEFAULT_TARGET_THETA,
) -> CreasePattern:
    """Miura-ori with panel lengths ``a[i]`` along x (straight creases) and ``b[j]`` along the
    zig-zag creases (y).

    Parameters
    ----------
    a : sequence of float
        Lengths of the panels along x (one per column of facets, >= 2 values, each > 0).
    b : sequence of float
        Side lengths of the facets along the zig-zag creases (one per row, >= 2 values).
    alpha : float
        Sector angle gamma, degrees in (0, 90).
    fold : float or None
        Facet angle theta (degrees, [0, 90]) of the exact folded state; None: flat pattern.
    target : float
        Facet angle whose fold angles become the flat pattern's targets.

    Returns
    -------
    CreasePattern
        Same vertex/edge order and M/V assignment as :func:`miura` with
        ``meta['barhinge:grid'] = [len(a) + 1, len(b) + 1]``.
    """
    fam = "miura_nonuniform"
    a_arr = _lengths("a", a, fam)
    b_arr = _lengths("b", b, fam)
    alpha = check_range("alpha", alpha, 0.0, 90.0, family=fam)
    if fold is not None:
        fold = check_range("fold", fold, 0.0, 90.0, lo_open=False, hi_open=False, family=fam)
    target = check_range("target", target, 0.0, 90.0, hi_open=False, family=fam)
    params = {"a": a_arr.tolist(), "b": b_arr.tolist(), "alpha": alpha, "fold": fold}
    if fold is None:
        params["target"] = target
    return miura_from_lengths(a_arr, b_arr, alpha, fold, target, family=fam, parameters=params)


def miura_from_lengths(
    a_arr: np.ndarray,
    b_arr: np.ndarray,
    alpha: float,
    fold: float | None,
    target: float,
    *,
    family: str,
    parameters: dict,
) -> CreasePattern:
    """Miura grid with panel lengths ``a_arr`` (x) and ``b_arr`` (zig-zag); parameters already
    validated (shared by :func:`miura_nonuniform` and
    :func:`~barhinge.families.russo.russo_pleat`)."""
    lay = GridLayout(len(a_arr) + 1, len(b_arr) + 1)
    X = miura_grid_coords(a_arr, b_arr, alpha, 0.0 if fold is None else fold)
    if fold is None:
        X = X[:, :2]
    rho = miura_fold_angles(lay, alpha, target if fold is None else fold)
    A = mv_assignment(miura_fold_angles(lay, alpha, 45.0), lay.boundary_mask())
    return build_pattern(
        X,
        lay.quads(),
        edges=lay.edges(),
        assignment=A,
        fold_angles=rho,
        family=family,
        parameters=parameters,
        extra_meta={"barhinge:grid": [lay.ni, lay.nj]},
    )
