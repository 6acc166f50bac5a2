"""Hinge-angle couplings (barhinge.model.hinge_pairs): energy, force and tangent.

References: central finite differences of the energy (force) and of the force (tangent), and
the energy's closed form ``c (rho_i - rho_i0) (rho_j - rho_j0)`` evaluated from the hinge
angles directly.
"""

from __future__ import annotations

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import ConfigError
from barhinge.kernels.geometry import hinge_angle
from barhinge.model.model import BarHingeModel


def _model_with_pairs(n_pairs: int = 40, seed: int = 0):
    cp = bh.families.miura(2, 2, fold=30.0)
    m = BarHingeModel.from_pattern(cp, "N5B8", bh.Material(E=1e3, nu=0.3, t=0.05))
    rng = np.random.default_rng(seed)
    h = np.asarray(m.hinges)
    cand = np.array(
        [
            (i, j)
            for i in range(m.n_hinges)
            for j in range(i + 1, m.n_hinges)
            if len(set(h[i]) & set(h[j])) >= 1
        ]
    )
    pairs = cand[rng.choice(len(cand), n_pairs, replace=False)]
    c = rng.uniform(-0.5, 0.5, n_pairs)
    X = np.asarray(m.X0) + 0.03 * rng.standard_normal(m.X0.shape)
    return m, m.with_(hinge_pairs=pairs, pair_k=c), X


def test_energy_is_the_closed_form():
    m, mp, X = _model_with_pairs()
    d = hinge_angle(X, m.hinges) - m.rest_angle
    i, j = mp.hinge_pairs.T
    expected = m.energy(X) + float(np.sum(mp.pair_k * d[i] * d[j]))
    assert mp.energy(X) == pytest.approx(expected, rel=1e-12)
    ev = mp.evaluate(X)
    assert ev.energy == pytest.approx(expected, rel=1e-12)


def test_force_and_tangent_against_finite_differences():
    _, mp, X = _model_with_pairs()
    ev = mp.evaluate(X)
    x, h = X.ravel(), 1e-6
    eye = np.eye(len(x))
    f_fd = np.array(
        [(mp.energy((x + h * e).reshape(-1, 3)) - mp.energy((x - h * e).reshape(-1, 3))) / (2 * h)
         for e in eye]
    )  # fmt: skip
    np.testing.assert_allclose(ev.force, f_fd, atol=1e-8 * np.abs(ev.force).max())
    K_fd = np.array(
        [(mp.evaluate((x + h * e).reshape(-1, 3), tangent=False).force
          - mp.evaluate((x - h * e).reshape(-1, 3), tangent=False).force) / (2 * h)
         for e in eye]
    )  # fmt: skip
    K = ev.K.toarray()
    np.testing.assert_allclose(K, K_fd, atol=1e-7 * np.abs(K).max())
    assert np.array_equal(K, K.T)


def test_without_pairs_the_model_is_unchanged():
    m, _, X = _model_with_pairs()
    empty = m.with_(hinge_pairs=np.zeros((0, 2), int), pair_k=np.zeros(0))
    a, b = m.evaluate(X), empty.evaluate(X)
    assert np.array_equal(a.force, b.force)
    assert np.array_equal(a.K.toarray(), b.K.toarray())


def test_moments_include_the_couplings_and_stiffened_scales_bend_pairs():
    m, mp, X = _model_with_pairs()
    d = hinge_angle(X, m.hinges) - m.rest_angle
    extra = np.zeros(m.n_hinges)
    i, j = mp.hinge_pairs.T
    np.add.at(extra, i, mp.pair_k * d[j])
    np.add.at(extra, j, mp.pair_k * d[i])
    np.testing.assert_allclose(mp.evaluate(X).hinge_moment - m.evaluate(X).hinge_moment, extra,
                               atol=1e-12)  # fmt: skip
    s = mp.stiffened(10.0)
    both_bend = (np.asarray(m.hinge_kind)[mp.hinge_pairs] == "bend").all(axis=1)
    np.testing.assert_allclose(s.pair_k, np.where(both_bend, 10.0, 1.0) * mp.pair_k)


def test_bad_pairs_are_one_line_errors():
    m, mp, _ = _model_with_pairs()
    with pytest.raises(ConfigError, match="shape"):
        m.with_(hinge_pairs=np.zeros((3, 2), int), pair_k=np.zeros(2))
    with pytest.raises(ConfigError, match="does not have"):
        m.with_(hinge_pairs=np.array([[0, m.n_hinges]]), pair_k=np.ones(1))
    with pytest.raises(ConfigError, match="itself"):
        m.with_(hinge_pairs=np.array([[1, 1]]), pair_k=np.ones(1)).evaluate(m.X0)


def test_stiffness_parts_sum_to_the_tangent_with_couplings():
    from barhinge.analysis.buckling import stiffness_parts

    _, mp, X = _model_with_pairs()
    Km, Kg = stiffness_parts(mp, X)
    K = mp.evaluate(X).K
    assert abs(Km + Kg - K).max() <= 1e-12 * abs(K).max()
