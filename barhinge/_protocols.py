"""The ``Protocol`` of the model the solver needs (:class:`SolverModel`) and of one
evaluation of it (:class:`ModelEvaluation`): what :mod:`barhinge.solver` reads of a model,
written once. Kept apart from :mod:`barhinge._typing` so that ``import barhinge`` does not
pay for it.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np

from barhinge._typing import Scheme

__all__ = ["ModelEvaluation", "SolverModel"]


class ModelEvaluation(Protocol):
    """One evaluation of a model at coordinates ``X`` (``BarHingeModel.evaluate``)."""

    @property
    def energy_bars(self) -> float: ...
    @property
    def energy_bend(self) -> float: ...
    @property
    def energy_fold(self) -> float: ...
    @property
    def force(self) -> np.ndarray:
        """(n_dof,) internal force dE/dX (xyz interleaved), force."""
        ...

    @property
    def K(self) -> Any:
        """(n_dof, n_dof) sparse tangent d2E/dX2 (None without ``tangent``), force/length."""
        ...


@runtime_checkable
class SolverModel(Protocol):
    """The model the solver needs: what :mod:`barhinge.solver` reads of a model.
    :class:`barhinge.model.model.BarHingeModel` is one; any object with these members can be
    solved.

    Shapes: ``X0`` (n_nodes, 3) reference coordinates, length; ``bars`` (n_bars, 2) node
    pairs; ``hinges`` (n_hinges, 4) node quadruples ``[i, j, k, l]`` (axis i-j);
    ``hinge_kind`` (n_hinges,) ``"fold"`` / ``"bend"``; ``hinge_edge`` (n_hinges,) pattern
    edge of a fold hinge (-1 for a bend hinge); ``hinge_k`` (n_hinges,) rotational stiffness,
    force x length / rad; ``rest_angle`` (n_hinges,) rad.
    """

    @property
    def pattern(self) -> Any: ...
    @property
    def scheme(self) -> Scheme: ...
    @property
    def X0(self) -> np.ndarray: ...
    @property
    def bars(self) -> np.ndarray: ...
    @property
    def hinges(self) -> np.ndarray: ...
    @property
    def hinge_kind(self) -> np.ndarray: ...
    @property
    def hinge_edge(self) -> np.ndarray: ...
    @property
    def hinge_k(self) -> np.ndarray: ...
    @property
    def rest_angle(self) -> np.ndarray: ...
    @property
    def n_nodes(self) -> int: ...
    @property
    def n_dof(self) -> int: ...
    def evaluate(self, X: np.ndarray, tangent: bool = True) -> ModelEvaluation:
        """Energy, internal force and (``tangent``) tangent stiffness at ``X``."""
        ...

    def crease_fold_angles_deg(self, X: np.ndarray) -> np.ndarray:
        """(n_edges,) fold angle of every pattern edge at ``X``, deg (0 off the creases)."""
        ...
