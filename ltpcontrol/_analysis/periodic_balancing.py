"""Balanced truncation of continuous-time periodic systems.

The periodic gramians ``P(t)`` (``Ṗ = AP + PAᵀ + BBᵀ``) and ``Q(t)``
(``−Q̇ = AᵀQ + QA + CᵀC``) come from `ltpcontrol.lyap`.  At every t, with
``P = SSᵀ``, ``Q = RRᵀ`` and ``RᵀS = UΣVᵀ``, the Hankel singular values
are ``σ_j(t) = diag Σ`` (``σ_j² = λ_j(PQ)``) and the pointwise balancing
projections of order r are

    V_b = S V_r Σ_r^{-1/2},   W_b = Σ_r^{-1/2} U_rᵀ Rᵀ,   W_b V_b = I_r,

so ``Π = V_b W_b`` is the spectral projector of ``M = PQ`` onto
``σ_1², ..., σ_r²``.  When the gap ``σ_r(t) > σ_{r+1}(t)`` holds for all t,
Π(t) is as smooth as P and Q, and truncating a balanced realization keeps
the state ``x ≈ V z`` for any smooth basis ``V(t)`` of ``range Π(t)``
(another basis is a Lyapunov transformation of the reduced model).  We
take ``V = Π Y`` with a smooth periodic n x r matrix ``Y(t)`` (trigonometric
interpolant of orthonormal bases of ``range Π`` aligned from sample to
sample, with the holonomy rotated out), ``K = W_b Y``, ``W = K⁻¹ W_b``.
From ``ż = Ẇx + Wẋ`` the reduced model is

    Â = W A V − W V̇,  B̂ = W B,  Ĉ = C V,  D̂ = D,   V̇ = Π̇ Y + Π Ẏ.

``W_b Π̇`` needs only the coupling block of Π̇: with ``V_⊥`` an orthonormal
basis of ``ker W_b``, ``W_⊥ = V_⊥ᵀ(I − Π)`` and ``M_⊥ = V_⊥ᵀ M V_⊥``,

    W_b Π̇ = X W_⊥,   Σ_r² X − X M_⊥ = W_b Ṁ V_⊥,   Ṁ = ṖQ + PQ̇

(resolvent calculus; solvable exactly when the gap holds), with Ṗ and Q̇
from the Lyapunov equations themselves, so no derivative is approximated:

    Â = K⁻¹ (W_b A V_b K − X W_⊥ Y − W_b Ẏ),  B̂ = K⁻¹ W_b B,  Ĉ = C V_b K.

The reduced matrices are computed at Chebyshev points of every interval
of the step grid (`_steps`) and interpolated (barycentric formula).
"""

import warnings

import numpy as np
import scipy.linalg as la
from scipy.optimize import linear_sum_assignment

from .._core.floquet import chebyshev_nodes, piecewise_chebyshev
from .lyapunov import lyap
from .._core.periodic_matrix import PeriodicMatrix
from .._core.steps import gram_weight, step_grid

__all__ = []

_CHEB_DEG = 24
# a subspace may turn by at most this principal angle between samples of Y
_MAX_COS = np.cos(0.3)


def gramians(sys, nsteps=None):
    """Periodic controllability and observability gramians P(t), Q(t).

    Examples
    --------
    For an LTI system the gramians are the constant ones of python-control:

    >>> from ltpcontrol._analysis.periodic_balancing import gramians
    >>> G = ct.ss([[-1.0, 0.0], [1.0, -4.0]], [[1.0], [0.0]], [[0.0, 1.0]], 0)
    >>> P, Q = gramians(ltp.ltpss(G, period=1.0))
    >>> bool(np.allclose(P(0.3), ct.gram(G, 'c'))), bool(np.allclose(Q(0.3), ct.gram(G, 'o')))
    (True, True)
    """
    P = lyap(sys.A, gram_weight(sys.B), nsteps=nsteps)
    Q = lyap(sys.A, gram_weight(sys.C, True), adjoint=True, nsteps=nsteps)
    return P, Q


def sqrt_factor(X):
    """``S`` with ``X = S Sᵀ`` for symmetric positive semidefinite X (stacked).

    Examples
    --------
    >>> from ltpcontrol._analysis.periodic_balancing import sqrt_factor
    >>> X = np.array([[[4.0, 2.0], [2.0, 2.0]], [[1.0, 0.0], [0.0, 0.0]]])
    >>> S = sqrt_factor(X)
    >>> S.shape, bool(np.allclose(S @ np.swapaxes(S, 1, 2), X))
    ((2, 2, 2), True)
    """
    w, U = np.linalg.eigh(0.5 * (X + np.swapaxes(X, -1, -2)))
    return U * np.sqrt(np.clip(w, 0, None))[..., None, :]


