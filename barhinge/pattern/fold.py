"""FOLD files (https://github.com/edemaine/fold, spec v1.2): read and write crease patterns and
fold paths.

What is read: ``vertices_coords`` (2 or 3 columns), ``edges_vertices``, ``edges_assignment``
(missing -> ``U``), ``edges_foldAngle`` (**degrees**, valley > 0; missing or ``null`` -> 0; the
pre-1.1 name ``edges_foldAngles`` is accepted), ``faces_vertices`` (derived from the planar
graph when missing). Every other key (``file_*``, ``frame_*`` including ``frame_unit``, custom
``ns:key`` properties, ``file_frames``) is kept in ``cp.meta`` and written back unchanged.
Keys derived from the face list (``faces_edges``, ``edges_faces``, ``vertices_faces`` ...) are
dropped when barhinge re-orders or derives the faces, because they would be stale.

Faces of a flat pattern are normalised to counter-clockwise about the pattern's normal (+z for
a pattern in the xy plane; see :func:`barhinge.pattern.planar.pattern_plane`): some files list
them clockwise.

Multiple frames: frame 0 is the top level; frame ``k >= 1`` is ``file_frames[k - 1]``, which
inherits the properties of its ``frame_parent`` (default 0) when ``frame_inherit`` is true.
A fold path is written as the crease pattern (key frame) plus one inheriting frame per state
with that state's ``vertices_coords`` and ``edges_foldAngle``.

Malformed input (bad JSON, wrong types, ragged arrays, missing keys, out-of-range indices)
raises :class:`~barhinge.errors.PatternError`, never another exception type.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec
import numpy as np

from barhinge.errors import PatternError
from barhinge.pattern.crease import CreasePattern

if TYPE_CHECKING:
    from barhinge.results import FoldPath

__all__ = ["read_fold", "read_fold_path", "write_fold", "write_fold_path", "fold_dict"]

#: keys barhinge interprets (everything else survives in ``cp.meta``)
CORE_KEYS = (
    "vertices_coords",
    "edges_vertices",
    "edges_assignment",
    "edges_foldAngle",
    "edges_foldAngles",
    "faces_vertices",
)
#: keys that depend on the face list; dropped when the faces are changed
FACE_DERIVED_KEYS = (
    "faces_edges",
    "faces_faces",
    "edges_faces",
    "vertices_faces",
    "faceOrders",
    "faces_flatFoldTransform",
    "faces_flatFoldOrientation",
)
#: meta key holding the developable flag
DEVELOPABLE_KEY = "barhinge:developable"


# ----------------------------------------------------------------------------- parsing
def _load(source: str | Path | Mapping[str, Any]) -> tuple[dict[str, Any], str]:
    if isinstance(source, Mapping):
        return dict(source), "FOLD data"
    path = Path(source)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise PatternError(f"{path}: cannot read FOLD file ({exc})") from None
    try:
        data = json.loads(text)
    except (json.JSONDecodeError, RecursionError, ValueError) as exc:
        raise PatternError(f"{path.name}: not valid JSON ({exc})") from None
    if not isinstance(data, dict):
        raise PatternError(f"{path.name}: expected a JSON object at the top level")
    return data, path.name


def _is_num(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _numbers(rows: Any, key: str, where: str, widths: tuple[int, ...]) -> np.ndarray:
    """A list of equal-length lists of numbers -> (k, w) float array."""
    if not isinstance(rows, list):
        raise PatternError(f"{where}: {key} must be a list, got {type(rows).__name__}")
    if not rows:
        return np.zeros((0, widths[0]))
    w = None
    for i, r in enumerate(rows):
        if not isinstance(r, list) or not all(_is_num(x) for x in r):
            raise PatternError(f"{where}: {key}[{i}] must be a list of numbers, got {r!r:.60}")
        if w is None:
            w = len(r)
            if w not in widths:
                raise PatternError(
                    f"{where}: {key}[{i}] has {w} entries; expected {' or '.join(map(str, widths))}"
                )
        elif len(r) != w:
            raise PatternError(f"{where}: {key}[{i}] has {len(r)} entries; expected {w}")
    try:
        return np.array(rows, dtype=float)
    except (OverflowError, ValueError, TypeError) as exc:
        raise PatternError(f"{where}: {key} is not numeric ({exc})") from None


def _int_rows(rows: Any, key: str, where: str, width: int | None) -> list[list[int]]:
    if not isinstance(rows, list):
        raise PatternError(f"{where}: {key} must be a list, got {type(rows).__name__}")
    out = []
    for i, r in enumerate(rows):
        ok = isinstance(r, list) and all(
            (isinstance(x, int) and not isinstance(x, bool))
            or (isinstance(x, float) and math.isfinite(x) and x == int(x))
            for x in r
        )
        if not ok:
            raise PatternError(f"{where}: {key}[{i}] must be a list of integers, got {r!r:.60}")
        if width is not None and len(r) != width:
            raise PatternError(f"{where}: {key}[{i}] has {len(r)} entries; expected {width}")
        out.append([int(x) for x in r])
    return out


def _frame(data: dict[str, Any], frame: int, where: str) -> dict[str, Any]:
    """Properties of frame ``frame`` with inheritance resolved."""
    if not isinstance(frame, int) or isinstance(frame, bool) or frame < 0:
        raise PatternError(f"{where}: frame must be an integer >= 0, got {frame!r}")
    if frame == 0:
        return data
    frames = data.get("file_frames")
    if not isinstance(frames, list) or not all(isinstance(f, dict) for f in frames):
        raise PatternError(f"{where}: file_frames must be a list of objects to read frame {frame}")
    if frame > len(frames):
        raise PatternError(f"{where}: frame {frame} requested, but the file has {len(frames) + 1}")
    chain = [frame]
    while True:
        fr = frames[chain[-1] - 1]
        if not fr.get("frame_inherit", False):
            break
        parent = fr.get("frame_parent", 0)
        if not isinstance(parent, int) or isinstance(parent, bool):
            raise PatternError(f"{where}: frame {chain[-1]} has a non-integer frame_parent")
        if parent < 0 or parent > len(frames) or parent in chain:
            raise PatternError(f"{where}: frame {chain[-1]} has invalid frame_parent {parent}")
        chain.append(parent)
        if parent == 0:
            break
    out: dict[str, Any] = {}
    for k in reversed(chain):
        src = data if k == 0 else frames[k - 1]
        out.update({key: v for key, v in src.items() if key != "file_frames" or k == 0})
    if chain[-1] == 0 and "file_frames" in out:
        del out["file_frames"]
    return out


def _orient_faces(V: np.ndarray, faces: list[list[int]]) -> tuple[list[list[int]], bool]:
    """Reverse the faces of a flat pattern if all are clockwise about its normal."""
    from barhinge.pattern.planar import pattern_plane, signed_areas

    if not faces or len(V) == 0:
        return faces, False
    size = float(np.linalg.norm(np.ptp(V, axis=0)))
    plane = pattern_plane(V, 1e-6 * size)
    if plane is None:
        return faces, False
    X = V if V.shape[1] == 3 else np.column_stack([V, np.zeros(len(V))])
    P = (X - plane[0]) @ plane[1][:2].T
    if any(min(f) < 0 or max(f) >= len(V) for f in faces if f):
        return faces, False
    area = signed_areas(P, faces)
    if np.all(area < 0):
        return [[f[0], *f[:0:-1]] for f in faces], True
    return faces, False


def _assignments(fr: dict[str, Any], m: int, where: str) -> list[str]:
    """``edges_assignment`` of a frame (``U`` for every edge when absent), checked."""
    asg = fr.get("edges_assignment")
    if asg is None:
        return ["U"] * m
    if not isinstance(asg, list) or not all(isinstance(a, str) for a in asg):
        raise PatternError(f"{where}: edges_assignment must be a list of strings")
    if len(asg) != m:
        raise PatternError(
            f"{where}: len(edges_vertices) = {m}, but len(edges_assignment) = {len(asg)}"
        )
    if "J" in asg:
        raise PatternError(
            f"{where}: edge {asg.index('J')} has assignment 'J' (join), which barhinge does "
            "not support; expected one of M V F B U C"
        )
    return asg


def _fold_angles(fr: dict[str, Any], m: int, where: str) -> np.ndarray:
    """``edges_foldAngle`` of a frame in degrees (0 where absent or null), checked."""
    ang = fr.get("edges_foldAngle", fr.get("edges_foldAngles"))
    if ang is None:
        return np.zeros(m)
    if not isinstance(ang, list) or not all(a is None or _is_num(a) for a in ang):
        raise PatternError(f"{where}: edges_foldAngle must be a list of numbers (degrees)")
    if len(ang) != m:
        raise PatternError(
            f"{where}: len(edges_vertices) = {m}, but len(edges_foldAngle) = {len(ang)}"
        )
    try:
        return np.array([0.0 if a is None else float(a) for a in ang])
    except OverflowError:
        raise PatternError(f"{where}: edges_foldAngle holds a number too large") from None


def fold_dict_to_pattern(
    data: dict[str, Any],
    frame: int = 0,
    *,
    where: str = "FOLD data",
    validate: bool = True,
    developable: bool | None = None,
    merge_tol: float | None = None,
) -> CreasePattern:
    """Build a CreasePattern from a parsed FOLD dictionary (see :func:`read_fold`)."""
    fr = _frame(data, frame, where)
    if "vertices_coords" not in fr:
        raise PatternError(f"{where}: frame {frame} has no vertices_coords")
    if "edges_vertices" not in fr:
        raise PatternError(f"{where}: frame {frame} has no edges_vertices")
    V = _numbers(fr["vertices_coords"], "vertices_coords", where, (2, 3))
    E = _int_rows(fr["edges_vertices"], "edges_vertices", where, 2)
    asg = _assignments(fr, len(E), where)
    F = _fold_angles(fr, len(E), where)
    meta = {k: v for k, v in fr.items() if k not in CORE_KEYS}
    faces = None
    if "faces_vertices" in fr:
        faces = _int_rows(fr["faces_vertices"], "faces_vertices", where, None)
        faces, flipped = _orient_faces(V, faces)
        if flipped:
            for k in FACE_DERIVED_KEYS:
                meta.pop(k, None)
    if "faces_vertices" not in fr or merge_tol is not None:  # faces found or renumbered
        for k in FACE_DERIVED_KEYS:
            meta.pop(k, None)
    if developable is None:
        developable = meta.get(DEVELOPABLE_KEY, True)
    if not isinstance(developable, bool):
        raise PatternError(f"{where}: {DEVELOPABLE_KEY} must be true or false")
    try:
        Ea = np.array(E, dtype=np.int64).reshape(-1, 2)
    except (OverflowError, ValueError):
        raise PatternError(f"{where}: edges_vertices holds an index out of range") from None
    try:
        return CreasePattern(
            V, Ea, np.array(asg, dtype=object), F,
            faces, developable=developable, meta=meta, validate=validate, merge_tol=merge_tol,
        )  # fmt: skip
    except PatternError as exc:
        raise PatternError(f"{where}: {exc}") from None


def read_fold(
    source: str | Path | Mapping[str, Any],
    frame: int = 0,
    *,
    validate: bool = True,
    developable: bool | None = None,
    merge_tol: float | None = None,
) -> CreasePattern:
    """Read a crease pattern (or one frame of it) from a FOLD file.

    Parameters
    ----------
    source : path or dict
        A ``.fold`` file or an already parsed FOLD dictionary.
    frame : int
        0 for the key frame, ``k`` for ``file_frames[k - 1]`` (with inheritance).
    validate : bool
        Run :func:`barhinge.pattern.validate.check` (set False for bent, non-rigid states).
    developable : bool, optional
        Override the file's ``barhinge:developable`` flag (default True).
    merge_tol : float, optional
        Merge vertices closer than this length (and drop the zero-length and duplicate edges
        that result) *before* the faces are found, or renumber the file's faces.

    Returns
    -------
    CreasePattern
        Fold angles in degrees (FOLD convention, valley > 0); every key barhinge does not
        interpret is kept in ``meta``.
    """
    data, where = _load(source)
    return fold_dict_to_pattern(
        data, frame, where=where, validate=validate, developable=developable, merge_tol=merge_tol
    )


def _coords(V: np.ndarray) -> list[list[float]]:
    return np.asarray(V, dtype=float).tolist()


def fold_dict(cp: CreasePattern) -> dict[str, Any]:
    """The FOLD dictionary of a crease pattern (``cp.meta`` keys included)."""
    d: dict[str, Any] = {"file_spec": 1.2, "file_creator": "barhinge"}
    core = {
        "vertices_coords": _coords(cp.vertices),
        "edges_vertices": cp.edges.tolist(),
        "edges_assignment": cp.assignment.tolist(),
        "edges_foldAngle": [float(a) for a in cp.fold_angles],
        "faces_vertices": [list(f) for f in cp.faces],
    }
    meta = {k: v for k, v in cp.meta.items() if k not in CORE_KEYS}
    for k, v in meta.items():
        if k.startswith(("file_", "frame_")) and k != "file_frames":
            d[k] = v
    d.update(core)
    for k, v in meta.items():
        if k not in d:
            d[k] = v
    if not cp.developable:
        d[DEVELOPABLE_KEY] = False
    elif DEVELOPABLE_KEY in d:
        del d[DEVELOPABLE_KEY]
    return d


def _frame_entry(fr: Any, n: int, m: int) -> dict[str, Any]:
    if isinstance(fr, CreasePattern):
        if fr.n_vertices != n or fr.n_edges != m:
            raise PatternError(
                f"frame pattern has {fr.n_vertices} vertices and {fr.n_edges} edges; expected "
                f"{n} and {m}"
            )
        return {
            "frame_classes": ["foldedForm"],
            "frame_parent": 0,
            "frame_inherit": True,
            "vertices_coords": _coords(fr.vertices),
            "edges_foldAngle": [float(a) for a in fr.fold_angles],
        }
    if isinstance(fr, Mapping):
        out = {"frame_parent": 0, "frame_inherit": True}
        out.update(fr)
        return out
    X = np.asarray(fr, dtype=float)
    if X.ndim != 2 or X.shape[0] < n or X.shape[1] not in (2, 3):
        raise PatternError(f"frame coordinates must have shape ({n}, 3), got {X.shape}")
    return {
        "frame_classes": ["foldedForm"],
        "frame_parent": 0,
        "frame_inherit": True,
        "vertices_coords": _coords(X[:n]),
    }


def _dump(d: dict[str, Any], path: str | Path, indent: int | None = 1) -> Path:
    path = Path(path)
    try:
        text = json.dumps(d, indent=indent, allow_nan=False)
    except ValueError as exc:
        raise PatternError(f"{path.name}: cannot write FOLD ({exc})") from None
    path.write_text(text + "\n", encoding="utf-8")
    return path


def write_fold(
    cp: CreasePattern,
    path: str | Path,
    frames: Sequence[CreasePattern | np.ndarray | Mapping[str, Any]] | None = None,
) -> Path:
    """Write ``cp`` to a FOLD file (the key frame), optionally with more frames.

    Parameters
    ----------
    cp : CreasePattern
    path : path
        Output ``.fold`` file.
    frames : sequence, optional
        Extra frames, each a CreasePattern with the same topology (its coordinates and fold
        angles are written), an (n, 3) coordinate array, or a FOLD frame dictionary. Each
        frame inherits from the key frame (``frame_parent`` 0, ``frame_inherit`` true) and
        replaces any ``file_frames`` kept in ``cp.meta``.

    Returns
    -------
    Path
    """
    d = fold_dict(cp)
    if frames is not None:
        d["file_frames"] = [_frame_entry(f, cp.n_vertices, cp.n_edges) for f in frames]
        if "file_classes" not in d:
            d["file_classes"] = ["singleModel"]
    return _dump(d, path)


def write_fold_path(cp: CreasePattern, fold_path: FoldPath, path: str | Path) -> Path:
    """Write a fold path as a FOLD file: the crease pattern as the key frame and one
    ``file_frames`` entry per state (``vertices_coords`` = the pattern's vertices in that state,
    ``edges_foldAngle`` = that state's fold angles in degrees, ``frame_inherit`` true).

    The FOLD ``file_classes`` include ``"animation"``; per-state load factor and energies are
    stored under ``barhinge:`` keys.
    """
    X = np.asarray(fold_path.X)
    n, m = cp.n_vertices, cp.n_edges
    if X.ndim != 3 or X.shape[1] < n:
        raise PatternError(f"fold path has nodes of shape {X.shape}; expected (k, >= {n}, 3)")
    bad = np.argwhere(~np.isfinite(X[:, :n]))
    if len(bad):
        s, v, _ = bad[0]
        raise PatternError(
            f"{Path(path).name}: cannot write FOLD (state {s}: vertex {v} has a non-finite "
            "coordinate)"
        )
    A = np.asarray(fold_path.fold_angles_deg, float)
    if A.shape != (X.shape[0], m):
        raise PatternError(f"fold path fold angles have shape {A.shape}; expected ({len(X)}, {m})")
    d = fold_dict(cp)
    d["file_classes"] = ["singleModel", "animation"]
    frames = []
    for s in range(X.shape[0]):
        fr: dict[str, Any] = {
            "frame_title": f"state {s}",
            "frame_classes": ["foldedForm"],
            "frame_attributes": ["3D"],
            "frame_parent": 0,
            "frame_inherit": True,
            "vertices_coords": _coords(X[s, :n]),
            # an angle that was not measured (NaN) is written as null
            "edges_foldAngle": [a if math.isfinite(a) else None for a in A[s].tolist()],
        }
        lf = fold_path.load_factor
        if lf is not None and np.isfinite(lf[s]):
            fr["barhinge:load_factor"] = float(lf[s])
        e = fold_path.energy[s]
        if np.isfinite(e):
            fr["barhinge:energy"] = float(e)
        frames.append(fr)
    d["file_frames"] = frames
    d["barhinge:path_kind"] = fold_path.kind
    # one line, by msgspec's encoder (~20x faster than json's for many frames; the
    # coordinates are checked finite above, NaN fold angles are None already)
    path = Path(path)
    path.write_bytes(msgspec.json.encode(d) + b"\n")
    return path


def read_fold_path(
    source: str | Path | Mapping[str, Any],
) -> tuple[CreasePattern, np.ndarray, np.ndarray]:
    """Read a file written by :func:`write_fold_path`.

    Returns
    -------
    cp : CreasePattern
        The key frame (validated).
    X : (n_frames, n_vertices, 3) float
        Vertex coordinates of every extra frame (z = 0 added to 2-D frames).
    fold_angles_deg : (n_frames, n_edges) float
        Fold angles of every extra frame, degrees (NaN where the file has null).
    """
    data, where = _load(source)
    cp = fold_dict_to_pattern(data, 0, where=where)
    frames = data.get("file_frames", [])
    if not isinstance(frames, list):
        raise PatternError(f"{where}: file_frames must be a list")
    Xs, As = [], []
    for k in range(1, len(frames) + 1):
        fr = _frame(data, k, where)
        V = _numbers(fr.get("vertices_coords"), "vertices_coords", where, (2, 3))
        if V.shape[0] != cp.n_vertices:
            raise PatternError(
                f"{where}: frame {k} has {len(V)} vertices; expected {cp.n_vertices}"
            )
        if V.shape[1] == 2:
            V = np.column_stack([V, np.zeros(len(V))])
        ang = fr.get("edges_foldAngle", [0.0] * cp.n_edges)
        if (
            not isinstance(ang, list)
            or len(ang) != cp.n_edges
            or not all(a is None or _is_num(a) for a in ang)
        ):
            raise PatternError(f"{where}: frame {k} edges_foldAngle must be {cp.n_edges} numbers")
        Xs.append(V)
        As.append([np.nan if a is None else float(a) for a in ang])
    X = np.array(Xs, float).reshape(len(Xs), cp.n_vertices, 3)
    return cp, X, np.array(As, float).reshape(len(As), cp.n_edges)
