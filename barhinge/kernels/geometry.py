"""Vectorised element geometry: bar lengths and strains, hinge fold angles, with exact
first and second derivatives.

Conventions
-----------
* ``X`` : (n_nodes, 3) float coordinates.
* ``bars`` : (n_bars, 2) int node pairs ``(a, b)``.
* ``hinges`` : (n_hinges, 4) int ``(i, j, k, l)``: axis ``i -> j``, wing ``k`` on the left of
  the axis and wing ``l`` on the right (seen from the side the face normals point to).
  The left face is ``(i, j, k)`` and the right face ``(j, i, l)``, both counter-clockwise;
  their normals are ``n_L = a x u`` and ``n_R = w x a`` with ``a = x_j - x_i``,
  ``u = x_k - x_i``, ``w = x_l - x_i``.
* Fold angle ``rho`` in radians, FOLD convention: 0 flat, valley > 0 (the wings rotate
  towards the side their normals point to), mountain < 0, ``rho in (-pi, pi]``. It is the
  signed angle from ``n_L`` to ``n_R`` about the axis, computed as
  ``atan2(((n_R x n_L) . a) / |a|, n_L . n_R)``, which is accurate at every angle
  (no ``arccos``), in particular near flat and near fully folded. This is the same definition
  as :meth:`barhinge.pattern.crease.CreasePattern.state_fold_angles`.

Derivatives
-----------
The gradient is the classical one for a dihedral angle (Bridson et al. 2003; Liu & Paulino
2017, Proc. R. Soc. A 473:20170348; Filipov et al. 2017, IJSS 124:26-45), written
in this module's node order::

    d rho / d x_k =  |a| n_L / |n_L|^2
    d rho / d x_l =  |a| n_R / |n_R|^2
    d rho / d x_i = -(1 - t_k) g_k - (1 - t_l) g_l
    d rho / d x_j = -t_k g_k - t_l g_l,   t_k = (u . a) / |a|^2,  t_l = (w . a) / |a|^2

The Hessian is obtained here by exact differentiation of these expressions (chain rule on
``n_L``, ``n_R``, ``|a|``, ``t_k``, ``t_l``); :mod:`barhinge.kernels.reference` implements
Liu & Paulino's closed-form Hessian blocks independently, and the tests compare the
two and both against finite differences.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from barhinge._typing import StrainMeasure
from barhinge.linalg.threads import parallel_map

__all__ = [
    "bar_lengths",
    "bar_strain",
    "bar_strain_derivatives",
    "bar_strain_gradient",
    "bar_strain_hessian",
    "element_passes",
    "hinge_angle",
    "hinge_angle_gradient",
    "hinge_angle_gradient_t",
    "hinge_angle_derivatives",
    "hinge_angle_hessian_packed",
    "hinge_energy_hessian_packed",
]

#: hinges per pass of the Hessian kernel (:func:`hinge_energy_hessian_packed`) and of the
#: force-only gradient kernel (:func:`hinge_angle_gradient_t`): each pass's working vectors
#: stay in cache, and the passes run side by side on the worker threads. The passes are
#: the same whatever the number of threads, so are the results to the last bit.
HESSIAN_CHUNK = 8192
GRADIENT_CHUNK = 16384
#: bars per pass of the assembly's bar kernel (:mod:`barhinge.model.model`)
BAR_CHUNK = 16384


# ---------------------------------------------------------------------------------- bars
def bar_lengths(X: np.ndarray, bars: np.ndarray) -> np.ndarray:
    """(n_bars,) current lengths ``|x_b - x_a|``."""
    d = X[bars[:, 1]] - X[bars[:, 0]]
    return np.sqrt(np.einsum("ni,ni->n", d, d))


def bar_strain(
    X: np.ndarray, bars: np.ndarray, L0: np.ndarray, measure: StrainMeasure = "green"
) -> np.ndarray:
    """(n_bars,) axial strain: Green-Lagrange ``(L^2 - L0^2) / (2 L0^2)`` or engineering
    ``(L - L0) / L0``."""
    d = X[bars[:, 1]] - X[bars[:, 0]]
    LL = np.einsum("ni,ni->n", d, d)
    if measure == "green":
        return 0.5 * (LL - L0 * L0) / (L0 * L0)
    return (np.sqrt(LL) - L0) / L0


def bar_strain_gradient(
    X: np.ndarray, bars: np.ndarray, L0: np.ndarray, measure: StrainMeasure = "green"
) -> tuple[np.ndarray, np.ndarray]:
    """Strain of every bar and its derivative: ``(eps (n_bars,), d (n_bars, 3))`` with
    ``d = d eps / d x_b`` (``d eps / d x_a = -d``); see :func:`bar_strain_derivatives`."""
    dx = X[bars[:, 1]] - X[bars[:, 0]]
    LL = np.einsum("ni,ni->n", dx, dx)
    if measure == "green":
        inv = 1.0 / (L0 * L0)
        return 0.5 * (LL * inv - 1.0), dx * inv[:, None]
    L = np.sqrt(LL)
    return L / L0 - 1.0, dx / (L * L0)[:, None]


def bar_strain_hessian(
    d: np.ndarray, eps: np.ndarray, L0: np.ndarray, measure: StrainMeasure = "green"
) -> np.ndarray:
    """(n, 3, 3) ``d^2 eps / d x_b^2`` of bars from their strain ``eps`` (n,) and its
    derivative ``d`` (n, 3) (:func:`bar_strain_gradient`): the assembly computes it for one
    chunk of bars at a time."""
    eye = np.broadcast_to(np.eye(3), (len(d), 3, 3))
    if measure == "green":
        return eye / (L0 * L0)[:, None, None]
    e = d * L0[:, None]  # the unit bar direction
    L = (1.0 + eps) * L0
    return (eye - e[:, :, None] * e[:, None, :]) / (L * L0)[:, None, None]


def bar_strain_derivatives(
    X: np.ndarray, bars: np.ndarray, L0: np.ndarray, measure: StrainMeasure = "green"
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Strain of every bar with its exact derivatives.

    Returns
    -------
    eps : (n_bars,) strain.
    d : (n_bars, 3) ``d eps / d x_b`` (``d eps / d x_a = -d``).
    B : (n_bars, 3, 3) ``d^2 eps / d x_b^2``; the full 6x6 Hessian w.r.t. ``(x_a, x_b)`` is
        ``[[B, -B], [-B, B]]``.

    Green-Lagrange: ``d = (x_b - x_a) / L0^2``, ``B = I / L0^2``. Engineering:
    ``d = e / L0`` (``e`` the unit bar direction), ``B = (I - e e^T) / (L L0)``.
    """
    eps, d = bar_strain_gradient(X, bars, L0, measure)
    return eps, d, bar_strain_hessian(d, eps, L0, measure)


