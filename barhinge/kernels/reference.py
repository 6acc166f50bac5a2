"""Slow, per-element reference implementation used by the tests as an oracle.

Plain Python loops over elements, 3-vectors and 3x3 blocks only, and -- where possible -- a
different formulation from the vectorised kernels:

* hinge angle and derivatives follow Liu & Paulino (2017, Proc. R. Soc. A 473:20170348,
  rotational spring element) in *their* node labelling (wing ``p``, axis ``q -> r``, wing
  ``s``, ``m = r_pq x r_rq``, ``n = r_rq x r_rs``), with their explicit closed-form Hessian blocks
  (in :mod:`barhinge.kernels.geometry` the Hessian is derived by the chain rule on the
  gradient and assembled in a different block form);
* bar derivatives are written out per bar with both strain measures;
* assembly into dense matrices, element by element.

Never used by the library itself.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "hinge_reference",
    "bar_reference",
    "law_reference",
    "assemble_reference",
    "hinge_with_angle",
]


def hinge_with_angle(rho: float, rng: np.random.Generator, place: bool = True) -> np.ndarray:
    """(4, 3) points ``(i, j, k, l)`` of a hinge with fold angle ``rho`` (FOLD convention),
    random wing shapes, in a random position and orientation (test fixture).

    Built from the flat hinge (axis along x, k at +y, l at -y, normals +z) by rotating the
    wing l about the axis by ``-rho``: for ``rho > 0`` l comes up to the normals' side, a
    valley."""
    from scipy.spatial.transform import Rotation

    xk = np.array([rng.uniform(0.2, 0.8), rng.uniform(0.5, 1.5), 0.0])
    xl = np.array([rng.uniform(0.2, 0.8), -rng.uniform(0.5, 1.5), 0.0])
    X = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], xk, xl])
    X[3] = Rotation.from_rotvec([-rho, 0.0, 0.0]).apply(X[3])
    if place:
        R = Rotation.random(random_state=int(rng.integers(1 << 31)))
        X = R.apply(X) + rng.normal(size=3)
    return X


def _outer(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.outer(a, b)


def hinge_reference(xi, xj, xk, xl) -> tuple[float, np.ndarray, np.ndarray]:
    """Fold angle (FOLD convention), gradient (12,) and Hessian (12, 12) of one hinge with
    axis ``i -> j`` and wings ``k`` (left), ``l`` (right), by Liu & Paulino's formulas.

    Liu & Paulino's dihedral ``theta`` is measured with wing ``p = k``, axis ``q = j``,
    ``r = i`` and wing ``s = l``, so that ``m`` and ``n`` are the outward normals of the two
    triangles; in this labelling the FOLD angle is ``rho = theta - pi`` wrapped to
    ``(-pi, pi]``.
    """
    xp, xq, xr, xs = (np.asarray(v, dtype=float) for v in (xk, xj, xi, xl))
    r_pq = xp - xq
    r_rq = xr - xq
    r_rs = xr - xs
    m = np.cross(r_pq, r_rq)
    n = np.cross(r_rq, r_rs)
    lrq = math.sqrt(r_rq @ r_rq)
    mm = m @ m
    nn = n @ n
    # angle between m and n, signed by eta = sign(m . r_rs); atan2 for accuracy
    cosang = float(m @ n)
    sinang = float(np.linalg.norm(np.cross(m, n)))
    eta = 1.0 if m @ r_rs >= 0 else -1.0
    theta = eta * math.atan2(sinang, cosang)  # in (-pi, pi]: their theta mod 2 pi, shifted
    theta = theta % (2.0 * math.pi)
    rho = theta - math.pi
    if rho <= -math.pi:
        rho += 2.0 * math.pi

    # gradient (Liu & Paulino 2017)
    dp = lrq / mm * m
    ds = -lrq / nn * n
    A = (r_pq @ r_rq) / (lrq * lrq)
    B = (r_rs @ r_rq) / (lrq * lrq)
    dq = (A - 1.0) * dp - B * ds
    dr = (B - 1.0) * ds - A * dp

    # Hessian blocks (Liu & Paulino 2017); H_ab = d2 theta / dx_a dx_b
    def sym(v, w):
        return _outer(v, w) + _outer(w, v)

    Hpp = -lrq / mm**2 * sym(m, np.cross(r_rq, m))
    Hss = lrq / nn**2 * sym(n, np.cross(r_rq, n))
    Hpr = _outer(m, r_rq) / (mm * lrq) + lrq / mm**2 * sym(m, np.cross(r_pq, m))
    Hsq = _outer(n, r_rq) / (nn * lrq) - lrq / nn**2 * sym(n, np.cross(r_rs, n))
    Hpq = -_outer(m, r_rq) / (mm * lrq) + lrq / mm**2 * sym(m, np.cross(r_rq - r_pq, m))
    Hsr = -_outer(n, r_rq) / (nn * lrq) - lrq / nn**2 * sym(n, np.cross(r_rq - r_rs, n))
    Hps = np.zeros((3, 3))
    dA_q = ((2.0 * A - 1.0) * r_rq - r_pq) / lrq**2
    dB_q = (2.0 * B * r_rq - r_rs) / lrq**2
    dA_r = (r_pq - 2.0 * A * r_rq) / lrq**2
    dB_r = ((1.0 - 2.0 * B) * r_rq + r_rs) / lrq**2
    Hqq = _outer(dp, dA_q) + (A - 1.0) * Hpq - _outer(ds, dB_q) - B * Hsq
    Hqr = _outer(dp, dA_r) + (A - 1.0) * Hpr - _outer(ds, dB_r) - B * Hsr
    Hrr = _outer(ds, dB_r) + (B - 1.0) * Hsr - _outer(dp, dA_r) - A * Hpr

    # the blocks above are d(grad_a)/dx_b for the "row" node a; make the full matrix in the
    # (p, q, r, s) order and symmetrise the cross blocks from their transposes
    blocks = {
        ("p", "p"): Hpp, ("s", "s"): Hss, ("p", "r"): Hpr, ("s", "q"): Hsq,
        ("p", "q"): Hpq, ("s", "r"): Hsr, ("p", "s"): Hps, ("q", "q"): Hqq,
        ("q", "r"): Hqr, ("r", "r"): Hrr,
    }  # fmt: skip
    names = ["p", "q", "r", "s"]
    H4 = np.zeros((12, 12))
    for a_, na in enumerate(names):
        for b_, nb in enumerate(names):
            if (na, nb) in blocks:
                blk = blocks[(na, nb)]
            else:
                blk = blocks[(nb, na)].T
            H4[3 * a_ : 3 * a_ + 3, 3 * b_ : 3 * b_ + 3] = blk
    g4 = np.concatenate([dp, dq, dr, ds])
    # reorder (p, q, r, s) = (k, j, i, l) -> (i, j, k, l)
    perm = [2, 1, 0, 3]
    idx = np.concatenate([np.arange(3 * p, 3 * p + 3) for p in perm])
    g = g4[idx]
    H = H4[np.ix_(idx, idx)]
    return rho, g, 0.5 * (H + H.T)


def bar_reference(
    xa, xb, L0: float, measure: str = "green"
) -> tuple[float, np.ndarray, np.ndarray]:
    """Strain, gradient (6,) and Hessian (6, 6) of one bar w.r.t. ``(x_a, x_b)``."""
    xa, xb = np.asarray(xa, float), np.asarray(xb, float)
    d = xb - xa
    L = math.sqrt(d @ d)
    if measure == "green":
        eps = (L * L - L0 * L0) / (2.0 * L0 * L0)
        de = d / (L0 * L0)
        Hb = np.eye(3) / (L0 * L0)
    else:
        eps = L / L0 - 1.0
        de = d / (L * L0)
        Hb = (np.eye(3) / L - np.outer(d, d) / L**3) / L0
    g = np.concatenate([-de, de])
    H = np.block([[Hb, -Hb], [-Hb, Hb]])
    return eps, g, H


def law_reference(kind: str, x: float, x0: float, k: float, lo=-0.75 * math.pi, hi=0.75 * math.pi):
    """Scalar constitutive law: ``kind`` is ``"bar"`` (x = strain, k = EA*L0, x0 unused),
    ``"linear"`` or ``"penetration"`` (x = rho). Returns ``(force, tangent, energy)``."""
    if kind == "bar":
        return k * x, k, 0.5 * k * x * x
    d = x - x0
    if kind == "linear" or lo <= x <= hi:
        return k * d, k, 0.5 * k * d * d
    lim = hi if x > hi else lo
    c = 2.0 * (math.pi - abs(lim)) / math.pi
    psi = (x - lim) / c
    Mlim = k * (lim - x0)
    Wlim = 0.5 * k * (lim - x0) ** 2
    return (
        Mlim + k * c * math.tan(psi),
        k / math.cos(psi) ** 2,
        Wlim + Mlim * (x - lim) - k * c * c * math.log(math.cos(psi)),
    )


def assemble_reference(model, X: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Energy, force (n_dof,) and dense tangent (n_dof, n_dof) of a BarHingeModel, element by
    element."""
    X = np.asarray(X, float).reshape(-1, 3)
    n = model.n_dof
    E = 0.0
    f = np.zeros(n)
    K = np.zeros((n, n))
    for b, (a_, b_) in enumerate(model.bars):
        eps, g, H = bar_reference(X[a_], X[b_], model.bar_L0[b], model.strain)
        S, dS, W = law_reference("bar", eps, 0.0, model.bar_EA[b] * model.bar_L0[b])
        dofs = np.r_[3 * a_ : 3 * a_ + 3, 3 * b_ : 3 * b_ + 3]
        E += W
        f[dofs] += S * g
        K[np.ix_(dofs, dofs)] += dS * np.outer(g, g) + S * H
    # the CST membrane's couplings c eps_i eps_j (barhinge.model.membrane), pair by pair
    for (bi, bj), c in zip(model.bar_pairs, model.bar_pair_c, strict=True):
        ends = [model.bars[bi], model.bars[bj]]
        parts = [
            bar_reference(X[a_], X[b_], model.bar_L0[b], model.strain)
            for b, (a_, b_) in zip((bi, bj), ends, strict=True)
        ]
        dofs = [np.r_[3 * a_ : 3 * a_ + 3, 3 * b_ : 3 * b_ + 3] for a_, b_ in ends]
        (ei, gi, Hi), (ej, gj, Hj) = parts
        E += c * ei * ej
        f[dofs[0]] += c * ej * gi
        f[dofs[1]] += c * ei * gj
        K[np.ix_(dofs[0], dofs[1])] += c * np.outer(gi, gj)
        K[np.ix_(dofs[1], dofs[0])] += c * np.outer(gj, gi)
        K[np.ix_(dofs[0], dofs[0])] += c * ej * Hi
        K[np.ix_(dofs[1], dofs[1])] += c * ei * Hj
    lo0, hi0 = model.fold_limits
    for h, (i, j, k, l) in enumerate(model.hinges):
        # limits widened to the rest angle (see BarHingeModel.fold_limits_per_hinge)
        lo = min(lo0, model.rest_angle[h])
        hi = max(hi0, model.rest_angle[h])
        rho, g, H = hinge_reference(X[i], X[j], X[k], X[l])
        kind = (
            "penetration"
            if (model.fold_law == "penetration" and model.hinge_kind[h] == "fold")
            else "linear"
        )
        M, Kt, W = law_reference(kind, rho, model.rest_angle[h], model.hinge_k[h], lo, hi)
        dofs = np.concatenate([np.arange(3 * v, 3 * v + 3) for v in (i, j, k, l)])
        E += W
        f[dofs] += M * g
        K[np.ix_(dofs, dofs)] += Kt * np.outer(g, g) + M * H
    return E, f, K