def hankel_svd(P, Q):
    """Square-root factors and the SVD ``RᵀS = UΣVᵀ`` of stacked gramians.

    Examples
    --------
    The singular values are those of python-control for an LTI system:

    >>> from ltpcontrol._analysis.periodic_balancing import hankel_svd
    >>> G = ct.ss([[-1.0, 0.0], [1.0, -4.0]], [[1.0], [0.0]], [[0.0, 1.0]], 0)
    >>> S, R, U, hsv, Vt = hankel_svd(ct.gram(G, 'c')[None], ct.gram(G, 'o')[None])
    >>> hsv.shape, bool(np.allclose(hsv[0], ct.hankel_singular_values(G)))
    ((1, 2), True)
    """
    S, R = sqrt_factor(P), sqrt_factor(Q)
    U, hsv, Vt = np.linalg.svd(np.swapaxes(R, -1, -2) @ S)
    return S, R, U, hsv, Vt


def truncate(sys, r, nsteps=None):
    """Order-r balanced truncation (module notes).

    Returns the reduced ``(Â, B̂, Ĉ)`` and ``sup_t σ_j(t)`` of each
    discarded branch j > r (`branches`).

    Examples
    --------
    An LTI system gives python-control's balanced truncation (up to the
    state's scale), and the bound term is the discarded singular value:

    >>> from ltpcontrol._analysis.periodic_balancing import truncate
    >>> G = ct.ss([[-1.0, 0.0], [1.0, -4.0]], [[1.0], [0.0]], [[0.0, 1.0]], 0)
    >>> (Ar, Br, Cr), sup = truncate(ltp.ltpss(G, period=1.0), 1)
    >>> red = ct.balred(G, 1)
    >>> bool(np.allclose(Ar(0.2), red.A)), bool(np.allclose(Cr(0.2) @ Br(0.2), red.C @ red.B))
    (True, True)
    >>> bool(np.allclose(sup, ct.hankel_singular_values(G)[1]))
    True
    """
    n, T = sys.nstates, sys.period
    P, Q = gramians(sys, nsteps)
    grid = step_grid(sys.A, [sys.B, sys.C], nsteps)
    nodes = (grid[:-1, None] + np.diff(grid)[:, None] * chebyshev_nodes(_CHEB_DEG)).ravel()
    Pt, Qt = P(nodes), Q(nodes)
    S, R, U, hsv, Vt = hankel_svd(Pt, Qt)
    vectors = S @ np.swapaxes(Vt, 1, 2)
    order = branches(hsv, vectors)
    gap = hsv[:, r - 1] - (hsv[:, r] if r < n else 0.0)
    # a branch that leaves the first r values crosses σ_r between two samples
    crossed = np.flatnonzero(np.any(order[:, :r] >= r, axis=1))
    if np.min(gap) <= 1e-8 * hsv.max() or crossed.size:
        k = int(crossed[0]) if crossed.size else int(np.argmin(gap))
        raise ValueError(f"orders={r}: the Hankel singular values {r} and {r + 1} meet at "
                         f"t = {nodes[k] % T:.4g} (no uniform gap σ_{r}(t) > σ_{r + 1}(t)): "
                         "no balanced truncation of constant order exists (choose another "
                         "order)")
    Y, Ydot = _smooth_basis(P, Q, r, T)

    def matrices(t, Pt, Qt, factors):
        A, B, C = sys.A(t), sys.B(t), sys.C(t)
        S, R, U, hsv, Vt = factors
        sr = hsv[:, :r]
        Vb = S @ np.swapaxes(Vt, 1, 2)[:, :, :r] / np.sqrt(sr)[:, None, :]
        Wb = (np.swapaxes(U, 1, 2)[:, :r] @ np.swapaxes(R, 1, 2)) / np.sqrt(sr)[:, :, None]
        Vp = np.linalg.svd(R @ U[:, :, :r])[0][:, :, r:]        # orthonormal, ker W_b
        Vpt = np.swapaxes(Vp, 1, 2)
        Wp = Vpt - (Vpt @ Vb) @ Wb                              # V_⊥ᵀ(I − Π)
        At, Ct = np.swapaxes(A, 1, 2), np.swapaxes(C, 1, 2)
        Pdot = A @ Pt + Pt @ At + B @ np.swapaxes(B, 1, 2)
        Qdot = -(At @ Qt + Qt @ A + Ct @ C)
        G = Wb @ (Pdot @ Qt + Pt @ Qdot) @ Vp
        Mp = Vpt @ Pt @ Qt @ Vp
        # row i of X: X_i (σ_i² I − M_⊥) = G_i
        lhs = (sr ** 2)[:, :, None, None] * np.eye(n - r) - Mp[:, None]
        X = np.linalg.solve(np.swapaxes(lhs, -1, -2), G[..., None])[..., 0]
        y, yd = Y(t), Ydot(t)
        K = Wb @ y
        Ar = np.linalg.solve(K, Wb @ A @ Vb @ K - X @ Wp @ y - Wb @ yd)
        return Ar, np.linalg.solve(K, Wb @ B), C @ Vb @ K

    values = matrices(nodes, Pt, Qt, (S, R, U, hsv, Vt))
    shape = (len(grid) - 1, _CHEB_DEG + 1)
    interpolants = [piecewise_chebyshev(grid, v.reshape(shape + v.shape[1:])) for v in values]
    # check the interpolants against exact values inside every interval
    probe = grid[:-1] + 0.3717 * np.diff(grid)
    Pp, Qp = P(probe), Q(probe)
    exact = matrices(probe, Pp, Qp, hankel_svd(Pp, Qp))
    err = max(np.abs(f(probe) - e).max() / max(1.0, np.abs(e).max())
              for f, e in zip(interpolants, exact))
    if err > 1e-8:
        warnings.warn(f"the reduced matrices are interpolated with relative errors up to "
                      f"{err:.1e}; increase nsteps", UserWarning, stacklevel=3)
    breaks = np.concatenate([M.breakpoints for M in (sys.A, sys.B, sys.C)])
    Ar, Br, Cr = (PeriodicMatrix.from_function(f, T, v.shape[1:], breakpoints=breaks,
                                               check=False)
                  for f, v in zip(interpolants, values))
    # sup of every discarded branch: the bound's terms
    sup = np.max(np.take_along_axis(hsv, order, axis=1)[:, r:], axis=0, initial=0.0)
    return (Ar, Br, Cr), sup


