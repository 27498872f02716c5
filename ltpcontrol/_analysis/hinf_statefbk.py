"""Periodic H∞ state feedback by the periodic Riccati equation and bisection on γ.

Generalized plant (continuous or discrete time, T-periodic data)::

    ẋ = A x + B1 w + B2 u,     z = C1 x + D12 u      (D11 = 0)

with the inputs of `P` ordered ``[w; u]`` (the last `ncon` are controls)
and ``D12ᵀD12 ≻ 0``.  With ``B = [B1 B2]``, ``Q = C1ᵀC1``, ``S = C1ᵀD =
[0, C1ᵀD12]`` and the indefinite weight ``R_γ = DᵀD - γ²[[I, 0], [0, 0]] =
blkdiag(-γ²I, D12ᵀD12)``, the level γ is achievable by a stabilizing
periodic state feedback ``u = -K x`` (closed-loop L2 gain from w to z
below γ) if and only if the periodic Riccati equation of the data
``(A, B, Q, R_γ, S)`` has a stabilizing periodic solution ``X ⪰ 0`` (the
periodic bounded real lemma; Bittanti and Colaneri, *Periodic Systems*),
and in discrete time in addition ``γ²I - B1ᵀX_{k+1}B1 ≻ 0``.  It is solved
by the library's periodic Riccati solver (the cyclic Hamiltonian or
symplectic pencil), which admits the indefinite R.  The gains are

* continuous: ``K = (D12ᵀD12)⁻¹(B2ᵀX + D12ᵀC1)``;
* discrete (u does not see w_k): with ``X̃ = X_{k+1} + X_{k+1}B1(γ²I -
  B1ᵀX_{k+1}B1)⁻¹B1ᵀX_{k+1}``, ``K_k = (D12ᵀD12 + B2ᵀX̃B2)⁻¹(B2ᵀX̃A_k +
  D12ᵀC1)``.

In continuous time the indefinite Riccati differential equation may
escape to infinity inside the period although its pencil has a stable
subspace: X is then no solution.  The escape shows as a sign change of
``det U`` over a step of the backward flow ``[U; V]`` (checked by the
solver), and ``X ⪰ 0`` is checked at every step boundary.

Without a level, the smallest achievable γ is bracketed by halving and
doubling, then bisected (geometrically) until the bracket's ratio is below
``1 + tol``; the gain of the upper end is returned.  Whatever the Riccati
test says, the returned gain is closed around the plant and the loop's
Floquet multipliers and H∞ norm (`ltpcontrol.norm`, certified upper bound) are computed
independently: `success` requires a stable loop whose norm is at most the
returned bound.
"""

import numbers
import warnings
from dataclasses import dataclass

import numpy as np
from control.exception import ControlArgument

from .._core.coerce import as_ltp
from .._core.floquet import floquet_multipliers
from .._core.ltpsys import ltpss
from .._core.periodic_matrix import PeriodicMatrix
from .norms import norm as linf_norm
from .riccati import _care_solution, _dare_solution
from .riccati_solution import _RiccatiSolution

__all__ = ['hinf_statefbk', 'HinfStateFeedbackResult']

# the bracket of the search: γ between these multiples of the starting level
_GAMMA_RANGE = 1e12
# accuracies of the independent norm check, and the relative slack of the
# comparison with γ at the finest
_NORM_TOLS = (1e-4, 1e-8)
_NORM_SLACK = 1e-7


