"""Egg-box pattern: a non-developable tessellation of identical parallelograms.

Sources: Schenk & Guest, "Geometry of Miura-folded metamaterials", PNAS 110(9), 2013 (the
egg-box as the non-developable relative of the Miura-ori, with positive Poisson's ratio);
Nassar, Lebee, Monasse, "Curvature, metric and parametrization of origami tessellations: theory
and application to the eggbox pattern", Proc. R. Soc. A 473, 2017 (the folded egg-box as a
translational surface with a single folding degree of freedom).

Geometry
--------
Vertex ``(i, j)``, i = 0..2 nx, j = 0..2 ny, id ``j (2 nx + 1) + i``, sits at

    X(i, j) = (i a cos psi1,  j b cos psi2,  (i mod 2) a sin psi1 + (j mod 2) b sin psi2),

a translational surface P(i) + Q(j) of two zig-zags in the xz and yz planes, so every face is
a parallelogram with sides a, b. The facet angle gamma between the sides is kept by
``sin psi1 sin psi2 = cos gamma``, leaving one parameter: ``fold`` = psi1, the inclination of
the a-edges (degrees, in (90 - gamma, 90)). Vertices with i, j both even are pits, both odd
peaks (four sectors gamma: angle defect 2 pi - 4 gamma > 0 for gamma < 90), the others
saddles (four sectors pi - gamma: angle excess). There is no flat state: the pattern is
``developable=False`` and ``fold=None`` returns the folded state at ``target``.
"""

from __future__ import annotations

import math

import numpy as np

from barhinge.families._common import (
    GridLayout,
    build_pattern,
    check_int,
    check_range,
    fold_angles_of,
    mv_assignment,
)
from barhinge.pattern.crease import CreasePattern

__all__ = ["eggbox", "eggbox_symmetric_fold"]


def eggbox_symmetric_fold(alpha: float) -> float:
    """The ``fold`` (degrees) at which both zig-zags are equally inclined:
    ``arcsin(sqrt(cos gamma))``."""
    return math.degrees(math.asin(math.sqrt(math.cos(math.radians(alpha)))))


def eggbox(
    nx: int = 3,
    ny: int = 3,
    a: float = 1.0,
    b: float = 1.0,
    alpha: float = 60.0,
    fold: float | None = None,
    target: float | None = None,
) -> CreasePattern:
    """Egg-box sheet of ``nx`` x ``ny`` cells of 2 x 2 parallelograms (3-D; non-developable).

    Parameters
    ----------
    nx, ny : int
        Cells along x and y, >= 1.
    a, b : float
        Facet sides along x and y, > 0.
    alpha : float
        Facet angle gamma between the sides, degrees in (0, 90).
    fold : float or None
        Inclination psi1 of the a-edges, degrees in (90 - alpha, 90). None: the state at
        ``target``.
    target : float or None
        The state used when ``fold`` is None; default :func:`eggbox_symmetric_fold`.

    Returns
    -------
    CreasePattern
        (n, 3) vertices, quad faces counter-clockwise from +z, ``developable=False``,
        ``fold_angles`` = the state's fold angles; ``meta['barhinge:grid']`` as for Miura.
    """
    fam = "eggbox"
    nx = check_int("nx", nx, 1, family=fam)
    ny = check_int("ny", ny, 1, family=fam)
    a = check_range("a", a, 0.0, None, family=fam)
    b = check_range("b", b, 0.0, None, family=fam)
    alpha = check_range("alpha", alpha, 0.0, 90.0, family=fam)
    lo = 90.0 - alpha
    if fold is not None:
        psi1 = check_range("fold", fold, lo, 90.0, family=fam)
    elif target is not None:
        psi1 = check_range("target", target, lo, 90.0, family=fam)
    else:
        psi1 = eggbox_symmetric_fold(alpha)
    g = math.radians(alpha)
    p1 = math.radians(psi1)
    p2 = math.asin(min(1.0, math.cos(g) / math.sin(p1)))
    lay = GridLayout(2 * nx + 1, 2 * ny + 1)
    I, J = np.meshgrid(np.arange(lay.ni), np.arange(lay.nj), indexing="xy")
    I, J = I.ravel(), J.ravel()
    X = np.column_stack(
        [
            I * a * math.cos(p1),
            J * b * math.cos(p2),
            (I % 2) * a * math.sin(p1) + (J % 2) * b * math.sin(p2),
        ]
    )
    faces = lay.quads()
    edges = lay.edges()
    rho = fold_angles_of(X, faces, edges)
    bnd = lay.boundary_mask()
    A = mv_assignment(rho, bnd)
    rho[bnd] = 0.0
    return build_pattern(
        X,
        faces,
        edges=edges,
        assignment=A,
        fold_angles=rho,
        developable=False,
        family=fam,
        parameters={"nx": nx, "ny": ny, "a": a, "b": b, "alpha": alpha, "fold": psi1},
        extra_meta={"barhinge:grid": [lay.ni, lay.nj]},
    )