def _smooth_basis(P, Q, r, T):
    """Smooth T-periodic ``Y(t)`` (n x r) spanning about ``range Π(t)``, and ``Ẏ``."""
    nsamp = 32
    while True:
        t = np.arange(nsamp) * T / nsamp
        S, _, _, _, Vt = hankel_svd(P(t), Q(t))
        Z = np.linalg.qr(S @ np.swapaxes(Vt, 1, 2)[:, :, :r])[0]
        Y = np.empty_like(Z)
        Y[0], prev, worst = Z[0], Z[0], 1.0
        # orthogonal Procrustes: the basis of range Π(t_k) closest to the last one
        for k in range(1, nsamp + 1):
            a, c, bt = np.linalg.svd(Z[k % nsamp].T @ prev)
            prev, worst = Z[k % nsamp] @ (a @ bt), min(worst, c.min())
            if k < nsamp:
                Y[k] = prev
        if worst >= _MAX_COS or nsamp >= 4096:
            break
        nsamp *= 2
    holonomy = Y[0].T @ prev                     # Y(T) = Y(0) H after one turn
    if np.linalg.det(holonomy) < 0:
        raise ValueError(f"orders={r}: the retained subspace reverses its orientation over "
                         "one period, so no T-periodic reduced model of this order exists")
    L = np.real(la.logm(holonomy))
    Y = Y @ la.expm(-L[None] * (t / T)[:, None, None])
    Y = PeriodicMatrix.from_samples(Y, T)
    K = Y.nharmonics
    Ydot = PeriodicMatrix(Y.fourier(K) * (1j * Y.omega_p * np.arange(-K, K + 1))[:, None, None],
                          T)
    return Y, Ydot


def branches(hsv, vectors):
    """Follow every Hankel singular value along its branch over the samples.

    Where two values cross, the ordered values switch branches; a smooth
    balanced realization follows the branches, matched from sample to sample
    by the overlap of the eigenvectors of ``P Q`` (columns of `vectors`)
    among values within 20 % of each other (vanishing values, whose vectors
    are arbitrary, form one group).  Returns ``order`` (samples, n): the
    column of each branch at each sample.

    Examples
    --------
    Two close values whose eigenvectors trade places: the branch along ``e_1``
    moves from column 0 to column 1.

    >>> from ltpcontrol._analysis.periodic_balancing import branches
    >>> hsv = np.array([[1.1, 1.0], [1.1, 1.0]])
    >>> vectors = np.array([np.eye(2), np.eye(2)[:, ::-1]])
    >>> branches(hsv, vectors)
    array([[0, 1],
           [1, 0]])
    """
    E = vectors / np.maximum(np.linalg.norm(vectors, axis=1, keepdims=True), 1e-300)
    order = np.empty(hsv.shape, int)
    order[0] = np.arange(hsv.shape[1])
    logs = np.log(np.maximum(hsv, 1e-10 * hsv.max(initial=0.0) + 1e-300))
    for k in range(1, len(hsv)):
        overlap = np.abs(E[k - 1][:, order[k - 1]].T @ E[k])
        far = np.abs(logs[k - 1, order[k - 1]][:, None] - logs[k][None, :]) > 0.2
        overlap[far] -= 2.0
        order[k] = linear_sum_assignment(-overlap)[1]
    return order