# -------------------------------------------------------------------------------- hinges
def _hinge_vectors(X: np.ndarray, hinges: np.ndarray):
    xi, xj, xk, xl = (X[hinges[:, c]] for c in range(4))
    a = xj - xi
    u = xk - xi
    w = xl - xi
    nL = np.cross(a, u)
    nR = np.cross(w, a)
    return a, u, w, nL, nR


def _angle(a: np.ndarray, nL: np.ndarray, nR: np.ndarray) -> np.ndarray:
    la = np.sqrt(np.einsum("ni,ni->n", a, a))
    s = np.einsum("ni,ni->n", np.cross(nR, nL), a) / la
    c = np.einsum("ni,ni->n", nL, nR)
    return np.arctan2(s, c)


def hinge_angle(X: np.ndarray, hinges: np.ndarray) -> np.ndarray:
    """(n_hinges,) fold angle ``rho`` in radians, FOLD convention (valley > 0), in
    ``(-pi, pi]``."""
    a, _, _, nL, nR = _hinge_vectors(X, hinges)
    return _angle(a, nL, nR)


def hinge_angle_gradient(X: np.ndarray, hinges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(rho (nh,), grad (nh, 12))``; grad w.r.t. ``(x_i, x_j, x_k, x_l)`` xyz-interleaved."""
    a, u, w, nL, nR = _hinge_vectors(X, hinges)
    rho = _angle(a, nL, nR)
    gi, gj, gk, gl, *_ = _gradient_parts(a, u, w, nL, nR)
    return rho, np.concatenate([gi, gj, gk, gl], axis=1)


def _gradient_parts(a, u, w, nL, nR):
    aa = np.einsum("ni,ni->n", a, a)
    la = np.sqrt(aa)
    mL = np.einsum("ni,ni->n", nL, nL)
    mR = np.einsum("ni,ni->n", nR, nR)
    fL = nL / mL[:, None]  # n_L / |n_L|^2
    fR = nR / mR[:, None]
    gk = la[:, None] * fL
    gl = la[:, None] * fR
    tk = np.einsum("ni,ni->n", u, a) / aa
    tl = np.einsum("ni,ni->n", w, a) / aa
    gi = -(1.0 - tk)[:, None] * gk - (1.0 - tl)[:, None] * gl
    gj = -tk[:, None] * gk - tl[:, None] * gl
    return gi, gj, gk, gl, aa, la, mL, mR, fL, fR, tk, tl


def _cross_t(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Cross product of component-major (3, n) arrays."""
    return np.stack(
        [p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]]
    )