@dataclass
class HinfStateFeedbackResult:
    """Result of `hinf_statefbk`.

    Attributes
    ----------
    success : bool
        True when the gain stabilizes the plant (independent Floquet
        multipliers) and the closed-loop H∞ norm, computed independently by
        `ltpcontrol.norm`, is at most `gamma`.
    message : str
        What happened, or why the design failed.
    gamma : float
        The certified bound (the achievable level whose gain is returned);
        inf when none was found.
    gamma_lower : float
        Largest level found not achievable (the optimum lies in
        ``(gamma_lower, gamma]``); nan when a level was given and achievable.
    norm : float
        Closed-loop H∞ norm from w to z: the certified upper bound of
        ``ltpcontrol.norm(closed_loop, 'inf')`` (inf for an unstable loop,
        nan when no gain).
    multipliers : ndarray of complex
        Floquet multipliers of the closed loop.
    X : PeriodicMatrix or ndarray
        Riccati solution at `gamma` (continuous: periodic matrix; discrete:
        the N samples ``X_k``); None when no gain.
    closed_loop : LTPStateSpace
        ``ẋ = (A - B2K)x + B1w``, ``z = (C1 - D12K)x``; None when no gain.
    ntrials : int
        Riccati equations solved.

    Examples
    --------
    >>> P = ltp.ltpss([[1.0]], [[1.0, 1.0]], [[1.0], [0.0]], [[0.0, 0.0], [0.0, 1.0]],
    ...               period=1.0)
    >>> K, info = ltp.hinf_statefbk(P, 1)
    >>> info.success, bool(info.norm <= info.gamma)
    (True, True)
    """

    success: bool
    message: str
    gamma: float
    gamma_lower: float
    norm: float
    multipliers: np.ndarray
    X: object
    closed_loop: object
    ntrials: int


def hinf_statefbk(P, ncon, gamma=None, *, tol=1e-2, nsteps=None):
    """Periodic H∞ state feedback ``u = -K(t) x`` of a generalized plant.

    Parameters
    ----------
    P : LTPStateSpace
        Generalized plant, continuous or discrete time, inputs ``[w; u]``
        and outputs z (module notes): ``D11 = 0``, ``D12`` of full column
        rank.  The whole state is measured.
    ncon : int
        Number of control inputs (the last `ncon` inputs of `P`).
    gamma : float, optional
        Level to achieve.  By default the smallest achievable level is
        found by bisection.
    tol : float, optional
        Relative width of the final bracket: the returned bound is at most
        ``(1 + tol)`` times the optimum.  Near the optimum the gains grow
        (often without bound), so a loose tolerance gives gentler gains.
    nsteps : int, optional
        Continuous time: steps of the period grid (see `care`).

    Returns
    -------
    K : PeriodicMatrix or None
        State-feedback gain, shape (ncon, n), ``u = -K x`` (held samples in
        discrete time); None when no level could be achieved.
    info : HinfStateFeedbackResult
        The bound ``gamma``, the closed loop and its independently computed
        norm and multipliers, and `success` (module notes).

    Raises
    ------
    ControlArgument
        If `ncon` is not an integer in ``[1, ninputs - 1]``.
    ValueError
        If D11 is not zero, D12 is not of full column rank, or `gamma`/`tol`
        is not a positive number.

    Examples
    --------
    ``ẋ = x + w + u``, ``z = [x; u]``: the optimal level solves the
    Riccati equation ``2X - X²(1 - γ⁻²) + 1 = 0`` with a finite stabilizing
    solution, ``γ* = 1``:

    >>> P = ltp.ltpss([[1.0]], [[1.0, 1.0]], [[1.0], [0.0]],
    ...               [[0.0, 0.0], [0.0, 1.0]], period=1.0)
    >>> K, info = ltp.hinf_statefbk(P, 1, tol=1e-4)
    >>> info.success, round(info.gamma, 3), bool(info.norm <= info.gamma)
    (True, 1.0, True)
    >>> K, info = ltp.hinf_statefbk(P, 1, gamma=0.9)
    >>> K is None, info.success
    (True, False)
    """
    P = as_ltp(P, 'P')
    m = P.ninputs
    if (not isinstance(ncon, numbers.Integral) or isinstance(ncon, bool)
            or not 1 <= ncon <= m - 1):
        raise ControlArgument(f"ncon must be an integer in [1, {m - 1}] (P has {m} inputs, "
                              f"the disturbances first), got {ncon!r}")
    for value, name in ((gamma, 'gamma'), (tol, 'tol')):
        if value is not None and (not isinstance(value, numbers.Real) or isinstance(value, bool)
                                  or not np.isfinite(value) or value <= 0):
            raise ValueError(f"{name} must be a positive number, got {value!r}")
    problem = _Problem(P, m - ncon, nsteps)
    if gamma is not None:
        sol = problem.solve(float(gamma))
        if sol is None:
            return None, _failure(problem, f"the level gamma = {gamma:.6g} is not achievable: "
                                  "the H∞ Riccati equation has no stabilizing positive "
                                  "semidefinite solution (the optimal level is larger, or the "
                                  "plant is not stabilizable)", float(gamma))
        return problem.result(float(gamma), sol, np.nan)
    return _bisection(problem, tol)


