"""Discrete-time LQ output-feedback cost with its exact gradient and Hessian.

For the loop ``x_{k+1} = A_{c,k} x_k``, ``A_{c,k} = A_k - B_kF_kC_k`` with
``F_k = Σ_i φ_{ki} F_i`` (`ltpcontrol.oflqr`, module notes there), the
cost is ``J = tr(P_0 X_0)`` with the adjoint periodic Lyapunov solution
``P_k = A_{c,k}ᵀ P_{k+1} A_{c,k} + Q_{c,k}``, ``Q_c = Q + CᵀFᵀRFC``, and
its gradient is

    ∂J/∂F_k = 2 (R_kF_kC_k - B_kᵀP_{k+1}A_{c,k}) Y_k C_kᵀ,

Y the forward solution with ``Y_0 = A_{c,N-1} Y_{N-1} A_{c,N-1}ᵀ + X_0``.
A direction ``D_k`` changes ``A_c`` by ``δA_k = -B_kD_kC_k`` and ``Q_c`` by
``C_kᵀ(D_kᵀR_kF_k + F_kᵀR_kD_k)C_k``; ``δP`` and ``δY`` solve the same
cyclic equations forced by ``δA_kᵀP_{k+1}A_{c,k} + A_{c,k}ᵀP_{k+1}δA_k +
δQ_{c,k}`` and ``δA_kY_kA_{c,k}ᵀ + A_{c,k}Y_kδA_kᵀ``, and

    δ(∂J/∂F_k) = 2 (R_kD_kC_k - B_kᵀδP_{k+1}A_{c,k} - B_kᵀP_{k+1}δA_k) Y_kC_kᵀ
                 + 2 (R_kF_kC_k - B_kᵀP_{k+1}A_{c,k}) δY_k C_kᵀ,

which gives the exact Hessian, one column per parameter, all columns at
once.

The cyclic equations ``X_{k+1} = T_kX_kT_kᵀ + S_k`` (k = 0..N-1, ``X_N =
X_0``) are solved by an associative scan of the maps ``X -> TXTᵀ + S``
(log₂ N batched products instead of N sequential ones), the Stein equation
``X_0 = MX_0Mᵀ + S`` of the composite map by a Kronecker solve, and every
``X_k`` from the scanned maps.  Only stable loops are evaluated (the cost is
infinite otherwise), where this is well conditioned for the small state
dimensions of output-feedback design.
"""

import warnings

import numpy as np
import scipy.linalg as la
from scipy.optimize import minimize

__all__ = []


def _kron(T):
    """``T_k ⊗ T_k`` (row-major vec: vec(TXTᵀ) = (T ⊗ T) vec X)."""
    N, n = T.shape[0], T.shape[-1]
    return np.einsum('kia,kjb->kijab', T, T).reshape(N, n * n, n * n)


def cyclic_congruence(T, S, stein=None):
    """Solve ``X_{k+1} = T_k X_k T_kᵀ + S_k`` cyclically (``X_N = X_0``).

    `T` has shape (N, n, n), `S` shape (..., N, n, n); returns ``X_0 ..
    X_{N-1}`` of the shape of `S`.  `stein` is an LU factorisation of
    ``I - M ⊗ M`` (M the composite map) to reuse, else it is computed; the
    pair ``(X, stein)`` is returned.  The maps act on vec X as the
    Kronecker products ``T_k ⊗ T_k``, so a batch of right-hand sides is one
    matrix product per scan level.

    Examples
    --------
    >>> from ltpcontrol._analysis.output_feedback_lq import cyclic_congruence
    >>> X, _ = cyclic_congruence(np.array([[[0.5]], [[0.5]]]), np.ones((2, 1, 1)))
    >>> X[:, 0, 0]          # X1 = X0/4 + 1, X0 = X1/4 + 1
    array([1.33333333, 1.33333333])
    """
    S = np.asarray(S, float)
    N, n = T.shape[0], T.shape[-1]
    batch = S.shape[:-3]
    nb = int(np.prod(batch))
    Sv = np.moveaxis(S.reshape((nb, N, n * n)), 0, -1).copy()       # (N, n², nb)
    Tc = T.copy()
    d = 1
    while d < N:                     # inclusive scan: map of steps 0..k
        Sv[d:] = _kron(Tc[d:]) @ Sv[:-d] + Sv[d:]
        Tc[d:] = Tc[d:] @ Tc[:-d]
        d *= 2
    if stein is None:
        stein = la.lu_factor(np.eye(n * n) - _kron(Tc[-1:])[0])
    X = np.empty_like(Sv)
    X[0] = la.lu_solve(stein, Sv[-1])
    X[1:] = _kron(Tc[:-1]) @ X[0] + Sv[:-1]
    X = np.moveaxis(X, -1, 0).reshape(batch + (N, n, n))
    return 0.5 * (X + np.swapaxes(X, -1, -2)), stein


