"""Kresling pattern: the flat crease pattern of a twisted (Kresling) tube, and the related
triangulated "diagonal" sheets.

Sources: B. Kresling, "Natural twist buckling in shells: from the hawkmoth's bellows to the
deployable Kresling-pattern and cylindrical Miura-ori", IASS-APCS 2008; S. D. Guest and
S. Pellegrino, "The folding of triangulated cylinders, Part I: geometric considerations",
J. Appl. Mech. 61:773-777, 1994 (the flat pattern of congruent triangles).

Flat pattern: ``stories`` rows of ``n`` parallelograms with horizontal sides ``a`` (the polygon
sides of the tube), slanted sides from (i a + j s, j h) to (i a + (j + 1) s, (j + 1) h) and the
diagonal from (i, j) to (i + 1, j + 1) in each parallelogram. Column ``n`` is the seam: rolled
into a tube, its slanted edges coincide with column 0 (so they are boundary edges of the flat
sheet). Polygon sides and slanted creases are mountains, the diagonals valleys (the common
drawing; Maekawa 4 M + 2 V, Kawasaki holds at every lattice vertex).

Folded tower (``fold=1`` or ``fold=2``): the seam is closed, the polygons are regular
``n``-gons of circumradius ``R = a / (2 sin(pi / n))`` and each story's top polygon is turned
by ``phi`` and raised by ``H`` over its bottom one. The two states in which every crease has
its flat-pattern length (stress-free for a bar model: the two stable states of the truss model
of Kresling bistability; Cai, Deng, Zhou, Feng & Tu, "Bistable behavior of the cylindrical
origami structure with Kresling pattern", J. Mech. Des. 137(6):061406, 2015) follow from
``b^2 = 2 R^2 (1 - cos phi) + H^2`` (slanted crease) and
``c^2 = 2 R^2 (1 - cos(phi + 2 pi / n)) + H^2`` (diagonal):
``sin(phi + pi / n) = (c^2 - b^2) / (4 R^2 sin(pi / n))``, whose two roots are
``phi_1 = asin(q) - pi / n`` (the taller state) and ``phi_2 = pi - asin(q) - pi / n``.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from barhinge.errors import PatternError
from barhinge.families._common import (
    GridLayout,
    build_pattern,
    check_int,
    check_range,
)
from barhinge.pattern.crease import CreasePattern

__all__ = ["KreslingStates", "kresling", "kresling_states", "triangulated_lattice"]


def triangulated_lattice(
    ni: int, nj: int, a: float, s: float, h: float, target: float, diag_assignment: str = "V"
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Vertices (n, 2), faces (k, 3), edges (m, 2), assignment and target angles of a
    parallelogram lattice of ni x nj cells (cell sides a and (s, h)) split by the diagonals
    (i, j)-(i+1, j+1). Row and column edges are mountains, diagonals ``diag_assignment``."""
    lay = GridLayout(ni + 1, nj + 1)
    I, J = np.meshgrid(np.arange(ni + 1), np.arange(nj + 1), indexing="xy")
    I, J = I.ravel(), J.ravel()
    X = np.column_stack([I * a + J * s, J * h])
    Q = lay.quads()  # (i,j),(i+1,j),(i+1,j+1),(i,j+1)
    faces = np.vstack([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]])
    grid_edges = lay.edges()
    diag = Q[:, [0, 2]]
    edges = np.vstack([grid_edges, diag])
    A = np.concatenate([np.full(len(grid_edges), "M"), np.full(len(diag), diag_assignment)])
    sign = np.where(A == "V", 1.0, -1.0)
    A[: len(grid_edges)][lay.boundary_mask()] = "B"
    F = np.where(A == "B", 0.0, sign * target)
    return X, faces, edges, A.astype("<U1"), F


@dataclasses.dataclass(frozen=True)
class KreslingStates:
    """The two stress-free folded states of a Kresling story (see the module docstring).

    Attributes
    ----------
    R : float
        Polygon circumradius (length).
    b, c : float
        Slanted crease and diagonal lengths of the flat pattern (length).
    phi : (2,) float
        Turn of the top polygon over the bottom one, radians (state 1, state 2).
    H : (2,) float
        Story height (length), ``H[0] > H[1]``.
    """

    R: float
    b: float
    c: float
    phi: tuple[float, float]
    H: tuple[float, float]


def kresling_states(n: int, a: float, height: float, shift: float) -> KreslingStates:
    """Closed-form stable states of a Kresling story (Cai et al. 2015, truss model).

    Parameters are those of :func:`kresling`. PatternError when the pattern has no two
    folded states (``q > 1`` or ``H^2 <= 0``)."""
    R = a / (2.0 * math.sin(math.pi / n))
    b = math.hypot(shift * a, height)
    c = math.hypot(a + shift * a, height)
    q = (c * c - b * b) / (4.0 * R * R * math.sin(math.pi / n))
    if q >= 1.0:
        raise PatternError(
            f"kresling: this pattern (n={n}, shift={shift}) does not close into a tower: "
            f"sin(phi + pi/n) = {q:.4g} > 1; use a smaller shift"
        )
    phis = (math.asin(q) - math.pi / n, math.pi - math.asin(q) - math.pi / n)
    H2 = [b * b - 2.0 * R * R * (1.0 - math.cos(p)) for p in phis]
    if min(H2) <= 0.0:
        raise PatternError(
            f"kresling: the folded state {1 + int(H2[1] <= 0)} of this pattern has no height "
            f"(H^2 = {min(H2):.4g}); use a larger height or a smaller shift"
        )
    return KreslingStates(R, b, c, phis, (math.sqrt(H2[0]), math.sqrt(H2[1])))


