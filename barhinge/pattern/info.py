"""Counts of a crease pattern as plain data: what ``barhinge info`` and ``barhinge
patterns`` print (JSON-serialisable)."""

from __future__ import annotations

from typing import Any

import numpy as np

from barhinge._typing import ASSIGNMENTS
from barhinge.pattern.crease import CreasePattern

__all__ = ["generated_info", "pattern_info"]


def pattern_info(cp: CreasePattern, findings: list[Any]) -> dict[str, Any]:
    """Counts, degree histogram, bounding box (in the pattern's units) and validation
    ``findings`` (:func:`barhinge.pattern.validate.findings`) of a pattern."""
    V = cp.vertices
    values, counts = np.unique(cp.vertex_degree, return_counts=True)
    return {
        "n_vertices": cp.n_vertices,
        "n_edges": cp.n_edges,
        "edges_by_assignment": {a: int((cp.assignment == a).sum()) for a in ASSIGNMENTS},
        "n_faces": cp.n_faces,
        "n_interior_vertices": int(len(cp.interior_vertices)),
        "n_boundary_vertices": int(len(cp.boundary_vertices)),
        "degree_histogram": {int(v): int(c) for v, c in zip(values, counts, strict=True)},
        "dimension": int(V.shape[1]),
        "flat": bool(cp.is_planar),
        "bounding_box": {
            "min": V.min(0).tolist() if len(V) else [],
            "max": V.max(0).tolist() if len(V) else [],
        },
        "size": cp.size,
        "n_holes": sum(f.code == "hole" for f in findings),
        "developable": cp.developable,
        "findings": [f.as_dict() for f in findings],
        "n_errors": sum(f.severity == "error" for f in findings),
    }


def generated_info(family: str, cp: CreasePattern) -> dict[str, Any]:
    """Family, parameters and counts of a generated pattern (``barhinge patterns NAME``)."""
    return {
        "family": family,
        "parameters": cp.meta.get("barhinge:parameters", {}),
        "n_vertices": cp.n_vertices,
        "n_edges": cp.n_edges,
        "n_faces": cp.n_faces,
        "n_interior_vertices": int(len(cp.interior_vertices)),
        "edges_by_assignment": {
            a: int((cp.assignment == a).sum())
            for a in ("M", "V", "F", "B")
            if (cp.assignment == a).any()
        },
        "folded": bool(not cp.is_flat),
        "developable": bool(cp.developable),
    }