# packed upper triangle of a 12x12 matrix from its 3x3 node blocks (bi <= bj):
# for each of the 10 upper blocks, the packed positions and the entries (row-major in 3x3)
TRIU12 = np.triu_indices(12)
_BLOCKS = [(0, 0), (0, 1), (0, 2), (0, 3), (1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3)]
_PACK: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}
for _bi, _bj in _BLOCKS:
    _sel = np.flatnonzero((TRIU12[0] // 3 == _bi) & (TRIU12[1] // 3 == _bj))
    _PACK[(_bi, _bj)] = (_sel, (TRIU12[0][_sel] % 3) * 3 + TRIU12[1][_sel] % 3)


def _hinge_grad_t(XT: np.ndarray, hinges: np.ndarray):
    """Component-major ``rho (nh,)``, ``grad (12, nh)`` and the intermediate quantities the
    Hessian needs, from the coordinates ``XT`` (3, n_nodes)."""
    xi, xj, xk, xl = (XT[:, hinges[:, c]] for c in range(4))
    a = xj - xi
    u = xk - xi
    w = xl - xi
    nL = _cross_t(a, u)
    nR = _cross_t(w, a)
    aa = (a * a).sum(0)
    la = np.sqrt(aa)
    rho = np.arctan2((_cross_t(nR, nL) * a).sum(0) / la, (nL * nR).sum(0))
    mL = (nL * nL).sum(0)
    mR = (nR * nR).sum(0)
    fL = nL / mL
    fR = nR / mR
    tk = (u * a).sum(0) / aa
    tl = (w * a).sum(0) / aa
    lam = (-(1.0 - tk) * la, -tk * la, la, None)  # grad block b = lam_b f_L + mu_b f_R
    mu = (-(1.0 - tl) * la, -tl * la, None, la)
    grad = np.empty((12, len(hinges)))
    for b in range(4):
        g = grad[3 * b : 3 * b + 3]
        if lam[b] is not None:
            np.multiply(lam[b], fL, out=g)
            if mu[b] is not None:
                g += mu[b] * fR
        else:
            np.multiply(mu[b], fR, out=g)
    return rho, grad, (a, u, w, aa, la, mL, mR, fL, fR, tk, tl, lam, mu)


def hinge_angle_gradient_t(
    X: np.ndarray, hinges: np.ndarray, chunk: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Component-major ``(rho (nh,), grad (12, nh))`` (the force-only fast path), in passes
    of ``chunk`` hinges (``GRADIENT_CHUNK`` by default)."""
    chunk = GRADIENT_CHUNK if chunk is None else chunk
    XT = np.ascontiguousarray(X.T)
    nh = len(hinges)
    rho, grad = np.empty(nh), np.empty((12, nh))

    def one(sl: slice) -> None:
        rho[sl], grad[:, sl], _ = _hinge_grad_t(XT, hinges[sl])

    parallel_map(one, element_passes(nh, chunk))
    return rho, grad


def element_passes(n: int, chunk: int) -> list[slice]:
    """The slices of ``n`` elements ``chunk`` at a time: a kernel's passes, run side by
    side on :func:`barhinge.linalg.threads.worker_threads` threads (each writes its own
    elements only, so the results do not depend on the number of threads)."""
    return [slice(s0, min(s0 + chunk, n)) for s0 in range(0, n, chunk)]


def _hinge_hessian_packed_t(
    XT: np.ndarray, hinges: np.ndarray, law=None, sl: slice | None = None, out=None
):
    """Component-major fast path on the coordinates ``XT`` (3, n_nodes): ``rho (nh,)``,
    ``grad (12, nh)``, the packed upper triangle ``(78, nh)`` (``TRIU12`` order) and the law's
    ``(M, dM/drho, W)`` (None without a law). Hinges are on the last axis of every array, so
    each operation is a contiguous vector operation.

    Block form (derived from the gradient of the module docstring): with
    ``f_L = n_L/|n_L|^2``, ``s_L = |a|/|n_L|^2`` (same for R) and, per column node c,
    ``v^L_c`` the vector with ``d n_L / d x_c = [v^L_c]x`` (``u - a, -u, a, 0`` for
    ``i, j, k, l``; for ``n_R``: ``a - w, w, 0, -a``),
    ``d g_k / d x_c = f_L (x) p^L_c + s_L [v^L_c]x`` with
    ``p^L_c = d|a|/dx_c - 2 |a| f_L x v^L_c``; the rows of ``i`` and ``j`` follow from
    ``g_i = -(1 - t_k) g_k - (1 - t_l) g_l`` and ``g_j = -t_k g_k - t_l g_l``. Every 3x3 block
    is therefore ``f_L (x) alpha + f_R (x) beta + [sigma]x``. Since every gradient block is
    ``lambda_b f_L + mu_b f_R`` too, the energy Hessian ``M d2rho + K grad grad^T`` keeps that
    form (``alpha -> M alpha + K lambda_bi g_bj``, ...); it is filled row by row of the packed
    triangle (vectors of length nh that stay in cache).

    With ``law`` (``(rho, sl) -> (M, dM/drho, W)``, ``sl`` the slice of these hinges in the
    model) the result is the Hessian of the hinge energy; without it, that of ``rho``.
    """
    rho, grad, (a, u, w, aa, la, mL, mR, fL, fR, tk, tl, lam, mu) = _hinge_grad_t(XT, hinges)

    sL = la / mL
    sR = la / mR
    ahat = a / la
    ia = a / aa
    vL = (u - a, -u, a, None)
    vR = (a - w, w, None, -a)
    Dla = (-ahat, ahat, None, None)
    Dtk = ((-a - u) / aa + 2.0 * tk * ia, u / aa - 2.0 * tk * ia, ia, None)
    Dtl = ((-a - w) / aa + 2.0 * tl * ia, w / aa - 2.0 * tl * ia, None, ia)
    twola = 2.0 * la

    def p_of(f, v, c):
        if v is None:
            return None
        t = -twola * _cross_t(f, v)
        return t if Dla[c] is None else t + Dla[c]

    pL = [p_of(fL, v, c) for c, v in enumerate(vL)]
    pR = [p_of(fR, v, c) for c, v in enumerate(vR)]

    nh = len(hinges)
    if law is None:
        M = Kt = W = None
    else:
        M, Kt, W = law(rho, slice(None) if sl is None else sl)
    Hp = np.empty((78, nh)) if out is None else out
    tmp = np.empty(nh)
    skew_sign = {
        (0, 1): (2, -1.0),
        (0, 2): (1, 1.0),
        (1, 0): (2, 1.0),
        (1, 2): (0, -1.0),
        (2, 0): (1, -1.0),
        (2, 1): (0, 1.0),
    }

    def lin(*terms):
        """Sum of the products in ``terms`` ((coef, vec) pairs; None entries skipped)."""
        acc = None
        for cf, v in terms:
            if cf is None or v is None:
                continue
            t = cf * v
            acc = t if acc is None else acc + t
        return acc

    def put(bi: int, bj: int, alpha, beta, sigma) -> None:
        if law is not None:
            gb = grad[3 * bj : 3 * bj + 3]
            alpha = lin((M, alpha), (None if lam[bi] is None else Kt * lam[bi], gb))
            beta = lin((M, beta), (None if mu[bi] is None else Kt * mu[bi], gb))
            sigma = None if sigma is None else M * sigma
        pos, ent = _PACK[(bi, bj)]
        for p, e in zip(pos, ent, strict=True):
            r, c = divmod(int(e), 3)
            row = Hp[p]
            if alpha is not None:
                np.multiply(fL[r], alpha[c], out=row)
            else:
                row[...] = 0.0
            if beta is not None:
                np.multiply(fR[r], beta[c], out=tmp)
                row += tmp
            if sigma is not None and (r, c) in skew_sign:
                comp, sgn = skew_sign[(r, c)]
                if sgn > 0:
                    row += sigma[comp]
                else:
                    row -= sigma[comp]

    def sig(cL, cR, c):
        return lin((None if vL[c] is None else cL * sL, vL[c]),
                   (None if vR[c] is None else cR * sR, vR[c]))  # fmt: skip

    for c in range(4):  # row blocks of i (c >= 0) and j (c >= 1)
        aL = lin((la, Dtk[c]), (-(1.0 - tk), pL[c]))
        aR = lin((la, Dtl[c]), (-(1.0 - tl), pR[c]))
        put(0, c, aL, aR, sig(-(1.0 - tk), -(1.0 - tl), c))
        if c >= 1:
            bL = lin((-la, Dtk[c]), (-tk, pL[c]))
            bR = lin((-la, Dtl[c]), (-tl, pR[c]))
            put(1, c, bL, bR, sig(-tk, -tl, c))
    put(2, 2, pL[2], None, sL * a)
    put(2, 3, None, None, None)
    put(3, 3, None, pR[3], -sR * a)
    return rho, grad, Hp, (M, Kt, W)


def hinge_angle_derivatives(
    X: np.ndarray, hinges: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fold angle of every hinge with its exact gradient and Hessian.

    Parameters
    ----------
    X : (n_nodes, 3) float
    hinges : (nh, 4) int ``(i, j, k, l)``

    Returns
    -------
    rho : (nh,) radians, FOLD convention (valley > 0).
    grad : (nh, 12) ``d rho / d (x_i, x_j, x_k, x_l)``, xyz interleaved per node.
    hess : (nh, 12, 12) symmetric second derivative, same ordering.
    """
    rho, grad, Hp, _ = _hinge_hessian_packed_t(np.ascontiguousarray(X.T), hinges)
    iu, ju = TRIU12
    H = np.empty((len(hinges), 12, 12))
    H[:, iu, ju] = Hp.T
    H[:, ju, iu] = Hp.T
    return rho, np.ascontiguousarray(grad.T), H


def hinge_angle_hessian_packed(
    X: np.ndarray, hinges: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Like :func:`hinge_angle_derivatives` but component-major (the assembly's fast path):
    ``rho (nh,)``, ``grad (12, nh)`` and the packed upper triangle of the Hessian
    ``(78, nh)`` in ``numpy.triu_indices(12)`` order."""
    rho, grad, Hp, _ = _hinge_hessian_packed_t(np.ascontiguousarray(X.T), hinges)
    return rho, grad, Hp


def hinge_energy_hessian_packed(
    X: np.ndarray,
    hinges: np.ndarray,
    law,
    out: Any = None,
    chunk: int | None = None,
    start: int = 0,
    XT: np.ndarray | None = None,
):
    """Fast path of the assembly: hinge energy derivatives, component-major.

    Parameters
    ----------
    law : callable ``(rho, sl) -> (M, dM/drho, W)``: the law of the hinges ``sl`` (a slice
        of ``hinges``) at their angles ``rho``, each result of the slice's length
    out : optional (78, nh) float array to write the packed Hessian into, or any object
        whose ``out[p]`` is a writable ``(nh,)`` row and ``out[:, sl]`` those rows of the
        hinges ``sl`` (the assembler's :class:`~barhinge.assembly.PackedRows`)
    chunk : hinges per pass (``HESSIAN_CHUNK`` by default: keeps the working vectors in
        cache; the passes run side by side on the worker threads, and ``law`` is called
        from them)
    start : the position of ``hinges[0]`` among the model's hinges (the law's slices are
        shifted by it: ``hinges`` may be a part of the model's)
    XT : optional ``X.T`` as a C-contiguous (3, n_nodes) array (saves the copy of a caller
        that passes the hinges part by part)

    Returns
    -------
    rho (nh,), M (nh,), Kt (nh,), W (nh,), grad of rho (12, nh), packed upper triangle of the
    energy Hessian ``M d2rho/dX2 + Kt grad grad^T`` (78, nh) in ``TRIU12`` order.
    """
    nh = len(hinges)
    chunk = HESSIAN_CHUNK if chunk is None else chunk
    XT = np.ascontiguousarray(X.T) if XT is None else XT
    Hp = np.empty((78, nh)) if out is None else out
    grad = np.empty((12, nh))
    rho, M, Kt, W = (np.empty(nh) for _ in range(4))

    def one(sl: slice) -> None:
        in_model = slice(start + sl.start, start + sl.stop)
        r, g, _, (m, k, e) = _hinge_hessian_packed_t(XT, hinges[sl], law, in_model, Hp[:, sl])
        rho[sl], grad[:, sl], M[sl], Kt[sl], W[sl] = r, g, m, k, e

    parallel_map(one, element_passes(nh, chunk))
    return rho, M, Kt, W, grad, Hp