def _tower(n: int, stories: int, a: float, height: float, shift: float, fold: int):
    st = kresling_states(n, a, height, shift)
    phi, H = st.phi[fold - 1], st.H[fold - 1]
    i, j = np.meshgrid(np.arange(n), np.arange(stories + 1), indexing="xy")
    i, j = i.ravel(), j.ravel()
    ang = 2.0 * math.pi * i / n + j * phi
    X = np.column_stack([st.R * np.cos(ang), st.R * np.sin(ang), j * H])
    vid = (j * n + i).reshape(stories + 1, n)
    nxt = np.roll(vid, -1, axis=1)
    bl, br, tl, tr = vid[:-1], nxt[:-1], vid[1:], nxt[1:]
    faces = np.vstack(
        [np.column_stack([bl.ravel(), br.ravel(), tr.ravel()]),
         np.column_stack([bl.ravel(), tr.ravel(), tl.ravel()])]
    )  # fmt: skip
    return X, faces


def kresling(
    n: int = 6,
    stories: int = 3,
    a: float = 1.0,
    height: float = 0.8,
    shift: float = 0.6,
    target: float = 60.0,
    fold: int | None = None,
) -> CreasePattern:
    """Flat crease pattern of a Kresling tube with an ``n``-gon cross-section.

    Parameters
    ----------
    n : int
        Polygon sides (columns of parallelograms), >= 3.
    stories : int
        Rows of parallelograms, >= 1.
    a : float
        Polygon side (horizontal crease length), > 0.
    height : float
        Flat height h of a story, > 0.
    shift : float
        Horizontal shift s of one story over the next, as a fraction of ``a``, in [0, 1).
    target : float
        Target fold angle magnitude (degrees, (0, 180]).
    fold : None, 1 or 2
        None: the flat pattern. 1 or 2: the closed tower in its taller (1) or shorter (2)
        stress-free state (:func:`kresling_states`), with fold angles and M/V assignment of
        that state (``target`` unused).

    Returns
    -------
    CreasePattern
        Flat: vertex (i, j), i = 0..n, j = 0..stories, has id ``j (n + 1) + i``; triangles
        counter-clockwise; the seam columns i = 0 and i = n are boundary edges. Tower: vertex
        (i, j), i = 0..n - 1, has id ``j n + i``; the bottom and top polygons are boundary
        edges.
    """
    fam = "kresling"
    n = check_int("n", n, 3, family=fam)
    stories = check_int("stories", stories, 1, family=fam)
    a = check_range("a", a, 0.0, None, family=fam)
    height = check_range("height", height, 0.0, None, family=fam)
    shift = check_range("shift", shift, 0.0, 1.0, lo_open=False, family=fam)
    target = check_range("target", target, 0.0, 180.0, hi_open=False, family=fam)
    # the tube closes only if the polygon (side a, n sides) fits: always true in the flat
    # pattern; warn through an error only for degenerate triangles
    if math.hypot(shift * a, height) <= 1e-12:
        raise PatternError(f"{fam}: height and shift give zero-length slanted creases")
    params = {
        "n": n, "stories": stories, "a": a, "height": height, "shift": shift, "target": target,
    }  # fmt: skip
    if fold is not None:
        if fold not in (1, 2) or isinstance(fold, bool):
            raise PatternError(f"{fam}: fold = {fold!r}; expected None (flat), 1 or 2")
        fold = int(fold)
        X, faces = _tower(n, stories, a, height, shift, fold)
        probe = build_pattern(
            X, faces, assignment=np.full(3 * n * stories + n, "F"), family=fam,
            parameters=params, developable=False,
        )  # fmt: skip
        F = probe.state_fold_angles()
        A = np.where(F > 0, "V", np.where(F < 0, "M", "F"))
        A[probe.assignment == "B"] = "B"
        return probe.replaced(
            assignment=A, fold_angles=F, meta={**probe.meta, "barhinge:kresling_fold": fold}
        )
    X, faces, edges, A, F = triangulated_lattice(n, stories, a, shift * a, height, target)
    return build_pattern(
        X,
        faces,
        edges=edges,
        assignment=A,
        fold_angles=F,
        family=fam,
        parameters={
            "n": n,
            "stories": stories,
            "a": a,
            "height": height,
            "shift": shift,
            "target": target,
        },  # fmt: skip
        extra_meta={"barhinge:grid": [n + 1, stories + 1], "barhinge:seam": [0, n]},
    )
