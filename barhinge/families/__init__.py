"""Parametric generators of origami tessellations, one module per family.

Every generator returns a :class:`~barhinge.pattern.crease.CreasePattern`: the flat state
with target fold angles from the assignment (valley > 0, mountain < 0, degrees), or, for the
families with a closed-form rigid folding (Miura and its variations, Yoshimura arch, pleats,
egg-box, Russo pleat), the exact folded state when ``fold=`` is given. Lengths are in the
user's unit, angles in degrees. Bad parameters raise :class:`~barhinge.errors.PatternError`
naming the parameter and its valid range. ``FAMILIES`` maps each family name to its generator.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any

from barhinge.families._common import GridLayout, grid_layout
from barhinge.families.diagonal import diagonal
from barhinge.families.eggbox import eggbox
from barhinge.families.hypar import hypar
from barhinge.families.kresling import kresling
from barhinge.families.miura import (
    MiuraGeometry,
    MiuraLayout,
    miura,
    miura_fold_angles,
    miura_geometry,
    miura_layout,
    miura_layout_of,
    miura_line_creases,
)
from barhinge.families.miura_arc import miura_arc
from barhinge.families.miura_nonuniform import miura_nonuniform
from barhinge.families.miura_tachi import miura_tachi
from barhinge.families.pleats import curved_pleats, pleats
from barhinge.families.resch import resch
from barhinge.families.russo import russo_pleat
from barhinge.families.square_twist import square_twist
from barhinge.families.waterbomb import waterbomb
from barhinge.families.yoshimura import yoshimura
from barhinge.pattern.crease import CreasePattern

FAMILIES: dict[str, Callable[..., CreasePattern]] = {
    "miura": miura,
    "miura_arc": miura_arc,
    "miura_nonuniform": miura_nonuniform,
    "miura_tachi": miura_tachi,
    "yoshimura": yoshimura,
    "pleats": pleats,
    "curved_pleats": curved_pleats,
    "eggbox": eggbox,
    "resch": resch,
    "waterbomb": waterbomb,
    "square_twist": square_twist,
    "kresling": kresling,
    "diagonal": diagonal,
    "hypar": hypar,
    "russo_pleat": russo_pleat,
}

#: families whose ``fold=`` parameter gives an exact rigidly folded state
FOLDABLE_FAMILIES: tuple[str, ...] = (
    "miura",
    "miura_arc",
    "miura_nonuniform",
    "yoshimura",
    "pleats",
    "eggbox",
    "russo_pleat",
)


def family_parameters(name: str) -> dict[str, Any]:
    """{parameter: default} of a family's generator (``inspect.Parameter.empty`` when
    required); PatternError for an unknown family."""
    from barhinge.errors import PatternError

    try:
        fn = FAMILIES[name]
    except KeyError:
        raise PatternError(
            f"unknown pattern family {name!r}; expected one of {', '.join(FAMILIES)}"
        ) from None
    return {p.name: p.default for p in inspect.signature(fn).parameters.values()}


def family_summary(name: str) -> str:
    """First line of a family generator's docstring."""
    doc = inspect.getdoc(FAMILIES[name]) or ""
    return doc.splitlines()[0] if doc else ""


__all__ = [
    "FAMILIES",
    "FOLDABLE_FAMILIES",
    "GridLayout",
    "MiuraGeometry",
    "MiuraLayout",
    "curved_pleats",
    "diagonal",
    "eggbox",
    "family_parameters",
    "family_summary",
    "grid_layout",
    "hypar",
    "kresling",
    "miura",
    "miura_arc",
    "miura_fold_angles",
    "miura_geometry",
    "miura_layout",
    "miura_layout_of",
    "miura_line_creases",
    "miura_nonuniform",
    "miura_tachi",
    "pleats",
    "resch",
    "russo_pleat",
    "square_twist",
    "waterbomb",
    "yoshimura",
]
