"""BarHingeModel: the bar-and-hinge model of a crease pattern (Filipov et al. 2017;
Liu & Paulino 2017).

Energy ``E(X) = sum_bars W_b(eps_b) + sum_bend W_h(rho_h) + sum_fold W_f(rho_f)``, or with
the constant-strain-triangle membrane (``bar_calibration="cst"``, :mod:`barhinge.model.membrane`)
the bars' part ``eps^T C eps / 2`` with the sides of each triangle coupled; the
internal force is ``dE/dX`` and the tangent ``d^2E/dX^2`` (material + geometric parts), both
exact. Node ordering: the pattern's vertices first (in order), then the centre nodes of N5B8
quads and polygons.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
from functools import cached_property
from typing import Any

import numpy as np
import scipy.sparse as sp

from barhinge import _check
from barhinge._disk_cache import load_array, make_key, store_array
from barhinge._typing import SCHEMES, Scheme, StrainMeasure
from barhinge.assembly import Assembler, PackedRows
from barhinge.errors import ConfigError
from barhinge.kernels.geometry import (
    BAR_CHUNK,
    bar_strain,
    bar_strain_gradient,
    bar_strain_hessian,
    element_passes,
    hinge_angle,
    hinge_angle_gradient_t,
    hinge_energy_hessian_packed,
)
from barhinge.kernels.laws import bar_linear, hinge_linear, hinge_penetration
from barhinge.linalg.heap import release_free_heap
from barhinge.linalg.threads import parallel_map
from barhinge.model.calibrate import (
    BAR_CALIBRATIONS,
    BEND_COEFFICIENT_F17,
    bar_areas,
    bend_stiffness,
    bend_stiffness_kirchhoff,
    face_areas,
    face_frames,
)
from barhinge.model.calibrate import (
    fold_stiffness as _fold_stiffness,
)
from barhinge.model.continuum import panel_corner_stiffness, plate_corner_stiffness
from barhinge.model.hinge_pairs import pair_matrix, pair_nodes
from barhinge.model.material import Material
from barhinge.model.membrane import cst_bar_matrix
from barhinge.model.topology import build_topology
from barhinge.model.triangulate import triangulate
from barhinge.pattern.crease import CreasePattern

logger = logging.getLogger(__name__)

__all__ = [
    "BarHingeModel",
    "ElementStates",
    "Evaluation",
    "FOLD_LAWS",
    "MEMBRANES",
    "plate_bend_scale",
]

FOLD_LAWS = ("linear", "penetration")
#: the panels' membrane: bars calibrated by one of ``BAR_CALIBRATIONS``, or ``"cst"``, the
#: constant-strain triangle written in the bars' strains (exact for every triangle shape)
MEMBRANES = (*BAR_CALIBRATIONS, "cst")

# packed upper triangle of a bar's 6x6 [[k, -k], [-k, k]]: which of the 6 distinct entries
# of the symmetric 3x3 k (_SYM3) each packed entry holds, with which sign; _BAR_FIRST[q] is
# the first packed entry holding +k[q] (computed there, copied to the others)
_r6, _c6 = np.triu_indices(6)
_SYM3 = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]
_BAR_Q = np.array(
    [
        _SYM3.index((min(int(a) % 3, int(b) % 3), max(int(a) % 3, int(b) % 3)))
        for a, b in zip(_r6, _c6, strict=True)
    ]
)
_BAR_SIGN = np.where((_r6 < 3) == (_c6 < 3), 1.0, -1.0)
_BAR_FIRST = [int(np.flatnonzero((_BAR_Q == q) & (_BAR_SIGN > 0))[0]) for q in range(6)]


@dataclasses.dataclass(frozen=True, eq=False)
class Evaluation:
    """Result of one :meth:`BarHingeModel.evaluate` pass.

    Attributes
    ----------
    energy_bars, energy_bend, energy_fold : float
        Stored energy in bars, bending hinges and fold hinges.
    force : (n_dof,) float
        Internal force ``dE/dX`` (flattened ``(n_nodes, 3)``, xyz interleaved).
    K : csr (n_dof, n_dof) or None
        Tangent stiffness ``d^2E/dX^2`` (None if ``tangent=False``).
    bar_strain : (n_bars,) float
    bar_force : (n_bars,) float
        Axial force ``dW/deps / L0`` (``EA eps`` for a bar; tension > 0).
    hinge_angle : (n_hinges,) float
        Radians, FOLD convention.
    hinge_moment : (n_hinges,) float
        ``dW/drho`` (moment per hinge, force x length).
    """

    energy_bars: float
    energy_bend: float
    energy_fold: float
    force: np.ndarray
    K: sp.csr_matrix | None
    bar_strain: np.ndarray
    bar_force: np.ndarray
    hinge_angle: np.ndarray
    hinge_moment: np.ndarray

    @property
    def energy(self) -> float:
        """Total stored energy."""
        return self.energy_bars + self.energy_bend + self.energy_fold


@dataclasses.dataclass(frozen=True, eq=False)
class ElementStates:
    """Forces and energies of every element at one state (:meth:`BarHingeModel.element_states`).

    Attributes
    ----------
    bar_axial_force : (n_bars,) float
        Force a bar exerts on its end nodes, ``S |d eps / dx|`` with ``S = dW/deps``; tension
        > 0 (force).
    bar_energy : (n_bars,) float
        Stored energy of each bar (force x length).
    hinge_angle : (n_hinges,) float
        Radians, FOLD convention (valley > 0).
    hinge_moment : (n_hinges,) float
        ``dW/drho``, couplings included (force x length).
    hinge_energy : (n_hinges,) float
        Stored energy of each hinge, half of each coupling's included (force x length).
    """

    bar_axial_force: np.ndarray
    bar_energy: np.ndarray
    hinge_angle: np.ndarray
    hinge_moment: np.ndarray
    hinge_energy: np.ndarray


def _ro(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.setflags(write=False)
    return a


def _bar_hessian_rows(
    rows: PackedRows,
    d: np.ndarray,
    eps: np.ndarray,
    S: np.ndarray,
    dS: np.ndarray,
    L0: np.ndarray,
    strain: StrainMeasure,
) -> None:
    """Write the packed upper triangles of the bars' energy Hessians
    ``[[k, -k], [-k, k]]``, ``k = S' d d^T + S B`` (``S`` the axial force conjugate to the
    strain, ``S'`` its derivative, ``d`` the strain gradient, ``B`` its Hessian), into
    ``rows``: the 6 distinct entries of the symmetric 3x3 ``k``, then the other 15 rows as
    signed copies."""
    dT = np.ascontiguousarray(d.T)
    B = bar_strain_hessian(d, eps, L0, strain)
    for q, (a, b) in enumerate(_SYM3):
        row = rows[_BAR_FIRST[q]]
        np.multiply(dS * dT[a], dT[b], out=row)
        row += S * B[:, a, b]
    for p_, (q, sgn) in enumerate(zip(_BAR_Q, _BAR_SIGN, strict=True)):
        if p_ != _BAR_FIRST[q]:
            np.multiply(rows[_BAR_FIRST[q]], sgn, out=rows[p_])


@dataclasses.dataclass(frozen=True, eq=False)
class BarHingeModel:
    """A bar-and-hinge model. Build it with :meth:`from_pattern`; all arrays are read-only.

    Attributes
    ----------
    pattern : CreasePattern
    scheme : "N4B5" | "N5B8"
    material : Material
    X0 : (n_nodes, 3) reference coordinates.
    bars : (n_bars, 2) int; bar_EA, bar_L0 : (n_bars,)
    hinges : (n_hinges, 4) int (i, j, k, l)
    hinge_kind : (n_hinges,) "fold" | "bend"
    hinge_edge, hinge_face : (n_hinges,) int (-1 where not applicable)
    hinge_k : (n_hinges,) rotational stiffness (moment per radian, length included)
    rest_angle : (n_hinges,) rad, FOLD convention
    fold_law : "linear" | "penetration"
    fold_limits : (rho_min, rho_max) radians of the penetration law
    strain : "green" | "engineering"
    hinge_pairs : (n_pairs, 2) int, hinges whose angles are coupled (empty by default)
    pair_k : (n_pairs,) coupling ``c`` of the energy ``c (rho_i - rho_i0) (rho_j - rho_j0)``
        (moment per radian; :mod:`barhinge.model.hinge_pairs`)
    bar_pairs : (n_bar_pairs, 2) int, bars whose strains are coupled (the sides of each
        triangle with the CST membrane; empty by default)
    bar_pair_c : (n_bar_pairs,) coupling ``c`` of the energy ``c eps_i eps_j`` (force x
        length; :mod:`barhinge.model.membrane`)
    """

    pattern: CreasePattern
    scheme: Scheme
    material: Material
    X0: np.ndarray
    bars: np.ndarray
    bar_EA: np.ndarray
    bar_L0: np.ndarray
    hinges: np.ndarray
    hinge_kind: np.ndarray
    hinge_edge: np.ndarray
    hinge_face: np.ndarray
    hinge_k: np.ndarray
    rest_angle: np.ndarray
    fold_law: str = "linear"
    fold_limits: tuple[float, float] = (-0.75 * np.pi, 0.75 * np.pi)
    strain: StrainMeasure = "green"
    meta: dict[str, Any] = dataclasses.field(default_factory=dict)
    hinge_pairs: np.ndarray = dataclasses.field(
        default_factory=lambda: _ro(np.zeros((0, 2), np.int64))
    )
    pair_k: np.ndarray = dataclasses.field(default_factory=lambda: _ro(np.zeros(0)))
    bar_pairs: np.ndarray = dataclasses.field(
        default_factory=lambda: _ro(np.zeros((0, 2), np.int64))
    )
    bar_pair_c: np.ndarray = dataclasses.field(default_factory=lambda: _ro(np.zeros(0)))

    # ------------------------------------------------------------------ creation
    @classmethod
    def from_pattern(
        cls,
        cp: CreasePattern,
        scheme: Scheme = "N5B8",
        material: Material | None = None,
        *,
        fold_stiffness: float | None = None,
        crease_length_scale: float | None = None,
        stiffness_ratio: float | None = None,
        fold_law: str = "linear",
        fold_limits_deg: tuple[float, float] = (-135.0, 135.0),
        bar_calibration: str = "fit",
        bend_coefficient: float | None = None,
        bend_calibration: str = "plate",
        bar_EA: np.ndarray | float | None = None,
        bend_k: np.ndarray | float | None = None,
        fold_k: np.ndarray | float | None = None,
        strain: StrainMeasure = "green",
    ) -> BarHingeModel:
        """Triangulate ``cp`` and calibrate the stiffnesses.

        Parameters
        ----------
        cp : CreasePattern, in any state; its state becomes the stress-free reference
            (rest angles = state fold angles).
        scheme : ``"N4B5"`` or ``"N5B8"`` for quadrilateral faces.
        material : Material (default ``Material()``).
        fold_stiffness : fold stiffness per unit crease length (moment per radian per length);
            or ``crease_length_scale`` L*: ``k = E t^3 / (12 (1 - nu^2) L*)`` (Filipov et al.
            2017). Default ``L* = 100 t``.
        stiffness_ratio : multiply bar EA and bending stiffness by this factor (rigid-panel
            limit studies).
        fold_law : ``"linear"`` or ``"penetration"`` (Liu & Paulino 2017) with
            ``fold_limits_deg``.
        bar_calibration : ``"fit"`` (default, all membrane moduli), ``"filipov"`` (F17),
            ``"dilation"`` (``"fit"`` with the uniform-dilation energy exact) or ``"cst"``
            (the constant-strain triangle: bars of a triangle coupled, exact for every
            triangle shape; :mod:`barhinge.model.membrane`); the errors of each against a
            plane-stress membrane are tabulated in docs/calibration.md.
        bend_coefficient : ``C_B`` of the ``"filipov"`` rule (default 0.55); an error with
            the other rules.
        bend_calibration : ``"plate"`` (default: ``"kirchhoff"`` scaled per face shape so
            that the panel's corner-warping stiffness equals a Morley plate's; exact for every
            quadrilateral; one small FE solve per distinct face shape), ``"kirchhoff"``
            (``2 D (1 - nu) A / D_L^2``, exact twisting of a rectangular Kirchhoff plate) or
            ``"filipov"`` (``C_B D (D_L/t)^(1/3)``, Filipov et al. 2017). See
            docs/calibration.md.
        bar_EA, bend_k, fold_k : overrides (scalar or per-element array: per bar, per bend
            hinge in model order, per fold hinge in model order).
        strain : ``"green"`` or ``"engineering"`` bar strain.
        """
        _check.choice(scheme, "scheme", SCHEMES)
        _check.choice(fold_law, "fold_law", FOLD_LAWS)
        _check.choice(strain, "strain", ("green", "engineering"))
        _check.choice(bar_calibration, "bar_calibration", MEMBRANES)
        _check.choice(bend_calibration, "bend_calibration", ("filipov", "kirchhoff", "plate"))
        lim = _check.float_array(fold_limits_deg, "fold_limits_deg", (2,))
        lo, hi = float(lim[0]), float(lim[1])
        if not -180.0 < lo < 0.0 < hi < 180.0:
            raise ConfigError(
                f"fold_limits_deg = {lim.tolist()}; expected -180 < min < 0 < max < 180"
            )
        if fold_stiffness is not None:
            fold_stiffness = _check.number(fold_stiffness, "fold_stiffness", 0.0)
        if crease_length_scale is not None:
            crease_length_scale = _check.number(
                crease_length_scale, "crease_length_scale", 0.0, lo_open=True
            )
        if stiffness_ratio is not None:
            stiffness_ratio = _check.number(stiffness_ratio, "stiffness_ratio", 0.0, lo_open=True)
        if bend_coefficient is None:
            bend_coefficient = BEND_COEFFICIENT_F17
        else:
            bend_coefficient = _check.number(bend_coefficient, "bend_coefficient", 0.0)
            if bend_calibration != "filipov":
                raise ConfigError(
                    f"bend_coefficient is the C_B of bend_calibration='filipov'; it has no "
                    f"effect with bend_calibration={bend_calibration!r}"
                )
        mat = Material() if material is None else material
        if not isinstance(mat, Material):
            raise ConfigError(f"material must be a Material, got {type(mat).__name__}")
        tri = triangulate(cp, scheme)
        topo = build_topology(cp, tri)
        X0 = tri.X0
        bars, hinges = topo.bars, topo.hinges
        L0 = np.linalg.norm(X0[bars[:, 1]] - X0[bars[:, 0]], axis=1)
        is_fold = topo.hinge_kind == "fold"
        is_bend = ~is_fold
        axis_len = np.linalg.norm(X0[hinges[:, 1]] - X0[hinges[:, 0]], axis=1)

        bar_pairs, bar_pair_c = np.zeros((0, 2), np.int64), np.zeros(0)
        if bar_calibration == "cst":
            if bar_EA is not None:
                raise ConfigError(
                    "bar_EA overrides the bars of a bar calibration; the 'cst' membrane has "
                    "no bar areas to override"
                )
            diagonal, bar_pairs, bar_pair_c = cst_bar_matrix(X0, tri.triangles, bars, mat)
            EA = diagonal / L0
        else:
            EA = mat.E * bar_areas(cp, tri, topo, mat, bar_calibration)
        # diagonal the bending hinge lies on: the axis itself (N4B5) or corner-centre-corner
        centred = (hinges[:, :2] >= cp.n_vertices).any(axis=1)
        DL = np.where(centred, 2.0 * axis_len, axis_len)
        k = np.zeros(len(hinges))
        if bend_calibration == "filipov":
            k[is_bend] = bend_stiffness(DL[is_bend], mat, bend_coefficient)
        elif bend_calibration in ("kirchhoff", "plate"):
            area = face_areas(cp, X0)[topo.hinge_face[is_bend]]
            k[is_bend] = bend_stiffness_kirchhoff(area, DL[is_bend], mat)
            if bend_calibration == "plate" and is_bend.any():
                hf = topo.hinge_face[is_bend]
                uf, inv = np.unique(hf, return_inverse=True)
                k[is_bend] *= plate_bend_scale(cp, scheme, mat, uf)[inv.ravel()]
        else:
            raise ConfigError(
                f"bend_calibration {bend_calibration!r} is unknown; expected 'filipov', "
                "'kirchhoff' or 'plate'"
            )
        k[is_fold] = _fold_stiffness(axis_len[is_fold], mat, fold_stiffness, crease_length_scale)
        if bar_EA is not None:
            EA = _override(EA, bar_EA, len(bars), "bar_EA")
        if bend_k is not None:
            k[is_bend] = _override(k[is_bend], bend_k, int(is_bend.sum()), "bend_k")
        if fold_k is not None:
            k[is_fold] = _override(k[is_fold], fold_k, int(is_fold.sum()), "fold_k")
        if stiffness_ratio is not None:
            if not stiffness_ratio > 0:
                raise ConfigError(f"stiffness_ratio = {stiffness_ratio}; expected > 0")
            EA = EA * stiffness_ratio
            bar_pair_c = bar_pair_c * stiffness_ratio
            k[is_bend] *= stiffness_ratio
        rest = hinge_angle(X0, hinges)
        for what, arr in (
            ("coordinates", X0),
            ("bar lengths", L0),
            ("bar stiffness", EA),
            ("bar couplings", bar_pair_c),
            ("hinge stiffness", k),
            ("rest angles", rest),
        ):
            if not np.all(np.isfinite(arr)):
                raise ConfigError(
                    f"the model has non-finite {what}: the pattern's size or the material "
                    "constants overflow floating point"
                )
        model = cls(
            pattern=cp,
            scheme=scheme,
            material=mat,
            X0=_ro(X0),
            bars=_ro(bars),
            bar_EA=_ro(EA),
            bar_L0=_ro(L0),
            hinges=_ro(hinges),
            hinge_kind=_ro(topo.hinge_kind),
            hinge_edge=_ro(topo.hinge_edge),
            hinge_face=_ro(topo.hinge_face),
            hinge_k=_ro(k),
            rest_angle=_ro(rest),
            fold_law=fold_law,
            fold_limits=(np.radians(lo), np.radians(hi)),
            strain=strain,
            bar_pairs=_ro(bar_pairs),
            bar_pair_c=_ro(bar_pair_c),
            meta={
                "bar_calibration": bar_calibration,
                "bend_calibration": bend_calibration,
                "bend_coefficient": bend_coefficient if bend_calibration == "filipov" else None,
            },
        )
        release_free_heap(model.n_dof)  # the construction's temporaries
        return model

    def with_(self, **changes: Any) -> BarHingeModel:
        """A new model with some fields replaced (arrays are validated for length)."""
        kw = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        for name, val in changes.items():
            if name not in kw:
                raise ConfigError(f"BarHingeModel has no field {name!r}")
            if name in ("hinge_pairs", "pair_k", "bar_pairs", "bar_pair_c"):
                kw[name] = _ro(np.array(val, dtype=kw[name].dtype))
                continue
            if isinstance(kw[name], np.ndarray):
                val = np.array(val, dtype=kw[name].dtype)
                if val.shape != kw[name].shape:
                    raise ConfigError(f"{name} must have shape {kw[name].shape}, got {val.shape}")
                val = _ro(val)
            kw[name] = val
        _check_pairs(kw, "hinge_pairs", "pair_k", "hinges")
        _check_pairs(kw, "bar_pairs", "bar_pair_c", "bars")
        new = BarHingeModel(**kw)
        # same connectivity: share the (expensive) scatter maps
        same = not {"bars", "hinges", "hinge_pairs", "bar_pairs"} & set(changes)
        if "assembler" in self.__dict__ and same:
            if len(new.X0) == len(self.X0):
                new.__dict__["assembler"] = self.__dict__["assembler"]
        return new

    def stiffened(self, ratio: float) -> BarHingeModel:
        """A new model with the membrane (bar EA and couplings) and bending stiffness
        multiplied by ``ratio``."""
        if not ratio > 0:
            raise ConfigError(f"stiffness ratio = {ratio}; expected > 0")
        k = np.array(self.hinge_k)
        k[self.hinge_kind == "bend"] *= ratio
        both_bend = (self.hinge_kind[self.hinge_pairs] == "bend").all(axis=1)
        pk = np.where(both_bend, self.pair_k * ratio, self.pair_k)
        return self.with_(
            bar_EA=self.bar_EA * ratio, bar_pair_c=self.bar_pair_c * ratio, hinge_k=k, pair_k=pk
        )

    # ------------------------------------------------------------------ sizes
    @property
    def n_nodes(self) -> int:
        return len(self.X0)

    @property
    def n_dof(self) -> int:
        return 3 * len(self.X0)

    @property
    def n_bars(self) -> int:
        return len(self.bars)

    @property
    def n_hinges(self) -> int:
        return len(self.hinges)

    @cached_property
    def fold_hinge_of_edge(self) -> np.ndarray:
        """(n_edges,) hinge index of each pattern edge's fold hinge, -1 if none."""
        out = -np.ones(self.pattern.n_edges, dtype=np.int64)
        f = np.flatnonzero(self.hinge_kind == "fold")
        out[self.hinge_edge[f]] = f
        return _ro(out)

    @cached_property
    def _is_fold(self) -> np.ndarray:
        return _ro(self.hinge_kind == "fold")

    @cached_property
    def fold_limits_per_hinge(self) -> tuple[np.ndarray, np.ndarray]:
        """(rho_min, rho_max) of the penetration law for each fold hinge (model order of the
        fold hinges): ``fold_limits`` widened to the rest angle where the rest angle lies
        beyond a limit (that crease's stiffening branch starts at its rest angle, so the
        reference state stays stress-free)."""
        r0 = self.rest_angle[self._is_fold]
        lo, hi = self.fold_limits
        return _ro(np.minimum(lo, r0)), _ro(np.maximum(hi, r0))

    @cached_property
    def assembler(self) -> Assembler:
        """Sparsity pattern and scatter maps (built once)."""
        # the hinge couplings' entries are in the pattern; their values come from one sparse
        # product per evaluation (:meth:`_add_pair_tangent`), not from per-pair element
        # matrices (up to 231 values per pair, most of a refined panel's memory)
        pairs = [pair_nodes(self.hinges, self.hinge_pairs)] if len(self.hinge_pairs) else []
        asm = Assembler(self.n_nodes, [self.bars, self.hinges], pattern_groups=pairs)
        release_free_heap(self.n_dof)  # its construction's temporaries
        return asm

    def release_assembler(self) -> int:
        """Drop the cached :attr:`assembler` (its scatter maps and pattern); the next
        evaluation builds it again. For a linear analysis of a large model that needs no
        more tangents, this frees the maps before its factorisation. Returns the bytes the
        maps held (0 when none were built)."""
        asm = self.__dict__.pop("assembler", None)
        return 0 if asm is None else asm.nbytes

    @cached_property
    def _pair_C(self) -> sp.csr_matrix:
        return pair_matrix(self.n_hinges, np.asarray(self.hinge_pairs), np.asarray(self.pair_k))

    def _add_pair_tangent(self, K: sp.csr_matrix, grad: np.ndarray) -> None:
        """Add the hinge couplings' tangent ``G^T C G`` into ``K`` (in place): ``G``
        (n_hinges, n_dof) the hinge-angle gradients ``grad`` (12, n_hinges; node-major) and
        ``C`` the coupling matrix. The pairs' second-order part (moment times the angle's
        Hessian) is in each hinge's own element, whose moment includes ``C (rho - rho0)``."""
        nh = self.n_hinges
        asm = self.assembler
        dofs = asm.dofs[1]  # the hinges' (n_hinges, 12) dofs, the assembler's second group
        G = sp.csr_matrix(
            (np.ascontiguousarray(grad.T).ravel(), dofs.ravel(), np.arange(0, 12 * nh + 1, 12)),
            shape=(nh, self.n_dof),
        )
        asm.add_entries(K, G.T @ (self._pair_C @ G))

    @cached_property
    def _bar_C(self) -> sp.csr_matrix:
        """(n_bars, n_bars) symmetric off-diagonal part of the membrane matrix ``C``."""
        nb = self.n_bars
        i, j = np.asarray(self.bar_pairs, np.int64).T
        c = np.asarray(self.bar_pair_c, float)
        return sp.csr_matrix((np.r_[c, c], (np.r_[i, j], np.r_[j, i])), shape=(nb, nb))

    def bar_law(self, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(dW/deps, d^2W/deps_b^2, W)`` per bar at the strains ``eps`` (n_bars,): the bars'
        own ``EA L0`` plus, with bar couplings, ``(C eps)_b`` in the first and half of each
        coupling's energy in the last (the cross second derivatives are :attr:`_bar_C`)."""
        S, dS, W = bar_linear(eps, self.bar_EA, self.bar_L0)
        if len(self.bar_pairs):
            Ce = self._bar_C @ eps
            S = S + Ce
            W = W + 0.5 * eps * Ce
        return S, dS, W

    def _add_bar_pair_tangent(self, K: sp.csr_matrix, d: np.ndarray) -> None:
        """Add the bar couplings' tangent ``G^T C_off G`` into ``K`` (in place): ``G`` (n_bars,
        n_dof) the bar-strain gradients (``-d`` at the first node, ``d`` at the second); one
        sparse product per evaluation, as for the hinge couplings."""
        nb = self.n_bars
        dofs = self.assembler.dofs[0]  # the bars' (n_bars, 6) dofs, the first group
        vals = np.concatenate([-d, d], axis=1)
        G = sp.csr_matrix(
            (vals.ravel(), dofs.ravel(), np.arange(0, 6 * nb + 1, 6)), shape=(nb, self.n_dof)
        )
        self.assembler.add_entries(K, G.T @ (self._bar_C @ G))

    def _pair_moment(self, rho: np.ndarray) -> np.ndarray | None:
        """(n_hinges,) moments ``C (rho - rho0)`` of the hinge couplings (None without)."""
        if not len(self.hinge_pairs):
            return None
        return self._pair_C @ (rho - self.rest_angle)

    # ------------------------------------------------------------------ evaluation
    @cached_property
    def _limits_all(self) -> tuple[np.ndarray, np.ndarray]:
        lo = np.full(self.n_hinges, -np.inf)
        hi = np.full(self.n_hinges, np.inf)
        lo[self._is_fold], hi[self._is_fold] = self.fold_limits_per_hinge
        return _ro(lo), _ro(hi)

    def _hinge_law(
        self, rho: np.ndarray, sl: slice = slice(None), pair_moment: np.ndarray | None = None
    ):
        """(M, dM/drho, W) of the hinges ``sl`` at the angles ``rho``; with hinge couplings
        the moment includes ``(C d)_i`` and the energy ``d_i (C d)_i / 2`` (each pair's
        energy split between its hinges). ``pair_moment`` (all hinges) is needed when ``sl``
        is not every hinge."""
        M, Kt, W = self._own_hinge_law(rho, sl)
        if len(self.hinge_pairs):
            if pair_moment is None:
                if len(rho) != self.n_hinges:
                    raise ValueError("hinge couplings need the moments of all hinges")
                pair_moment = self._pair_moment(rho)
            assert pair_moment is not None
            pm = pair_moment[sl]
            M = M + pm
            W = W + 0.5 * (rho - self.rest_angle[sl]) * pm
        return M, Kt, W

    def _own_hinge_law(self, rho: np.ndarray, sl: slice = slice(None)):
        """(M, dM/drho, W) of the hinges' own springs (no couplings)."""
        M, Kt, W = hinge_linear(rho, self.rest_angle[sl], self.hinge_k[sl])
        if self.fold_law == "penetration":
            f = self._is_fold[sl]
            lo, hi = (v[sl][f] for v in self._limits_all)
            Mf, Kf, Wf = hinge_penetration(
                rho[f], self.rest_angle[sl][f], self.hinge_k[sl][f], lo, hi
            )
            M[f], Kt[f], W[f] = Mf, Kf, Wf
        return M, Kt, W

    def _check_X(self, X: np.ndarray) -> np.ndarray:
        X = np.asarray(X, dtype=float)
        if X.shape == (self.n_dof,):
            X = X.reshape(-1, 3)
        if X.shape != (self.n_nodes, 3):
            raise ConfigError(f"X must have shape ({self.n_nodes}, 3), got {X.shape}")
        return X

    def evaluate(self, X: np.ndarray, tangent: bool = True) -> Evaluation:
        """Energy split, internal force and (optionally) the tangent at ``X`` in one pass.

        Parameters
        ----------
        X : (n_nodes, 3) or (n_dof,) float
        tangent : also assemble the sparse tangent stiffness.
        """
        X = self._check_X(X)
        bars, hinges = self.bars, self.hinges
        eps, d = bar_strain_gradient(X, bars, self.bar_L0, self.strain)
        S, dS, Wb = self.bar_law(eps)
        asm = self.assembler
        law = self._hinge_law
        if len(self.hinge_pairs):
            law = functools.partial(law, pair_moment=self._pair_moment(hinge_angle(X, hinges)))
        K = None
        if tangent:
            nh = len(hinges)
            rho, M, Kt, Wh = (np.empty(nh) for _ in range(4))
            # the hinge gradients (12 floats a hinge) are kept only for the couplings'
            # tangent; the force is summed chunk by chunk as the element values are written
            g = np.empty((12, nh)) if len(self.hinge_pairs) else None
            force = np.zeros(self.n_dof)
            XT = np.ascontiguousarray(X.T)
            L0, strain = self.bar_L0, self.strain

            def fill(group: int, sl: slice, rows: PackedRows) -> None:
                """The packed upper triangles of the elements ``sl`` of a group, and their
                internal force added to ``force``."""
                if group == 0:
                    # bar: [[k, -k], [-k, k]] with k = S'' d d^T + S B, packed upper
                    # triangle of 6x6; the 6 distinct entries of the symmetric 3x3 k. B and
                    # d's rows are made pass by pass (not held for all bars)
                    def bar_pass(part: slice) -> None:
                        own = slice(sl.start + part.start, sl.start + part.stop)
                        _bar_hessian_rows(
                            rows[:, part], d[own], eps[own], S[own], dS[own], L0[own], strain
                        )

                    parallel_map(bar_pass, element_passes(sl.stop - sl.start, BAR_CHUNK))
                    fb = d[sl].T * S[sl]
                    asm.add_force(force, 0, sl, np.concatenate([-fb, fb]))
                else:  # packed upper triangle (78, nh) of the hinge Hessian
                    out = hinge_energy_hessian_packed(
                        X, hinges[sl], law, rows, start=sl.start, XT=XT
                    )
                    rho[sl], M[sl], Kt[sl], Wh[sl], g_sl = out[:5]
                    if g is not None:
                        g[:, sl] = g_sl
                    asm.add_force(force, 1, sl, g_sl * M[sl])

            sums = asm.block_sums_filled(fill)  # one chunk of element values at a time
            del XT
            K = asm.matrix_from_sums(sums)  # in the sums' own buffer
            del sums
            if g is not None:
                self._add_pair_tangent(K, g)
            if len(self.bar_pairs):
                self._add_bar_pair_tangent(K, d)
        else:
            rho, g = hinge_angle_gradient_t(X, hinges)
            M, Kt, Wh = self._hinge_law(rho)
            fb = (S[:, None] * d).T  # (3, nb)
            force = asm.force([np.concatenate([-fb, fb], axis=0), np.multiply(g, M, out=g)])
        f = self._is_fold
        return Evaluation(
            energy_bars=float(Wb.sum()),
            energy_bend=float(Wh[~f].sum()),
            energy_fold=float(Wh[f].sum()),
            force=force,
            K=K,
            bar_strain=eps,
            bar_force=S / self.bar_L0,
            hinge_angle=rho,
            hinge_moment=M,
        )

    def energy(self, X: np.ndarray) -> float:
        """Total stored energy at ``X``."""
        Wb, Wh = self.element_energies(X)
        return float(Wb.sum() + Wh.sum())

    def element_energies(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Stored energy of every bar ``(n_bars,)`` and every hinge ``(n_hinges,)`` at ``X``,
        with the model's own laws (per-hinge penetration limits included)."""
        X = self._check_X(X)
        eps = bar_strain(X, self.bars, self.bar_L0, self.strain)
        _, _, Wb = self.bar_law(eps)
        _, _, Wh = self._hinge_law(hinge_angle(X, self.hinges))
        return Wb, Wh

    def element_states(self, X: np.ndarray) -> ElementStates:
        """Axial force and energy of every bar, angle, moment and energy of every hinge at
        ``X``, each computed once with the model's own laws (the result files of every
        state need all of them; no internal force or tangent is assembled)."""
        X = self._check_X(X)
        eps, d = bar_strain_gradient(X, self.bars, self.bar_L0, self.strain)
        S, _, Wb = self.bar_law(eps)
        rho = hinge_angle(X, self.hinges)
        M, _, Wh = self._hinge_law(rho)
        return ElementStates(
            bar_axial_force=S * np.linalg.norm(d, axis=1),
            bar_energy=Wb,
            hinge_angle=rho,
            hinge_moment=M,
            hinge_energy=Wh,
        )

    def internal_force(self, X: np.ndarray) -> np.ndarray:
        """(n_dof,) internal force ``dE/dX``."""
        return self.evaluate(X, tangent=False).force

    def tangent(self, X: np.ndarray) -> sp.csr_matrix:
        """(n_dof, n_dof) CSR tangent stiffness ``d^2E/dX^2``."""
        K = self.evaluate(X, tangent=True).K
        assert K is not None
        return K

    def hinge_angles(self, X: np.ndarray) -> np.ndarray:
        """(n_hinges,) fold angles in radians, FOLD convention (valley > 0)."""
        return hinge_angle(self._check_X(X), self.hinges)

    def crease_fold_angles_deg(self, X: np.ndarray) -> np.ndarray:
        """(n_edges,) fold angle of every pattern edge in degrees (0 where no fold hinge)."""
        X = self._check_X(X)
        out = np.zeros(self.pattern.n_edges)
        h = self.fold_hinge_of_edge
        has = h >= 0
        out[has] = np.degrees(hinge_angle(X, self.hinges[h[has]]))
        return out

    def __repr__(self) -> str:
        nf = int(self._is_fold.sum())
        return (
            f"BarHingeModel(scheme={self.scheme}, n_nodes={self.n_nodes}, n_bars={self.n_bars}, "
            f"fold_hinges={nf}, bend_hinges={self.n_hinges - nf}, fold_law={self.fold_law})"
        )


def _check_pairs(kw: dict[str, Any], pairs: str, values: str, of: str) -> None:
    """Raise ConfigError unless ``kw[pairs]`` is (n, 2) indices into ``kw[of]`` and
    ``kw[values]`` has one value per pair."""
    P, v = kw[pairs], kw[values]
    if P.ndim != 2 or P.shape[1] != 2 or v.shape != (len(P),):
        raise ConfigError(
            f"{pairs} must have shape (n, 2) and {values} (n,), got {P.shape} and {v.shape}"
        )
    if len(P) and (P.min() < 0 or P.max() >= len(kw[of])):
        raise ConfigError(
            f"{pairs} refers to {of} the model does not have (indices 0 .. {len(kw[of]) - 1})"
        )


def _override(current: np.ndarray, value: Any, n: int, name: str) -> np.ndarray:
    v = _check.float_array(value, name)
    if v.ndim == 0:
        v = np.full(n, float(v))
    if v.shape != (n,):
        raise ConfigError(f"{name} must be a scalar or have shape ({n},), got {v.shape}")
    if (v < 0).any():
        raise ConfigError(f"{name} has the entry {v[v < 0][0]}; expected numbers >= 0")
    return v.copy()


def plate_bend_scale(
    cp: CreasePattern, scheme: Scheme, material: Material, faces: np.ndarray, refine: int = 4
) -> np.ndarray:
    """(len(faces),) factor for the ``"kirchhoff"`` bending stiffnesses of each face so that
    the panel's corner-warping stiffness equals a Kirchhoff plate's (Morley elements,
    :mod:`barhinge.model.continuum`): ``trace(S_plate) / trace(S_bar)`` of the stiffnesses
    condensed to the corner deflections (exact for quadrilaterals, which have one warping
    mode; a least-squares-like average for polygons). Faces of equal shape are computed
    once."""
    X = cp.vertices3d
    faces = np.asarray(faces, dtype=np.int64)
    out = np.ones(len(faces))
    sizes = np.array([len(cp.faces[f]) for f in faces], dtype=np.int64)
    for k in np.unique(sizes):
        sel = np.flatnonzero(sizes == k)
        F = np.array([cp.faces[f] for f in faces[sel]], dtype=np.int64)
        e1, e2, _ = face_frames(X, cp.faces, faces[sel])
        P3 = X[F] - X[F[:, :1]]
        Q = np.stack([np.einsum("nki,ni->nk", P3, e1), np.einsum("nki,ni->nk", P3, e2)], axis=2)
        scale = np.abs(Q).max(axis=(1, 2))
        key = np.round(Q.reshape(len(sel), -1) / scale[:, None], 9)
        _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
        vals = np.empty(len(first))
        for u, f in enumerate(first):
            vals[u] = _plate_bend_ratio(Q[f], scheme, material, refine, int(faces[sel][f]))
        out[sel] = vals[inv.ravel()]
    logger.debug("plate bending calibration: %d faces", len(faces))
    return out


#: namespace of the plate bending ratios in the cache kept between processes
_PLATE_BEND = "plate_bend_ratio"


def _plate_bend_ratio(
    Q: np.ndarray, scheme: Scheme, material: Material, refine: int, face: int
) -> float:
    """``trace(S_plate) / trace(S_bar)`` of the flat panel with corners ``Q`` (k, 2) (face
    number ``face`` for the error message), kept between processes
    (:mod:`barhinge._disk_cache`, keyed on the exact corners, scheme, material and mesh
    refinement), so that a second run of the same sheet does not import scikit-fem."""
    Q = np.ascontiguousarray(Q, dtype=np.float64)
    inputs = (Q, str(scheme), material.E, material.nu, material.t, int(refine))
    entry = make_key(_PLATE_BEND, *inputs, libraries=("scipy", "skfem"))
    kept = load_array(_PLATE_BEND, entry, (1,))
    if kept is not None:
        return float(kept[0])
    k = len(Q)
    panel = CreasePattern(
        Q,
        np.array([[i, (i + 1) % k] for i in range(k)]),
        np.array(["B"] * k),
        faces=[list(range(k))],
    )
    m = BarHingeModel.from_pattern(
        panel, scheme, material, bend_calibration="kirchhoff", fold_stiffness=0.0
    )
    Sb = panel_corner_stiffness(m, np.arange(k))
    Sp = plate_corner_stiffness(Q, material, refine)
    tb, tp = float(np.trace(Sb)), float(np.trace(Sp))
    if not (np.isfinite(tb) and np.isfinite(tp) and tb > 0.0 and tp > 0.0):
        raise ConfigError(
            f"bend_calibration='plate': face {face} has no finite corner-warping stiffness "
            "(degenerate panel); use bend_calibration='kirchhoff' or 'filipov'"
        )
    ratio = tp / tb
    store_array(_PLATE_BEND, entry, np.array([ratio]))
    return ratio