def _adjoint(Ac, S, stein=None):
    """``P_k = A_kᵀ P_{k+1} A_k + S_k`` cyclic, by the forward solver on the
    reversed transposed sequence."""
    X, stein = cyclic_congruence(np.swapaxes(Ac[::-1], 1, 2), S[..., ::-1, :, :], stein)
    return np.roll(X[..., ::-1, :, :], 1, axis=-3), stein      # X_j = P_{N-j}


def _stable(Ac):
    """All multipliers of ``A_{N-1} ... A_0`` inside the unit circle (the plain
    product: only used to keep the cost evaluation on stable loops; results
    are verified independently)."""
    M = Ac[0]
    for a in Ac[1:]:
        M = a @ M
    with np.errstate(all='ignore'):
        return bool(np.all(np.isfinite(M)) and np.abs(np.linalg.eigvals(M)).max() < 1)


class DiscreteLQ:
    """``J``, ``∂J/∂θ`` and ``∂²J/∂θ²`` of the discrete LQ output-feedback cost.

    Parameters are ``θ = (F_i)`` of shape (s, m, p) raveled; `phi` (N, s)
    the basis values per step.  A, B, C, Q, R are per-step arrays.
    """

    def __init__(self, A, B, C, Q, R, X0, phi):
        self.A, self.B, self.C, self.Q, self.R, self.X0 = A, B, C, Q, R, X0
        self.phi = phi
        self.N, self.n = A.shape[0], A.shape[1]
        self.m, self.p = B.shape[2], C.shape[1]
        self.s = phi.shape[1]
        self.nev = 0

    def curvature(self, theta):
        """Block curvature ``Σ_k φ_kφ_kᵀ ⊗ 2(R_k + B_kᵀP_{k+1}B_k) ⊗ C_kY_kC_kᵀ``
        (the Hessian with P and Y held fixed, Levine and Athans' step),
        (d, d) for d = s m p; None for an unstable loop."""
        params = np.asarray(theta, float).reshape(self.s, self.m, self.p)
        F = np.einsum('ki,iab->kab', self.phi, params)
        FC = F @ self.C
        Ac = self.A - self.B @ FC
        if not _stable(Ac):
            return None
        P, _ = _adjoint(Ac, self.Q + np.swapaxes(FC, 1, 2) @ self.R @ FC)
        W = np.zeros_like(Ac)
        W[-1] = self.X0
        Y, _ = cyclic_congruence(Ac, W)
        Wm = self.R + np.swapaxes(self.B, 1, 2) @ np.roll(P, -1, axis=0) @ self.B
        V = self.C @ Y @ np.swapaxes(self.C, 1, 2)
        H = 2 * np.einsum('ki,kj,kac,kbd->iabjcd', self.phi, self.phi, Wm, V, optimize=True)
        d = self.s * self.m * self.p
        return H.reshape(d, d)

    def __call__(self, theta, hessian=False):
        """``(J, grad)`` or ``(J, grad, hess)``; J = inf for an unstable loop."""
        self.nev += 1
        params = np.asarray(theta, float).reshape(self.s, self.m, self.p)
        F = np.einsum('ki,iab->kab', self.phi, params)
        FC = F @ self.C
        Ac = self.A - self.B @ FC
        if not _stable(Ac):
            out = (np.inf, np.zeros(params.size))
            return out + (None,) if hessian else out
        RFC = self.R @ FC
        Qc = self.Q + np.swapaxes(FC, 1, 2) @ RFC
        P, stein_p = _adjoint(Ac, Qc)
        W = np.zeros_like(Ac)
        W[-1] = self.X0
        Y, stein_y = cyclic_congruence(Ac, W)
        Pn = np.roll(P, -1, axis=0)                      # P_{k+1}
        BtP = np.swapaxes(self.B, 1, 2) @ Pn
        Ct = np.swapaxes(self.C, 1, 2)
        L = RFC - BtP @ Ac                               # (N, m, n)
        G = 2 * L @ Y @ Ct
        cost = float(np.trace(P[0] @ self.X0))
        grad = np.einsum('ki,kab->iab', self.phi, G).ravel()
        if not hessian:
            return cost, grad
        # one direction per parameter: D_k = φ_ki E_ab
        s, m, p = self.s, self.m, self.p
        E = np.zeros((s, m, p, s, m, p))
        idx = np.arange(s * m * p)
        E.reshape(s * m * p, s * m * p)[idx, idx] = 1.0
        E = E.reshape(s * m * p, s, m, p)
        D = np.einsum('ki,diab->dkab', self.phi, E, optimize=True)     # (d, N, m, p)
        DC = D @ self.C                                  # (d, N, m, n)
        dA = -self.B @ DC                                # (d, N, n, n)
        PA = Pn @ Ac
        sym = np.swapaxes(dA, -1, -2) @ PA + np.swapaxes(DC, -1, -2) @ RFC
        dP, _ = _adjoint(Ac, sym + np.swapaxes(sym, -1, -2), stein_p)
        AY = Ac @ Y
        fy = dA @ np.swapaxes(AY, 1, 2)
        dY, _ = cyclic_congruence(Ac, fy + np.swapaxes(fy, -1, -2), stein_y)
        dPn = np.roll(dP, -1, axis=1)
        dL = self.R @ DC - np.swapaxes(self.B, 1, 2) @ dPn @ Ac - BtP @ dA
        dG = 2 * (dL @ Y @ Ct + L @ dY @ Ct)
        H = np.einsum('ki,dkab->diab', self.phi, dG, optimize=True).reshape(s * m * p, -1)
        return cost, grad, 0.5 * (H + H.T)


