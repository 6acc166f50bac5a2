"""Constitutive laws of bars and hinges, vectorised. Each returns (force, tangent, energy)
together, all of shape (n,).

Bars work in terms of the strain ``eps`` (see :mod:`barhinge.kernels.geometry`): the law
returns ``dW/deps``, ``d^2W/deps^2`` and ``W`` for the whole bar (volume ``A L0`` included).
Hinges work in terms of the fold angle ``rho`` (radians, FOLD convention): the law returns the
moment ``M = dW/drho``, the rotational tangent ``dM/drho`` and ``W``; the stiffness ``k`` is
the total rotational stiffness of the hinge (moment per radian, crease length included).
"""

from __future__ import annotations

import numpy as np

__all__ = ["bar_linear", "hinge_linear", "hinge_penetration"]


def bar_linear(
    eps: np.ndarray, EA: np.ndarray, L0: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Linear bar ``W = EA L0 eps^2 / 2`` (St Venant-Kirchhoff with Green strain).

    Returns ``(dW/deps = EA L0 eps, d^2W/deps^2 = EA L0, W)``; the axial force is
    ``EA eps`` (second Piola-Kirchhoff times area for the Green strain).
    """
    c = EA * L0
    return c * eps, c * np.ones_like(eps), 0.5 * c * eps * eps


def hinge_linear(
    rho: np.ndarray, rho0: np.ndarray, k: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Linear rotational spring ``M = k (rho - rho0)``; returns ``(M, k, k (rho-rho0)^2/2)``."""
    d = rho - rho0
    return k * d, k * np.ones_like(d), 0.5 * k * d * d


def hinge_penetration(
    rho: np.ndarray,
    rho0: np.ndarray,
    k: np.ndarray,
    rho_min: float | np.ndarray = -0.75 * np.pi,
    rho_max: float | np.ndarray = 0.75 * np.pi,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Penetration-preventing fold law of Liu & Paulino (2017, Proc. R. Soc. A 473:20170348,
    rotational spring law), written in the fold angle ``rho = pi - theta``.

    Linear ``M = k (rho - rho0)`` for ``rho_min <= rho <= rho_max``; beyond the limits the
    moment follows a tangent branch that is C1-continuous at the limit and tends to infinity
    as ``rho -> +-pi`` (the faces would interpenetrate)::

        rho > rho_max:  M = k (rho_max - rho0) + k c tan((rho - rho_max) / c),
                        c = 2 (pi - rho_max) / pi
        rho < rho_min:  M = k (rho_min - rho0) + k c tan((rho - rho_min) / c),
                        c = 2 (pi + rho_min) / pi

    (Liu & Paulino's limits ``theta_1 = 45 deg``, ``theta_2 = 315 deg`` are
    ``rho_max = 135 deg``, ``rho_min = -135 deg``, the defaults here.) The energy is the
    integral of ``M``: ``W = W(limit) + k (lim - rho0)(rho - lim) - k c^2 ln cos((rho-lim)/c)``.

    Returns ``(M, dM/drho, W)``.
    """
    rho = np.asarray(rho, dtype=float)
    rho0 = np.broadcast_to(np.asarray(rho0, dtype=float), rho.shape)
    k = np.broadcast_to(np.asarray(k, dtype=float), rho.shape)
    lo = np.broadcast_to(np.asarray(rho_min, dtype=float), rho.shape)
    hi = np.broadcast_to(np.asarray(rho_max, dtype=float), rho.shape)
    M, K, W = hinge_linear(rho, rho0, k)
    for lim, mask, c in (
        (hi, rho > hi, 2.0 * (np.pi - hi) / np.pi),
        (lo, rho < lo, 2.0 * (np.pi + lo) / np.pi),
    ):
        if not mask.any():
            continue
        r, r0, kk, L, cc = rho[mask], rho0[mask], k[mask], lim[mask], c[mask]
        psi = (r - L) / cc
        tn = np.tan(psi)
        M[mask] = kk * (L - r0) + kk * cc * tn
        K[mask] = kk * (1.0 + tn * tn)
        W[mask] = (
            0.5 * kk * (L - r0) ** 2 + kk * (L - r0) * (r - L) - kk * cc * cc * np.log(np.cos(psi))
        )
    return M, K, W
