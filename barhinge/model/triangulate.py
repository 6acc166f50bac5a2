"""Triangulation of a crease pattern's faces for the bar-and-hinge model.

* triangles are kept as they are;
* quadrilaterals by ``N4B5`` (split along the shorter diagonal, which becomes a bending
  hinge; corners 0-2 when the two are equal to round-off) or ``N5B8`` (a centre node joined
  to the four corners: 8 bars, 4 bending hinges) -- Filipov et al. (2017, IJSS, Fig. 5).
  The centre node sits where the two diagonals cross (:func:`quad_centres`), so that each
  diagonal's two half-bars are collinear: under any uniform in-plane strain the centre node is
  then in equilibrium when they have equal stiffness (``calibrate.bar_areas`` ties them), and
  the panel stores the membrane energy its bars were fitted to. At the corners' mean (the
  same point for a parallelogram) the centre node of a trapezoid moves under a uniform strain
  and the panel's membrane is too soft (tests/model/test_model_quad_centres.py);
* polygons with more than four corners by a centre node (mean of the corners) joined to every
  corner, in both schemes.

Triangles keep the counter-clockwise orientation of their face, so every triangle normal
points to the side of the face normal (the side a valley fold closes towards).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from barhinge._typing import SCHEMES, Scheme
from barhinge.errors import ConfigError, PatternError
from barhinge.pattern.crease import CreasePattern

__all__ = ["Triangulation", "quad_centres", "triangulate"]


@dataclasses.dataclass(frozen=True, eq=False)
class Triangulation:
    """Triangles of a pattern.

    Attributes
    ----------
    X0 : (n_nodes, 3) float
        Node coordinates: the pattern's vertices first (in order), then centre nodes.
    triangles : (n_tri, 3) int
        Counter-clockwise node triples.
    tri_face : (n_tri,) int
        Pattern face of each triangle.
    centre_face : (n_nodes - n_vertices,) int
        Face of each added centre node.
    """

    X0: np.ndarray
    triangles: np.ndarray
    tri_face: np.ndarray
    centre_face: np.ndarray


def quad_centres(P: np.ndarray) -> np.ndarray:
    """(..., d) centre points of quadrilaterals ``P`` (..., 4, d), d = 2 or 3: where the
    diagonals 0-2 and 1-3 cross (in a non-planar quad, the midpoint of their common
    perpendicular).

    Written as the corners' mean plus a correction proportional to the quad's departure from
    a parallelogram, ``g = P0 + P2 - P1 - P3``, so that a parallelogram's centre is its mean
    to the last bit. Where the crossing falls outside either diagonal (a non-convex quad) or
    the diagonals are parallel, the mean is kept.
    """
    P = np.asarray(P, dtype=float)
    mean = P.mean(axis=-2)
    d1 = P[..., 2, :] - P[..., 0, :]
    d2 = P[..., 3, :] - P[..., 1, :]
    g = P[..., 0, :] + P[..., 2, :] - P[..., 1, :] - P[..., 3, :]
    a = np.einsum("...i,...i->...", d1, d1)
    b = np.einsum("...i,...i->...", d1, d2)
    c = np.einsum("...i,...i->...", d2, d2)
    det = a * c - b * b
    ok = det > 1e-12 * a * c
    det = np.where(ok, det, 1.0)
    # closest points P0 + (1/2 + s) d1 and P1 + (1/2 + t) d2: [-d1 d2] [s t] = g / 2
    rg1 = -0.5 * np.einsum("...i,...i->...", d1, g)
    rg2 = 0.5 * np.einsum("...i,...i->...", d2, g)
    s = (c * rg1 + b * rg2) / det
    t = (b * rg1 + a * rg2) / det
    ok &= (np.abs(s) < 0.5) & (np.abs(t) < 0.5)
    shift = 0.5 * (s[..., None] * d1 + t[..., None] * d2)
    return np.where(ok[..., None], mean + shift, mean)


def triangulate(cp: CreasePattern, scheme: Scheme = "N5B8") -> Triangulation:
    """Triangulate every face of ``cp`` with ``scheme`` (``"N4B5"`` or ``"N5B8"``).

    The geometry used (shorter diagonal, centre nodes) is the pattern's current state
    ``cp.vertices3d``; a quadrilateral's centre node is where its diagonals cross
    (:func:`quad_centres`), a larger polygon's the mean of its corners, so in a folded,
    non-planar face the rest angles of its bending hinges take up the state.
    """
    if scheme not in SCHEMES:
        raise ConfigError(f"scheme {scheme!r} is unknown; expected one of {', '.join(SCHEMES)}")
    V = np.array(cp.vertices3d, dtype=float)
    nv = len(V)
    tris: list[np.ndarray] = []
    tface: list[np.ndarray] = []
    centres: list[np.ndarray] = []
    cface: list[np.ndarray] = []
    next_node = nv
    sizes = np.array([len(f) for f in cp.faces], dtype=np.int64)
    for k in np.unique(sizes):
        fid = np.flatnonzero(sizes == k)
        F = np.array([cp.faces[i] for i in fid], dtype=np.int64)  # (nf, k)
        if k == 3:
            tris.append(F)
            tface.append(fid)
            continue
        if k == 4 and scheme == "N4B5":
            d02 = np.linalg.norm(V[F[:, 2]] - V[F[:, 0]], axis=1)
            d13 = np.linalg.norm(V[F[:, 3]] - V[F[:, 1]], axis=1)
            # roll so that the split diagonal is always corners 0-2; diagonals equal to
            # round-off (squares, rectangles) keep 0-2, whatever the units
            shorter13 = d13 < d02 * (1.0 - 1e-9)
            Fr = np.where(shorter13[:, None], np.roll(F, -1, axis=1), F)
            tris.append(np.stack([Fr[:, [0, 1, 2]], Fr[:, [0, 2, 3]]], axis=1).reshape(-1, 3))
            tface.append(np.repeat(fid, 2))
            continue
        c = next_node + np.arange(len(fid))
        next_node += len(fid)
        centres.append(quad_centres(V[F]) if k == 4 else V[F].mean(axis=1))
        cface.append(fid)
        T = np.empty((len(fid), k, 3), dtype=np.int64)
        T[:, :, 0] = F
        T[:, :, 1] = np.roll(F, -1, axis=1)
        T[:, :, 2] = c[:, None]
        tris.append(T.reshape(-1, 3))
        tface.append(np.repeat(fid, k))
    X0 = np.vstack([V, *centres]) if centres else V
    triangles = np.vstack(tris) if tris else np.zeros((0, 3), dtype=np.int64)
    tri_face = np.concatenate(tface) if tface else np.zeros(0, dtype=np.int64)
    order = np.argsort(tri_face, kind="stable")
    triangles, tri_face = triangles[order], tri_face[order]
    if len(triangles):
        P = X0[triangles]
        area2 = np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
        scale = max(float(np.ptp(X0, axis=0).max()), 1e-300)
        bad = np.flatnonzero(area2 <= 1e-12 * scale * scale)
        if len(bad):
            t = int(bad[0])
            raise PatternError(
                f"face {int(tri_face[t])} gives a degenerate (zero-area) triangle "
                f"{triangles[t].tolist()} in {scheme}; expected non-degenerate faces"
            )
    return Triangulation(
        X0=X0,
        triangles=triangles,
        tri_face=tri_face,
        centre_face=np.concatenate(cface) if cface else np.zeros(0, dtype=np.int64),
    )