def _trust_newton(fun, theta, maxiter, rtol, metric=None, stall=1e-7, floor=1e-8):
    """Trust-region Newton with the exact Hessian (Moré–Sorensen step from
    the eigendecomposition).

    The trust region is a ball in variables scaled by the Hessian diagonal
    (Moré's adaptive scaling) or, with a positive definite `metric` M, in
    variables whitened by M (``θ = θ₀ + M^{-1/2} x``; the Levine–Athans
    curvature makes the steps of very different gains comparable).
    `fun(θ, hessian)` returns ``(J, grad[, hess])`` with ``J = inf`` outside
    the domain.  Stops when the Hessian is positive definite and the Newton
    decrement ``gᵀH⁻¹g`` (twice the decrease a Newton step predicts) is at
    most ``rtol·J``; gives up when ten steps lower J by less than `stall`
    relative (a saddle or a flat valley).  Returns ``(θ, nit, converged,
    decrement)``.
    """
    J, g, H = fun(theta, True)
    history = [J]
    if metric is None:
        d = np.sqrt(np.maximum(np.abs(np.diag(H)), 1e-300))
        d = np.maximum(d, floor * d.max())
    else:
        lam, U = np.linalg.eigh(metric)
        lam = np.maximum(lam, 1e-12 * lam.max())
        S = U / np.sqrt(lam)
    radius, nit, dec = 1.0, 0, np.inf
    for nit in range(maxiter + 1):
        if metric is None:
            d = np.maximum(d, np.sqrt(np.abs(np.diag(H))))      # Moré's adaptive scaling
            gs, Hs = g / d, H / d[:, None] / d[None, :]
        else:
            gs, Hs = S.T @ g, S.T @ H @ S
        w, V = np.linalg.eigh(Hs)
        c = V.T @ gs
        if w[0] > 0:
            dec = float(np.sum(c * c / w))
            if dec <= rtol * abs(J):
                return theta, nit, True, dec
        if nit == maxiter:
            break
        while True:
            step = _tr_step(w, V, c, radius)
            pred = -(gs @ step + 0.5 * step @ Hs @ step)
            trial = theta + (step / d if metric is None else S @ step)
            J_new, g_new = fun(trial, False)[:2]
            rho = (J - J_new) / pred if pred > 0 else -np.inf
            norm = np.linalg.norm(step)
            if not rho > 0.25:
                radius = 0.25 * norm
            elif rho > 0.75 and norm > 0.99 * radius:
                radius = 2 * radius
            if rho > 1e-4:
                break
            if radius < 1e-14:
                return theta, nit, False, dec
        theta = trial
        J, g, H = fun(theta, True)
        history.append(J)
        if len(history) > 10 and history[-11] - J <= stall * abs(J):
            return theta, nit + 1, False, dec
    return theta, maxiter, False, dec


