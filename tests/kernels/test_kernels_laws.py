"""Constitutive laws: force = dW, tangent = d2W (central differences), C1 continuity of the
Liu & Paulino (2017) penetration law, oracle agreement, and the hinge energy as a function of
the coordinates (gradient and Hessian by finite differences, near flat and near folded)."""

from __future__ import annotations

import numpy as np
import pytest

from barhinge.kernels.geometry import TRIU12, hinge_angle, hinge_energy_hessian_packed
from barhinge.kernels.laws import bar_linear, hinge_linear, hinge_penetration
from barhinge.kernels.reference import hinge_with_angle, law_reference

LO, HI = np.radians(-135.0), np.radians(135.0)


def _laws():
    rng = np.random.default_rng(0)
    x = np.concatenate([rng.uniform(-3.1, 3.1, 40), [LO - 0.3, HI + 0.3, 3.0, -3.0, 1e-7]])
    x0 = rng.uniform(-1.0, 1.0, len(x))
    k = rng.uniform(0.5, 2.0, len(x))
    return (
        {
            "bar": (x * 0.05, lambda e: bar_linear(e, k, 0.7 + 0 * k)),
            "linear": (x, lambda r: hinge_linear(r, x0, k)),
            "penetration": (x, lambda r: hinge_penetration(r, x0, k, LO, HI)),
        },
        x0,
        k,
    )


@pytest.mark.parametrize("name", ["bar", "linear", "penetration"])
def test_law_force_and_tangent_are_derivatives_of_energy(name: str) -> None:
    laws, _, _ = _laws()
    x, law = laws[name]
    h = 1e-6
    F, K, _ = law(x)
    _, _, Wp = law(x + h)
    _, _, Wm = law(x - h)
    Fp, _, _ = law(x + h)
    Fm, _, _ = law(x - h)
    assert np.allclose((Wp - Wm) / (2 * h), F, rtol=1e-6, atol=1e-9)
    assert np.allclose((Fp - Fm) / (2 * h), K, rtol=1e-6, atol=1e-9)


def test_laws_equal_scalar_oracle() -> None:
    laws, x0, k = _laws()
    x, law = laws["penetration"]
    F, K, W = law(x)
    for e in range(len(x)):
        ref = law_reference("penetration", x[e], x0[e], k[e], LO, HI)
        assert np.allclose([F[e], K[e], W[e]], ref, rtol=1e-12, atol=1e-14)
    x, law = laws["linear"]
    F, K, W = law(x)
    for e in range(len(x)):
        assert np.allclose([F[e], K[e], W[e]], law_reference("linear", x[e], x0[e], k[e]))


def test_penetration_law_is_c1_linear_inside_and_blows_up_at_pi() -> None:
    """Liu & Paulino (2017) penetration law: linear between the limits, moment and tangent
    continuous at the limits, moment -> +-infinity as rho -> +-pi."""
    k, r0 = 2.0, 0.2
    d = 1e-9
    for lim in (LO, HI):
        below = hinge_penetration(np.array([lim - d]), r0, k, LO, HI)
        above = hinge_penetration(np.array([lim + d]), r0, k, LO, HI)
        for a, b in zip(below, above, strict=True):
            assert a[0] == pytest.approx(b[0], abs=1e-7)
    inside = np.linspace(LO, HI, 11)
    M, K, W = hinge_penetration(inside, r0, k, LO, HI)
    assert np.allclose(M, k * (inside - r0)) and np.allclose(K, k)
    near = np.array([np.pi - 1e-6, -np.pi + 1e-6])
    M, K, _ = hinge_penetration(near, r0, k, LO, HI)
    assert M[0] > 1e5 * k and M[1] < -1e5 * k and (K > 1e11 * k).all()


@pytest.mark.parametrize("law_name", ["linear", "penetration"])
@pytest.mark.parametrize("rho_deg", [1e-5, -3e-5, 40.0, 150.0, -160.0, 179.2, -179.5])
def test_hinge_energy_gradient_hessian_match_fd(law_name: str, rho_deg: float) -> None:
    """E(X) = W(rho(X)): the packed energy Hessian M d2rho + K grad grad^T and the force
    M grad against central differences of the energy (relative error <= 1e-6), including
    near-flat (|rho| < 1e-6 rad) and near-folded (|rho| > 179 deg) hinges."""
    rng = np.random.default_rng(int(abs(rho_deg) * 1000) % 2**31)
    X = hinge_with_angle(np.radians(rho_deg), rng)
    H4 = np.array([[0, 1, 2, 3]])
    r0 = np.array([np.radians(rho_deg) * 0.5 + 0.05])

    def law(r, sl=slice(None)):
        if law_name == "linear":
            return hinge_linear(r, r0, np.array([1.3]))
        return hinge_penetration(r, r0, np.array([1.3]), LO, HI)

    def energy(Y):
        return law(hinge_angle(Y, H4))[2][0]

    rho, M, Kt, W, g, Hp = hinge_energy_hessian_packed(X, H4, law)
    f = M[0] * g[:, 0]
    H = np.zeros((12, 12))
    H[TRIU12] = Hp[:, 0]
    H = H + np.triu(H, 1).T
    h = 1e-5
    fd_f = np.zeros(12)
    fd_H = np.zeros((12, 12))
    for c in range(12):
        Xp, Xm = X.copy(), X.copy()
        Xp[c // 3, c % 3] += h
        Xm[c // 3, c % 3] -= h
        fd_f[c] = (energy(Xp) - energy(Xm)) / (2 * h)
        rp, Mp, *_, gp, _ = hinge_energy_hessian_packed(Xp, H4, law)
        rm, Mm, *_, gm, _ = hinge_energy_hessian_packed(Xm, H4, law)
        fd_H[c] = (Mp[0] * gp[:, 0] - Mm[0] * gm[:, 0]) / (2 * h)
    scale_f = np.abs(f).max()
    scale_H = np.abs(H).max()
    assert np.abs(fd_f - f).max() <= 1e-6 * scale_f
    assert np.abs(fd_H - H).max() <= 1e-6 * scale_H
