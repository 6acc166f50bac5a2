"""SVG crease patterns in the Origami Simulator colour convention (Ghassaei et al. 2018).

* Stroke colour gives the crease kind: black ``B`` (border), red ``M``, blue ``V``, green ``C``
  (cut), yellow ``F`` (facet / triangulation line), magenta ``U`` (undriven hinge). Hex (long
  or short), ``rgb(...)`` and colour names are accepted; a colour is matched to the nearest of
  these six, and strokes whose colour is far from all of them are skipped (logged).
* ``opacity * stroke-opacity`` (each defaulting to 1) is the target fold angle as a fraction of
  180 deg: mountain ``-opacity * 180``, valley ``+opacity * 180`` (FOLD sign convention); other
  kinds get 0.
* Geometry: ``<line>``, ``<polyline>``, ``<polygon>``, ``<rect>``, ``<path>`` (and any other
  shape) inside groups with transforms, all resolved by ``svgelements``. Creases are straight:
  a curved path segment is replaced by its chord (logged).
* Endpoints closer than ``merge_tol`` (default ``MERGE_REL * size``) are merged, crossing
  segments are split at their intersection, a vertex lying on a segment splits it, and
  overlapping duplicates are merged (border wins over crease, crease over facet line).
* The SVG y axis points down: y is negated (and the pattern shifted to start at the origin)
  so that faces are counter-clockwise in the usual x-right, y-up frame.
* Faces come from the planar graph (:func:`barhinge.pattern.planar.planar_faces`); a bounded
  face whose sides are all border/cut edges shared with other faces is a hole and is dropped.
"""

from __future__ import annotations

import logging
import re
from pathlib import Path
from typing import Any

import numpy as np

from barhinge.errors import PatternError
from barhinge.pattern.crease import CreasePattern

__all__ = ["MERGE_REL", "read_svg", "assignment_of_colour"]

log = logging.getLogger(__name__)

#: default vertex-merge distance relative to the pattern size
MERGE_REL = 1e-3

_REF = {
    "B": (0, 0, 0),
    "M": (255, 0, 0),
    "V": (0, 0, 255),
    "C": (0, 255, 0),
    "F": (255, 255, 0),
    "U": (255, 0, 255),
}
_NAMES = {
    "black": "B",
    "red": "M",
    "blue": "V",
    "green": "C",
    "lime": "C",
    "yellow": "F",
    "magenta": "U",
    "fuchsia": "U",
}
#: a stroke farther than this (RGB distance) from every reference colour is not a crease
COLOUR_TOL = 100.0
_PRIORITY = {"B": 5, "C": 4, "M": 3, "V": 3, "F": 2, "U": 1}


def assignment_of_colour(rgb: tuple[int, int, int], name: str | None = None) -> str | None:
    """Crease kind (``B M V C F U``) of a stroke colour, or None if it matches none."""
    if name is not None and name.strip().lower() in _NAMES:
        return _NAMES[name.strip().lower()]
    c = np.asarray(rgb, float)
    best, dist = None, np.inf
    for k, ref in _REF.items():
        d = float(np.linalg.norm(c - np.asarray(ref, float)))
        if d < dist:
            best, dist = k, d
    return best if dist <= COLOUR_TOL else None


def _float(v, what: str, where: str) -> float:
    if v is None:
        return 1.0
    try:
        x = float(str(v).strip().rstrip("%")) / (100.0 if str(v).strip().endswith("%") else 1.0)
    except ValueError:
        raise PatternError(f"{where}: {what} {v!r} is not a number") from None
    return min(max(x, 0.0), 1.0)


#: geometry attributes of the basic shapes, checked for a finite length before use
_LENGTH_ATTRS = ("x1", "y1", "x2", "y2", "x", "y", "width", "height", "cx", "cy", "r", "rx", "ry")
_LENGTH_RE = re.compile(r"^\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*(px|pt|mm|cm|in|pc|%)?\s*$")


def _check_lengths(values: dict, where: str) -> None:
    """PatternError naming the first geometry attribute that is not a finite length (a
    malformed value would otherwise make svgelements drop the shape without a word)."""
    for key in _LENGTH_ATTRS:
        v = values.get(key)
        if isinstance(v, str) and not _LENGTH_RE.match(v):
            raise PatternError(f"{where}: attribute {key}={v!r} is not a finite length")