class _Problem:
    """The H∞ Riccati data of a generalized plant, solved at a level γ."""

    def __init__(self, P, nw, nsteps):
        self.P, self.nw, self.nsteps = P, nw, nsteps
        self.ntrials = 0
        n, p = P.nstates, P.noutputs
        self.discrete = P.isdtime(strict=True)
        if self.discrete:
            N = P.nsteps
            self.A, self.B, self.C, self.D = (M.sample(N) for M in (P.A, P.B, P.C, P.D))
        else:
            self.A, self.B, self.C, self.D = P.A, P.B, P.C, P.D
        probe = self.D if self.discrete else P.D(np.union1d(np.arange(16) * P.period / 16,
                                                            P.D.breakpoints))
        D11, D12 = probe[:, :, :nw], probe[:, :, nw:]
        if np.abs(D11).max(initial=0.0) > 0:
            raise ValueError("the feedthrough D11 from w to z must be zero (D[:, :nw] of P)")
        R = np.swapaxes(D12, 1, 2) @ D12
        if np.linalg.eigvalsh(R).min() <= 1e-12 * max(1.0, np.abs(R).max()):
            raise ValueError(f"D12 (the last {P.ninputs - nw} columns of D) must have full "
                             "column rank: every control input must be weighted in z")
        self.n, self.p = n, p
        if self.discrete:
            Ct = np.swapaxes(self.C, 1, 2)
            self.Q, self.S = Ct @ self.C, Ct @ self.D
            self.R0 = np.swapaxes(self.D, 1, 2) @ self.D
        else:
            self.Q, self.S, self.R0 = P.C.T @ P.C, P.C.T @ P.D, P.D.T @ P.D
        self.Ew = np.diag(np.r_[np.ones(nw), np.zeros(P.ninputs - nw)])

    def solve(self, gamma):
        """``(X, K)`` at the level γ, or None when it is not achievable."""
        self.ntrials += 1
        try:
            with warnings.catch_warnings(), np.errstate(all='ignore'):
                warnings.simplefilter('ignore')
                return self._discrete(gamma) if self.discrete else self._continuous(gamma)
        except (ValueError, np.linalg.LinAlgError):
            return None

    def _continuous(self, gamma):
        P, nw = self.P, self.nw
        R = self.R0 - gamma ** 2 * self.Ew
        X, _, G, _ = _care_solution(P.A, P.B, self.Q, R, self.S, P.period, self.nsteps,
                                    definite=False)
        # X ⪰ 0 at every step boundary: a solution that escapes through
        # infinity inside the period (U(t) singular) changes sign there
        samples = X.function.Xg if isinstance(X.function, _RiccatiSolution) else [X(0.0)]
        if not all(_psd(x) for x in samples):
            return None
        if G.is_constant:
            K = PeriodicMatrix.constant(G(0.0)[nw:], P.period)
        else:
            G.function._build()
            K = G[nw:, :]
        return X, K

    def _discrete(self, gamma):
        nw = self.nw
        A, B = self.A, self.B
        R = self.R0 - gamma ** 2 * self.Ew
        X, _, _ = _dare_solution(A, B, self.Q, R, self.S)
        if not all(_psd(x) for x in X):
            return None
        Xn = np.roll(X, -1, axis=0)
        B1, B2 = B[:, :, :nw], B[:, :, nw:]
        B1t, B2t = np.swapaxes(B1, 1, 2), np.swapaxes(B2, 1, 2)
        W = gamma ** 2 * np.eye(nw) - B1t @ Xn @ B1
        if np.linalg.eigvalsh(0.5 * (W + np.swapaxes(W, 1, 2))).min() <= 0:
            return None
        Xt = Xn + Xn @ B1 @ np.linalg.solve(W, B1t @ Xn)
        Ru = self.R0[:, nw:, nw:]
        K = np.linalg.solve(Ru + B2t @ Xt @ B2, B2t @ Xt @ A + np.swapaxes(self.S[:, :, nw:], 1, 2))
        if np.all(K == K[0]):
            return X, PeriodicMatrix.constant(K[0], self.P.period)
        return X, PeriodicMatrix.from_samples(K, self.P.period, kind='hold')

    def closed_loop(self, K):
        P, nw = self.P, self.nw
        B1, B2 = P.B[:, :nw], P.B[:, nw:]
        D12 = P.D[:, nw:]
        Acl, Ccl = P.A - B2 @ K, P.C - D12 @ K
        if self.discrete:
            N = P.nsteps
            return ltpss(Acl.sample(N), B1.sample(N), Ccl.sample(N),
                         np.zeros((N, self.p, nw)), period=P.period, dt=P.dt)
        return ltpss(Acl, B1, Ccl, np.zeros((self.p, nw)), period=P.period)

    def result(self, gamma, sol, lower):
        X, K = sol
        loop = self.closed_loop(K)
        mult = floquet_multipliers(loop)
        stable = bool(np.all(np.abs(mult) < 1))
        norm = np.inf
        if stable:
            # the certified upper bound of the L∞ bisection; sharpened when it
            # does not settle the comparison with γ
            for rtol in _NORM_TOLS:
                with warnings.catch_warnings():
                    warnings.simplefilter('ignore')
                    norm = float(linf_norm(loop, 'inf', tol=rtol, print_warning=False))
                if norm <= gamma:
                    break
        if not stable:
            success, message = False, ("the Riccati solution passed the tests but the loop is "
                                       f"not stable (largest |mu| = {np.abs(mult).max():.6g}); "
                                       "the gain is not stabilizing")
        elif norm > gamma * (1 + _NORM_SLACK):
            success, message = False, (f"the closed-loop H∞ norm {norm:.6g} exceeds the level "
                                       f"{gamma:.6g} (numerical trouble near the optimum; "
                                       "try a larger gamma or tol)")
        else:
            success, message = True, (f"level {gamma:.6g} achieved: closed-loop H∞ norm "
                                      f"{norm:.6g}")
        return K, HinfStateFeedbackResult(success, message, float(gamma), float(lower),
                                          float(norm), mult, X, loop, self.ntrials)