def _tr_step(w, V, c, radius):
    """Minimizer of ``cᵀs + ½ sᵀ diag(w) s`` over ``|s| <= radius`` (eigenbasis
    of the scaled Hessian), mapped back by V."""
    def step(lam):
        return -c / (w + lam)
    lo = max(0.0, -w[0]) + 1e-14 * max(1.0, abs(w[-1]))
    if w[0] > 0 and np.linalg.norm(step(0.0)) <= radius:
        return V @ step(0.0)
    hi = lo + np.linalg.norm(c) / radius + abs(w[-1])
    if np.linalg.norm(step(lo)) <= radius:       # hard case: move along the lowest mode
        s = step(lo)
        s[0] += np.sqrt(max(radius ** 2 - s @ s, 0.0))
        return V @ s
    for _ in range(100):                         # |s(λ)| decreases in λ
        mid = 0.5 * (lo + hi)
        if np.linalg.norm(step(mid)) > radius:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-12 * hi:
            break
    return V @ step(hi)


def _minimize_lq(lq, theta, maxiter, rtol, newton=True, bfgs_round=200, newton_size=2e7):
    """Minimize the discrete LQ cost from a stabilizing θ.

    Rounds of BFGS in variables whitened by `DiscreteLQ.curvature` at the
    round's start (gains of 1e4..1e7 and costs of order 1 make the raw
    variables useless to BFGS) until a round ends on its own, lowers J by
    less than 1e-8 relative or reaches the first-order test below, at most
    `maxiter` iterations in all; then (`newton`)
    at most ``min(100, maxiter)`` steps of `_trust_newton` with the exact
    Hessian, which certifies a local minimum (positive definite Hessian,
    Newton decrement ``<= rtol J``).  Otherwise (or when the Hessian would
    need more than `newton_size` numbers, directions x steps x n²) the
    point is judged stationary by the whitened gradient, ``gᵀĤ⁻¹g <= rtol
    J`` with Ĥ the curvature above; failing both, BFGS and Newton are
    repeated within `maxiter` while a cycle lowers J by more than 1e-10
    relative; when they stall, `_polish` takes trust-region Newton steps
    along the negative curvature and the whitened-gradient test is applied
    again.  Returns ``(θ, nit, converged, message)``.
    """
    nit, d, dec = 0, theta.size, np.inf
    while True:
        J0 = lq(theta)[0]
        theta, k = _whitened_bfgs(lq, theta, maxiter - nit, rtol, bfgs_round)
        nit += k
        if not newton:
            return theta, nit, True, 'BFGS'
        if d * lq.N * lq.n ** 2 <= newton_size:
            theta, k, ok, dec = _trust_newton(lambda t, h: lq(t, hessian=h), theta,
                                             min(100, maxiter), rtol)
            nit += k
            if ok:
                return theta, nit, True, (f"local minimum: positive definite Hessian, Newton "
                                          f"decrement {dec / abs(lq(theta)[0]):.2e} J <= gtol J")
        dec = _whitened_decrement(lq, theta)
        if dec <= rtol:
            return theta, nit, True, (
                f"stationary point: whitened gradient gᵀĤ⁻¹g = {dec:.2e} J <= gtol J, but no "
                "local minimum certified (the exact Hessian is not positive definite or too "
                "large: a saddle or a flat valley)")
        if nit >= maxiter or J0 - lq(theta)[0] <= 1e-10 * abs(J0):
            break                                # budget spent, or a cycle that stalls
    if d * lq.N * lq.n ** 2 <= newton_size:
        theta, k, ok, dec = _polish(lq, theta, maxiter - nit, rtol)
        nit += k
        if ok:
            return theta, nit, True, (
                f"stationary point: whitened gradient gᵀĤ⁻¹g = {dec:.2e} J <= gtol J, but no "
                "local minimum certified (the exact Hessian is indefinite: a saddle or a flat "
                "valley)")
    return theta, nit, False, f"not stationary: whitened gradient gᵀĤ⁻¹g = {dec:.2e} J > gtol J"


