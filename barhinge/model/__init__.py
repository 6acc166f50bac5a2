"""The bar-and-hinge model: triangulation, topology, calibration and the model object."""

from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel, Evaluation

__all__ = ["BarHingeModel", "Evaluation", "Material"]