def _crease_kind(el: Any, where: str) -> tuple[str | None, float] | None:
    """(assignment, fold angle in degrees) of a visible stroked SVG shape; assignment None
    when its stroke colour is no crease kind; None when it is hidden or has no stroke. The
    fold angle is 180 deg times the stroke's opacity (M negative, V positive, others 0)."""
    values = getattr(el, "values", {}) or {}
    if str(values.get("display", "")).strip() == "none":
        return None
    stroke = el.stroke
    if stroke is None or stroke.value is None:
        return None
    raw = values.get("stroke")
    a = assignment_of_colour(
        (stroke.red, stroke.green, stroke.blue), raw if isinstance(raw, str) else None
    )
    if a is None:
        return None, 0.0
    _check_lengths(values, where)
    op = _float(values.get("opacity"), "opacity", where)
    if values.get("stroke-opacity") is not None:  # exact value, not the 8-bit alpha
        sop = _float(values.get("stroke-opacity"), "stroke-opacity", where)
    else:  # rgba() / #rrggbbaa colours carry it in the alpha channel
        sop = stroke.opacity if stroke.opacity is not None else 1.0
    frac = op * float(sop)
    return a, {"M": -180.0 * frac, "V": 180.0 * frac}.get(a, 0.0)


def _segments(path: Path) -> tuple[np.ndarray, list[str], list[float], dict]:
    """Straight segments (k, 4) [x0, y0, x1, y1] in SVG coordinates, their assignments and
    fold angles (degrees)."""
    try:
        import svgelements as se
    except ImportError as exc:  # pragma: no cover - declared dependency
        raise PatternError(f"SVG import needs svgelements ({exc})") from None
    where = path.name
    try:
        svg = se.SVG.parse(str(path), reify=True)
        elements = list(svg.elements())
    except PatternError:
        raise
    except Exception as exc:  # svgelements / XML parser errors of every kind
        raise PatternError(f"{where}: cannot parse SVG ({type(exc).__name__}: {exc})") from None
    segs: list[tuple[float, float, float, float]] = []
    asg: list[str] = []
    ang: list[float] = []
    stats = {"skipped_colours": 0, "curves_as_chords": 0}
    for el in elements:
        if not isinstance(el, se.Shape):
            continue
        kind = _crease_kind(el, where)
        if kind is None:
            continue
        a, rho = kind
        if a is None:
            stats["skipped_colours"] += 1
            continue
        try:
            segments = list(se.Path(el).segments())
        except Exception as exc:  # malformed path data
            raise PatternError(f"{where}: cannot read the geometry of {el!r:.60} ({exc})") from None
        for s in segments:
            if isinstance(s, se.Move) or s.start is None or s.end is None:
                continue
            if not isinstance(s, (se.Line, se.Close)):
                stats["curves_as_chords"] += 1
            segs.append((float(s.start.x), float(s.start.y), float(s.end.x), float(s.end.y)))
            asg.append(a)
            ang.append(rho)
    if stats["skipped_colours"]:
        log.warning("%s: skipped %d shapes whose stroke colour is no crease kind", where,
                    stats["skipped_colours"])  # fmt: skip
    if stats["curves_as_chords"]:
        log.warning("%s: %d curved segments replaced by chords", where, stats["curves_as_chords"])
    S = np.array(segs, float).reshape(-1, 4)
    if not np.all(np.isfinite(S)):
        raise PatternError(f"{where}: non-finite coordinates")
    return S, asg, ang, stats


def _cluster(P: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Merge points closer than tol (transitively). Returns (labels (k,), centres)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    k = len(P)
    if k == 0:
        return np.zeros(0, np.int64), np.zeros((0, 2))
    pairs = cKDTree(P).query_pairs(r=tol, output_type="ndarray")
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(k, k))
    nlab, lab = connected_components(g, directed=False)
    # number clusters in order of their first member
    first = np.full(nlab, k, np.int64)
    np.minimum.at(first, lab, np.arange(k))
    order = np.argsort(first)
    ren = np.empty(nlab, np.int64)
    ren[order] = np.arange(nlab)
    lab = ren[lab]
    cnt = np.bincount(lab, minlength=nlab)
    C = np.stack([np.bincount(lab, weights=P[:, i], minlength=nlab) for i in (0, 1)], 1)
    return lab, C / cnt[:, None]