def _polish(lq, theta, maxiter, rtol):
    """Last stage of `_minimize_lq` on an indefinite, badly scaled Hessian
    where BFGS and Newton stall: trust-region Newton steps along the
    negative curvature, the trust region alternately a ball in variables
    whitened by the curvature and in variables scaled by the Hessian
    diagonal down to 1e-12 of its largest entry, stopping on ten steps that
    lower J by less than 1e-9 relative, repeated while a round lowers J.
    Returns ``(θ, nit, stationary, whitened decrement / J)``."""
    nit, dec = 0, _whitened_decrement(lq, theta)
    for rnd in range(20):
        if dec <= rtol or nit >= maxiter:
            break
        J0 = lq(theta)[0]
        metric = lq.curvature(theta) if rnd % 2 else None
        theta_new, k, ok, _ = _trust_newton(lambda t, h: lq(t, hessian=h), theta,
                                           min(100, maxiter - nit), rtol, metric=metric,
                                           stall=1e-9, floor=1e-12)
        nit += max(k, 1)
        if lq(theta_new)[0] < J0:
            theta = theta_new
        dec = _whitened_decrement(lq, theta)
        if ok:
            return theta, nit, True, dec
        if rnd % 2 and not J0 - lq(theta)[0] > 1e-12 * abs(J0) and rnd > 1:
            break
    return theta, nit, dec <= rtol, dec


def _whitened_decrement(lq, theta):
    J, g = lq(theta)
    return float(g @ np.linalg.solve(lq.curvature(theta), g)) / abs(J)


def _whitened_bfgs(lq, theta, maxiter, rtol, bfgs_round):
    """BFGS rounds in whitened variables (`_minimize_lq`); ``(θ, nit)``."""
    nit, J, d = 0, lq(theta)[0], theta.size
    while nit < maxiter:
        H = lq.curvature(theta)
        lam, U = np.linalg.eigh(H)
        lam = np.maximum(lam, 1e-12 * lam.max())
        S = U / np.sqrt(lam)
        f0 = theta.copy()

        def fun(x):
            c, g = lq(f0 + S @ x)
            if not np.isfinite(c):
                return 1e300, np.zeros_like(x)
            return c, S.T @ g
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', RuntimeWarning)
            res = minimize(fun, np.zeros(d), jac=True, method='BFGS',
                           options={'maxiter': min(bfgs_round, maxiter - nit), 'gtol': 0.0})
        nit += max(int(res.nit), 1)
        drop = 0.0
        if res.fun < J:
            theta = f0 + S @ res.x
            drop, J = (J - res.fun) / abs(res.fun), res.fun
        if res.nit < bfgs_round or drop < 1e-8 or _whitened_decrement(lq, theta) <= rtol:
            break
    return theta, nit


def _stabilize_lq(make_lq, theta, log_radius, target, maxiter, rounds=10):
    """Lower ``f = log|μ_max|`` (per period) below `target` by minimizing the
    LQ cost of loops scaled by ``e^{-α}`` per period, ``α = max(f, 0) +
    log 1.01`` (finite at the start; the reference toolbox's homotopy),
    at most 50 whitened BFGS iterations per round and `maxiter` in all.
    `make_lq(α)` builds the scaled `DiscreteLQ`.  Returns ``(θ, f, nit)``."""
    f, nit = log_radius(theta), 0
    for _ in range(rounds):
        if f < target or nit >= maxiter:
            break
        lq = make_lq(max(f, 0.0) + np.log(1.01))
        theta_new, k, _, _ = _minimize_lq(lq, theta, min(50, maxiter - nit), 0.0, newton=False)
        nit += k
        f_new = log_radius(theta_new)
        if not f_new < f:
            break
        theta, f = theta_new, f_new
    return theta, f, nit