def _bisection(problem, tol):
    g = 1.0
    sol = problem.solve(g)
    lo, hi, best = None, None, None
    if sol is not None:                       # halve until not achievable
        hi, best = g, sol
        while g > 1 / _GAMMA_RANGE:
            g /= 2
            sol = problem.solve(g)
            if sol is None:
                lo = g
                break
            hi, best = g, sol
        else:
            return problem.result(hi, best, 0.0)
    else:                                     # double until achievable
        lo = g
        while g < _GAMMA_RANGE:
            g *= 2
            sol = problem.solve(g)
            if sol is not None:
                hi, best = g, sol
                break
            lo = g
        else:
            return None, _failure(problem, f"no level up to {_GAMMA_RANGE:.0e} is achievable: "
                                  "the plant is not stabilizable by state feedback (or "
                                  "an uncontrollable mode is on the stability boundary)", np.inf)
    while hi / lo > 1 + tol:
        g = np.sqrt(lo * hi)
        sol = problem.solve(g)
        if sol is None:
            lo = g
        else:
            hi, best = g, sol
    return problem.result(hi, best, lo)


def _failure(problem, message, lower):
    return HinfStateFeedbackResult(False, message, np.inf, lower, np.nan,
                                   np.array([], complex), None, None, problem.ntrials)


def _psd(X):
    X = 0.5 * (X + X.T)
    return bool(np.linalg.eigvalsh(X).min() >= -1e-10 * max(1.0, np.abs(X).max()))
