"""The transformation study's sweep function (``cells:cell``): one run of any kind.

It dispatches to the point functions of :mod:`transform` and to :func:`design.design`, and
sits above both, so that neither imports the other's caller.
"""

from __future__ import annotations

import transform
from design import design


def cell(kind: str, pattern: str, quick: bool = True, steps: int = 6, **params) -> dict:
    """One run of the study: ``kind`` is ``"form"`` (:func:`transform.point`),
    ``"placement"`` (:func:`transform.placement_point`) or ``"design"``
    (:func:`design.design`)."""
    if kind == "form":
        return transform.point(pattern, quick=quick, steps=steps, **params)
    if kind == "placement":
        return transform.placement_point(pattern, quick=quick, steps=steps, **params)
    if kind == "design":
        return design(pattern, quick=quick, **params)
    raise ValueError(f"kind must be 'form', 'placement' or 'design', got {kind!r}")
