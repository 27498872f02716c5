"""Stabilizing solutions of periodic Riccati equations from a cyclic pencil.

Continuous (one Hamiltonian flow factor per step) and discrete (one
symplectic pencil per step) periodic Riccati equations share these steps:
the cyclic product of the step pencils collapsed with orthogonal
transformations only, the stable deflating subspace by ordered QZ, Newton
refinement of the periodicity condition, and the closed-loop exponents
with the check that they are stabilizing (see `ltpcontrol._analysis.riccati`).
"""

import warnings

import numpy as np
import scipy.linalg as la

from .._core.floquet import _log_multipliers

# relative periodicity residual above which a warning is issued
_RESIDUAL_WARN = 1e-8
# multipliers within this distance of the unit circle count as on it
_CIRCLE_TOL = 1e-10
# closed-loop log|μ| above -first: not stabilizing; above -second: doubtful
# (a defective unit-circle pair splits by about sqrt(eps))
_CLOSED_LOOP_TOL = (1e-9, 1e-6)


def _stable_solution(Lk, Mk, n):
    """``X_0 = V U⁻¹`` from the stable deflating subspace of the collapsed pencil."""
    Lc, Mc = _collapse(np.asarray(Lk, float), np.asarray(Mk, float))
    # QZ of the pencil M - μ L, stable eigenvalues first
    _, _, alpha, beta, _, Zq = la.ordqz(Mc, Lc, sort='iuc', output='real')
    with np.errstate(divide='ignore', invalid='ignore'):
        mod = np.where(beta != 0, np.abs(alpha) / np.abs(beta), np.inf)
    nstable = int(np.count_nonzero(mod < 1 - _CIRCLE_TOL))
    if nstable != n or np.any(np.abs(mod - 1) <= _CIRCLE_TOL):
        raise ValueError(
            "no stabilizing periodic solution exists: the Hamiltonian has "
            f"{int(np.count_nonzero(np.abs(mod - 1) <= _CIRCLE_TOL))} multipliers on "
            "the unit circle (check that (A, B) is stabilizable and that Q penalizes "
            "every mode on the stability boundary)")
    U, V = Zq[:n, :n], Zq[n:, :n]
    if np.linalg.cond(U) > 1e12:
        raise ValueError("no stabilizing periodic solution exists: the stable subspace "
                         "is not a graph over the state space (check that (A, B) is "
                         "stabilizable)")
    X0 = np.linalg.solve(U.T, V.T).T
    return 0.5 * (X0 + X0.T)


def _collapse(L, M):
    """One pencil ``(L, M)`` with ``L⁻¹M = L_{K-1}⁻¹M_{K-1} ... L_0⁻¹M_0``.

    Neighbours are merged pairwise (a balanced tree, batched): for factors
    k, k+1 the QR factorisation of ``[L_k; -M_{k+1}]`` gives ``[Z1 Z2]``
    with ``Z1 L_k = Z2 M_{k+1}``, and the pair becomes ``(Z2 L_{k+1}, Z1 M_k)``.
    """
    d = L.shape[1]
    while len(L) > 1:
        even = len(L) - len(L) % 2
        q, _ = np.linalg.qr(np.concatenate([L[0:even:2], -M[1:even:2]], axis=1),
                            mode='complete')
        Z = np.swapaxes(q, 1, 2)[:, d:]
        Lnew, Mnew = Z[:, :, d:] @ L[1:even:2], Z[:, :, :d] @ M[0:even:2]
        if even < len(L):
            Lnew, Mnew = np.concatenate([Lnew, L[-1:]]), np.concatenate([Mnew, M[-1:]])
        L, M = Lnew, Mnew
    return L[0], M[0]



def _exponents(factors, period=None, nper=None):
    """Floquet exponents (continuous) or per-step exponents (discrete) of the
    closed-loop factors; raises unless every multiplier is inside the unit
    circle (a Hamiltonian multiplier pair on the circle, split by round-off,
    can pass the count of stable multipliers and give a non-stabilizing X)."""
    logmod, arg = _log_multipliers(None, None, grid=None, factors=factors)
    worst = logmod.max() if logmod.size else -np.inf
    if not worst < -_CLOSED_LOOP_TOL[0]:
        raise ValueError(
            "no stabilizing periodic solution exists: the closed loop keeps a Floquet "
            f"multiplier on the unit circle (log|mu| = {worst:.1e}); check that (A, B) "
            "is stabilizable and that Q penalizes every mode on the stability boundary")
    if worst >= -_CLOSED_LOOP_TOL[1]:
        warnings.warn(
            f"the closed loop has a Floquet multiplier with log|mu| = {worst:.1e}: at "
            "this precision a Hamiltonian multiplier pair on the unit circle looks the "
            "same, so the solution may not be stabilizing", UserWarning, stacklevel=3)
    if nper is not None:
        with np.errstate(under='ignore', over='ignore'):
            return np.exp(logmod / nper) * np.exp(1j * arg / nper)   # log|μ| may be -inf
    return logmod / period + 1j * (arg / period)


def _refine(X0, sweep, passes=2):
    """Newton refinement of the pencil's ``X_0`` on the periodicity condition.

    ``sweep(X_0)`` runs the backward recursion over one period and returns
    the samples (first: the period map ``F(X_0)``) and the closed-loop step
    factors.  ``F(X_0 + Δ) ≈ F(X_0) + ΦᵀΔΦ`` with the closed-loop monodromy
    Φ, so the Newton step solves the Stein equation ``Δ = ΦᵀΔΦ + F(X_0) -
    X_0``.  The pencil's ``X_0`` is backward stable but its error is
    amplified by the conditioning of the stable subspace; one or two steps
    restore full accuracy.  Returns the samples with ``X[0] = X[-1]``.
    """
    scale = max(1.0, np.abs(X0).max())
    Xs, factors = sweep(X0)
    res = Xs[0] - X0
    for _ in range(passes):
        if np.abs(res).max() <= 1e-13 * scale:
            break
        mono = np.eye(X0.shape[0])
        for f in factors:
            mono = f @ mono
        if not np.all(np.isfinite(mono)) or np.max(np.abs(la.eigvals(mono))) >= 1:
            break
        # a far from normal closed loop (a nearly uncontrollable plant) makes
        # the Stein equation's Kronecker form numerically singular: the step
        # is kept only when it lowers the residual
        try:
            with warnings.catch_warnings():
                warnings.simplefilter('ignore', la.LinAlgWarning)
                delta = la.solve_discrete_lyapunov(mono.T, res)
        except np.linalg.LinAlgError:
            break
        X1 = X0 + 0.5 * (delta + delta.T)
        Xs1, factors1 = sweep(X1)
        res1 = Xs1[0] - X1
        if not np.abs(res1).max() < np.abs(res).max():
            break
        X0, Xs, factors, res = X1, Xs1, factors1, res1
    err = np.abs(res).max() / scale
    if not np.isfinite(err) or err > _RESIDUAL_WARN:
        warnings.warn(f"the periodic Riccati solution has a periodicity residual of "
                      f"{err:.1e}: the problem is ill-conditioned (closed-loop "
                      "multipliers close to the unit circle, a nearly uncontrollable "
                      "mode or a badly scaled plant)",
                      UserWarning, stacklevel=3)
    Xs[0] = X0
    return Xs, factors

