"""Material of the sheet: an isotropic thin plate (E, nu, t), its bending rigidity and its
plane-stress stiffness. The calibration rules (:mod:`barhinge.model.calibrate`) and the
continuum reference (:mod:`barhinge.model.continuum`) both start from it."""

from __future__ import annotations

import dataclasses

import numpy as np

from barhinge import _check
from barhinge.errors import ConfigError

__all__ = ["Material"]


@dataclasses.dataclass(frozen=True)
class Material:
    """Isotropic thin sheet.

    Parameters
    ----------
    E : Young's modulus (force / length^2).
    nu : Poisson's ratio, in [0, 0.5).
    t : thickness (length).
    """

    E: float = 1.0e6
    nu: float = 0.3
    t: float = 0.01

    def __post_init__(self) -> None:
        # E > 0 and t > 0 finite; 0 <= nu < 0.5 (the membrane fit and the F17 bar areas
        # assume a compressible, non-auxetic sheet; nu -> 0.5 makes bar areas vanish)
        object.__setattr__(self, "E", _check.number(self.E, "material.E", 0.0, lo_open=True))
        object.__setattr__(
            self, "nu", _check.number(self.nu, "material.nu", 0.0, 0.5, hi_open=True)
        )
        object.__setattr__(self, "t", _check.number(self.t, "material.t", 0.0, lo_open=True))
        if not np.isfinite(self.bending_rigidity) or self.bending_rigidity == 0.0:
            raise ConfigError(
                f"material.t = {self.t!r} with material.E = {self.E!r}: the bending rigidity "
                "E t^3 / (12 (1 - nu^2)) is not a positive finite number"
            )

    @property
    def bending_rigidity(self) -> float:
        """Plate bending rigidity ``D = E t^3 / (12 (1 - nu^2))`` (force x length)."""
        return self.E * self.t * self.t * self.t / (12.0 * (1.0 - self.nu * self.nu))

    def membrane_mandel(self) -> np.ndarray:
        """(3, 3) plane-stress stiffness in Mandel notation (shear entry ``E/(1+nu)``)."""
        nu, E = self.nu, self.E
        c = E / (1.0 - nu * nu)
        return c * np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 1.0 - nu]])