def _split(V: np.ndarray, E: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Add crossing points as vertices, merge, split edges at vertices on their interior.

    Returns (V, E, parent) with ``parent[i]`` the input edge each output edge came from.
    """
    from barhinge.pattern.validate import box_pairs

    m = len(E)
    A, B = V[E[:, 0]], V[E[:, 1]]
    L = np.linalg.norm(B - A, axis=1)
    cell = 2.0 * float(np.median(L)) if m else 1.0
    # 1. proper crossings -> new points
    p, q = box_pairs(np.minimum(A, B), np.maximum(A, B), cell)
    share = (
        (E[p, 0] == E[q, 0]) | (E[p, 0] == E[q, 1]) | (E[p, 1] == E[q, 0]) | (E[p, 1] == E[q, 1])
    )
    p, q = p[~share], q[~share]
    r, s = B[p] - A[p], B[q] - A[q]
    den = r[:, 0] * s[:, 1] - r[:, 1] * s[:, 0]
    w = A[q] - A[p]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[:, 0] * s[:, 1] - w[:, 1] * s[:, 0]) / den
        u = (w[:, 0] * r[:, 1] - w[:, 1] * r[:, 0]) / den
    ok = (np.abs(den) > 0) & (t * L[p] > tol) & ((1 - t) * L[p] > tol)
    ok &= (u * L[q] > tol) & ((1 - u) * L[q] > tol)
    X = A[p[ok]] + t[ok, None] * r[ok]
    # 2. merge the crossing points with the vertices
    lab, C = _cluster(np.vstack([V, X]), tol)
    E = lab[: len(V)][E]
    V = C
    keep = E[:, 0] != E[:, 1]
    parent = np.flatnonzero(keep)
    E = E[keep]
    # 3. vertices on the interior of an edge split it
    A, B = V[E[:, 0]], V[E[:, 1]]
    m = len(E)
    lo = np.vstack([np.minimum(A, B) - tol, V - tol])
    hi = np.vstack([np.maximum(A, B) + tol, V + tol])
    i, j = box_pairs(lo, hi, cell)
    sel = (i < m) & (j >= m)
    e, v = i[sel], j[sel] - m
    sel = (E[e, 0] != v) & (E[e, 1] != v)
    e, v = e[sel], v[sel]
    d = B[e] - A[e]
    Le = np.linalg.norm(d, axis=1)
    off = V[v] - A[e]
    along = np.einsum("ij,ij->i", off, d) / Le
    dist = np.abs(d[:, 0] * off[:, 1] - d[:, 1] * off[:, 0]) / Le
    on = (dist <= tol) & (along > tol) & (along < Le - tol)
    e, v, along = e[on], v[on], along[on]
    if len(e) == 0:
        return V, E, parent
    order = np.lexsort((along, e))
    e, v = e[order], v[order]
    newE, newP = [], []
    split = np.zeros(m, bool)
    split[e] = True
    newE.append(E[~split])
    newP.append(parent[~split])
    brk = np.flatnonzero(np.diff(e)) + 1
    for grp_e, grp_v in zip(np.split(e, brk), np.split(v, brk), strict=True):
        ed = grp_e[0]
        chain = [E[ed, 0], *grp_v.tolist(), E[ed, 1]]
        sub = np.column_stack([chain[:-1], chain[1:]])
        newE.append(sub)
        newP.append(np.full(len(sub), parent[ed]))
    return V, np.vstack(newE).astype(np.int64), np.concatenate(newP)


def _dedupe(E: np.ndarray, asg: np.ndarray, ang: np.ndarray, where: str):
    """Merge duplicate edges (same vertex pair): border beats cut beats crease beats facet."""
    key = np.minimum(E[:, 0], E[:, 1]) * (E.max() + 1) + np.maximum(E[:, 0], E[:, 1])
    pri = np.array([_PRIORITY[a] for a in asg])
    order = np.lexsort((-pri, key))
    k = key[order]
    first = np.concatenate([[True], k[1:] != k[:-1]])
    # conflicting mountain/valley duplicates are an error
    grp = np.cumsum(first) - 1
    top = order[first][grp]
    clash = (pri[order] == 3) & (pri[top] == 3) & (asg[order] != asg[top])
    if clash.any():
        e = int(order[np.flatnonzero(clash)[0]])
        raise PatternError(
            f"{where}: a mountain and a valley crease overlap along vertices "
            f"{E[e].tolist()}; expected one crease kind per line"
        )
    keep = order[first]
    keep.sort()
    return E[keep], asg[keep], ang[keep]


def _drop_holes(faces: list[list[int]], E: np.ndarray, asg: np.ndarray) -> list[list[int]]:
    from barhinge.pattern.validate import _corners, _edge_lookup

    if not faces:
        return faces
    n = int(E.max()) + 1
    cv, cf, cn = _corners(faces)
    se = _edge_lookup(E, n, cv, cv[cn])
    nface = np.bincount(se[se >= 0], minlength=len(E))
    cut = np.isin(asg, ("B", "C"))
    good = np.ones(len(faces), bool)
    side_ok = (se >= 0) & cut[np.maximum(se, 0)] & (nface[np.maximum(se, 0)] == 2)
    allcut = np.bincount(cf, weights=side_ok, minlength=len(faces)) == np.bincount(
        cf, minlength=len(faces)
    )
    good &= ~allcut
    return [f for f, g in zip(faces, good, strict=True) if g]


def read_svg(
    path: str | Path,
    *,
    merge_tol: float | None = None,
    developable: bool = True,
    validate: bool = True,
) -> CreasePattern:
    """Read an SVG crease pattern (Origami Simulator colour convention).

    Parameters
    ----------
    path : path
        The ``.svg`` file.
    merge_tol : float, optional
        Distance (SVG user units) under which endpoints are merged; default
        ``MERGE_REL * size`` (size = diagonal of the drawing's bounding box).
    developable : bool
        Passed to the CreasePattern (False for non-developable drawings).
    validate : bool
        Validate the result (:func:`barhinge.pattern.validate.check`).

    Returns
    -------
    CreasePattern
        Flat pattern, vertices (n, 2) in SVG user units with y pointing up, faces
        counter-clockwise, fold angles in degrees (valley > 0).
    """
    from barhinge.pattern.planar import planar_faces

    path = Path(path)
    where = path.name
    if not path.is_file():
        raise PatternError(f"{path}: no such SVG file")
    S, asg_l, ang_l, stats = _segments(path)
    if len(S) == 0:
        raise PatternError(f"{where}: no crease lines found (expected coloured strokes)")
    P = S.reshape(-1, 2).copy()
    P[:, 1] = -P[:, 1]
    P -= P.min(0)
    with np.errstate(over="ignore"):
        size = float(np.linalg.norm(np.ptp(P, axis=0)))
    if not np.isfinite(size):
        raise PatternError(f"{where}: coordinates too large (bounding box overflows)")
    if size == 0:
        raise PatternError(f"{where}: all crease lines have zero length")
    tol = MERGE_REL * size if merge_tol is None else float(merge_tol)
    if not (tol >= 0 and np.isfinite(tol)):
        raise PatternError(f"merge_tol must be a finite length >= 0, got {merge_tol}")
    lab, V = _cluster(P, tol)
    E = lab.reshape(-1, 2)
    asg = np.array(asg_l)
    ang = np.array(ang_l, float)
    keep = E[:, 0] != E[:, 1]
    E, asg, ang = E[keep], asg[keep], ang[keep]
    if len(E) == 0:
        raise PatternError(
            f"{where}: every line is shorter than the merge tolerance {tol:.3g}; "
            "expected crease lines longer than that"
        )
    for _ in range(3):
        n_before = (len(V), len(E))
        V, E, parent = _split(V, E, tol)
        asg, ang = asg[parent], ang[parent]
        E, asg, ang = _dedupe(E, asg, ang, where)
        if (len(V), len(E)) == n_before:
            break
    # drop vertices no edge uses
    used = np.zeros(len(V), bool)
    used[E.ravel()] = True
    ren = np.cumsum(used) - 1
    V, E = V[used], ren[E]
    faces = _drop_holes(planar_faces(V, E), E, asg)
    meta = {"file_creator": "barhinge (from SVG)", "barhinge:svg_source": path.name}
    if stats["skipped_colours"]:
        meta["barhinge:svg_skipped_shapes"] = stats["skipped_colours"]
    try:
        return CreasePattern(
            V, E, asg, ang, faces, developable=developable, meta=meta, validate=validate
        )
    except PatternError as exc:
        raise PatternError(f"{where}: {exc}") from None
