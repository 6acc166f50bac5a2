"""Russo-style optical-illusion pleat: pleats that change direction from strip to strip.

Source: the "Optical Illusion" tessellations of Andrea Russo (paper artist; photographs only,
no published crease patterns), one of the six study patterns of the thesis barhinge grew from
("Foldable structures adapted from tessellation origami with high degree of freedom").

Geometry chosen (and why)
-------------------------
The sheet is cut into ``strips`` horizontal strips of height ``height``. Inside each strip
run ``pleats`` narrow pleats (a valley line and a mountain line ``width`` apart, one pleat per
``pitch``) leaning by ``angle`` from the vertical, to the right in even strips and to the left
in odd ones. Where a pleat meets a strip boundary it is reversed (reverse fold), so the strip
boundaries are straight creases whose segments alternate M/V.

This is a Miura-ori with alternating narrow and wide panels (panel lengths
``[pitch - width, width, pitch - width, ...]`` along x and ``height / cos(angle)`` along the
pleats, sector angle ``90 - angle``). We chose it because (1) it reproduces the visual effect:
the shaded pleats zig-zag from strip to strip, so a nearly flat sheet looks corrugated; (2)
every vertex has sectors (gamma, pi - gamma, pi - gamma, gamma), so it is developable and
flat-foldable (Kawasaki, Maekawa 3:1); (3) being a Miura with varying panel lengths, it has an
exact rigid folding (``fold=`` gives it), which makes it a checkable benchmark.
"""

from __future__ import annotations

import numpy as np

from barhinge.families._common import check_int, check_range
from barhinge.families.miura_nonuniform import miura_from_lengths
from barhinge.pattern.crease import CreasePattern

__all__ = ["russo_pleat"]


def russo_pleat(
    pleats: int = 5,
    strips: int = 4,
    pitch: float = 1.0,
    width: float = 0.3,
    height: float = 1.0,
    angle: float = 25.0,
    fold: float | None = None,
    target: float = 60.0,
) -> CreasePattern:
    """Russo-style optical-illusion pleat (see the module docstring for the geometry).

    Parameters
    ----------
    pleats : int
        Pleats across the sheet, >= 1.
    strips : int
        Strips (pleat direction alternates between strips), >= 2.
    pitch : float
        Distance between pleats along x, > 0.
    width : float
        Width of a pleat (narrow panel) along x, in (0, pitch).
    height : float
        Strip height, > 0.
    angle : float
        Lean of the pleats from the vertical, degrees in (0, 90).
    fold : float or None
        Miura facet angle theta of the exact folded state (degrees, [0, 90]); None: flat.
    target : float
        Facet angle whose fold angles become the flat pattern's targets.

    Returns
    -------
    CreasePattern
        Grid layout as :func:`miura` (``meta['barhinge:grid']``).
    """
    fam = "russo_pleat"
    pleats = check_int("pleats", pleats, 1, family=fam)
    strips = check_int("strips", strips, 2, family=fam)
    pitch = check_range("pitch", pitch, 0.0, None, family=fam)
    width = check_range("width", width, 0.0, pitch, family=fam)
    height = check_range("height", height, 0.0, None, family=fam)
    angle = check_range("angle", angle, 0.0, 90.0, family=fam)
    if fold is not None:
        fold = check_range("fold", fold, 0.0, 90.0, lo_open=False, hi_open=False, family=fam)
    target = check_range("target", target, 0.0, 90.0, hi_open=False, family=fam)
    a = np.array([pitch - width, width] * pleats + [pitch - width])
    b = np.full(strips, height / np.cos(np.radians(angle)))
    params = {
        "pleats": pleats, "strips": strips, "pitch": pitch, "width": width, "height": height,
        "angle": angle, "fold": fold,
    }  # fmt: skip
    if fold is None:
        params["target"] = target
    return miura_from_lengths(a, b, 90.0 - angle, fold, target, family=fam, parameters=params)
