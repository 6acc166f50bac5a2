"""String vocabularies shared across modules (one place for every Literal)."""

from __future__ import annotations

from typing import Literal

Assignment = Literal["M", "V", "F", "B", "U", "C"]
ASSIGNMENTS: tuple[str, ...] = ("M", "V", "F", "B", "U", "C")
#: assignments whose edges are creases that may fold (fold hinges in a model)
FOLDING_ASSIGNMENTS: tuple[str, ...] = ("M", "V", "F", "U")

Scheme = Literal["N4B5", "N5B8"]
SCHEMES: tuple[str, ...] = ("N4B5", "N5B8")

HingeKind = Literal["fold", "bend"]
StrainMeasure = Literal["green", "engineering"]
ControlKind = Literal["fold_angle", "displacement", "load", "arc_length"]
