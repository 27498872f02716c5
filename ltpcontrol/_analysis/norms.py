"""System norms of LTP systems: H2, L∞ (induced L2 gain) and Hankel.

Conventions (see the Conventions page):

* H2 is the per-period average ``‖G‖₂² = (1/T) ∫₀ᵀ tr(Bᵀ X_o B) dt``
  (discrete ``(1/N) Σ_k tr(B_kᵀ X_o[k+1] B_k + D_kᵀ D_k)``), X_o the
  periodic observability gramian.  On the step grid (`_steps`) the integral
  is exact: ``∫_step tr(Bᵀ X_o B) = tr(X_o(t_{k+1}) W_k) + S_k`` with the
  Van Loan integrals ``W_k`` (of ``B Bᵀ``) and ``S_k`` (of ``Cᵀ C``).
* L∞ is the induced L2 gain, the supremum over ω of σ_max of the HTF.  γ
  exceeds it iff the periodic Hamiltonian

      H_γ = [[A + B R⁻¹DᵀC, B R⁻¹Bᵀ], [−Cᵀ(I + D R⁻¹Dᵀ)C, −(A + B R⁻¹DᵀC)ᵀ]],
      R = γ²I − DᵀD,

  has no Floquet multiplier on the unit circle; its multipliers come from
  the periodic Schur form of the per-step factors (never a formed
  monodromy).  Bisection on γ between certified bounds gives the norm to
  a relative tolerance; the unit-circle multipliers ``e^{jωT}`` just below
  the norm give the peak frequency.  Discrete time: the norm of the
  time-lifted LTI system (lifting is an isometry), by SLICOT AB13DD.
* Hankel: ``max_t sqrt(λ_max(P(t) Q(t)))`` over the period, the largest
  Hankel singular value over all start times.
"""

import warnings

import numpy as np
import control as ct
from scipy.optimize import minimize_scalar

from .._core.floquet import _log_multipliers
from .._frequency.harmonic_ss import _HarmonicStateSpace, _internal_order
from .._core.lifting import lift
from .lyapunov import cyclic_lyap, periodic_solution
from .._core.periodic_matrix import PeriodicMatrix
from .._core.steps import gram_weight, step_grid, step_integrals
from .._core.transition import step_transitions
from .._core.coerce import as_ltp
from .._core.validation import check_method
from .._core.tvsystem import DiscreteLTPSystem
from .tvdesign import tv_norm

__all__ = ['norm']

# |log|μ|| below which a Hamiltonian multiplier is on the unit circle
_UNIT = 1e-7


def norm(sys, p=2, tol=1e-6, print_warning=True, method=None, *,
         return_frequency=False, nsteps=None):
    """Input/output norm of an LTP system (python-control's `norm`).

    Parameters
    ----------
    sys : LTPStateSpace or DiscreteLTPSystem
        Continuous- or discrete-time LTP system (or a `DiscreteLTPSystem`).
    p : {2, 'inf', 'hankel'}
        2: the H2 norm, per-period average (Conventions page); 'inf': the
        L∞ norm (``sup_ω σ_max`` of the HTF; for a stable system the H∞
        norm, the induced L2 gain; for an unstable one the L∞ norm, as
        python-control returns; inf when a Floquet multiplier lies on the
        unit circle); 'hankel': the
        largest Hankel singular value over all start times in the period.
    tol : float, optional
        Relative accuracy of the L∞ norm (bisection between certified
        bounds); ignored for the other norms, which are exact.
    print_warning : bool, optional
        Warn when the H2 norm of an unstable system, or the L∞ norm of a
        system with a multiplier on the unit circle, is returned as inf (as
        python-control does), or the H2 norm of a continuous system
        with feedthrough.
    method : {None, 'slycot', 'scipy'}, optional
        python-control's choice of LTI solver, accepted so that the same
        call works; the periodic algorithm is always used.
    return_frequency : bool, optional
        L∞ only: also return the peak frequency in rad/s, folded into
        ``[0, ω_p/2]`` (the HTF at ω and ω + ω_p describes the same
        operator).  Discrete time: the lifted system's peak frequency,
        in ``[0, π/T]``.
    nsteps : int, optional
        Continuous time: uniform steps of the period grid (see `lyap`).

    Returns
    -------
    float, or (float, float) with `return_frequency`

    Raises
    ------
    ValueError
        For `p` outside the documented set, or an unstable system with
        ``p='hankel'``.

    Notes
    -----
    For an LTI system written as periodic the three norms equal
    ``ct.norm(G, 2)``, ``ct.norm(G, 'inf')`` and the largest of
    ``ct.hankel_singular_values(G)``.  ``ct.norm`` itself accepts only LTI
    systems; call `ltpcontrol.norm`.

    Examples
    --------
    >>> G = ct.tf([1], [1, 0.4, 1])
    >>> sys = ltp.ltpss(G, period=1.0)
    >>> bool(np.isclose(ltp.norm(sys, 2), ct.norm(G, 2)))
    True
    >>> bool(np.isclose(ltp.norm(sys, 'inf', tol=1e-9), ct.norm(G, 'inf', tol=1e-9)))
    True
    """
    if isinstance(sys, DiscreteLTPSystem):          # time-varying dimensions
        return tv_norm(sys, np.inf if p == 'inf' else p, tol)
    sys = as_ltp(sys)
    check_method(method)
    if isinstance(p, str) and p in ('inf', 'hankel'):
        pass
    elif not isinstance(p, (bool, np.bool_, str)) and isinstance(
            p, (int, np.integer, float, np.floating)) and p == 2:
        p = 2
    else:
        raise ValueError(f"p must be 2, 'inf' or 'hankel', got {p!r}")
    if not (isinstance(tol, (int, float, np.floating)) and 0 < tol < 1):
        raise ValueError(f"tol must be a number in (0, 1), got {tol!r}")
    if return_frequency and p != 'inf':
        raise ValueError("return_frequency applies to p='inf' only")
    if p == 'inf':
        # the L∞ norm (python-control's answer, also for unstable systems);
        # infinite when a multiplier lies on the unit circle (|μ| = 1 ± 1e-8)
        mu = np.abs(np.linalg.eigvals(sys.monodromy())) if sys.nstates else np.zeros(0)
        if np.any(np.isclose(mu, 1.0, rtol=0, atol=1e-8)):
            if print_warning:
                where = ("complex unit circle" if sys.isdtime() else "imaginary axis")
                warnings.warn(f"Poles close to, or on, the {where}.", UserWarning,
                              stacklevel=2)
            return (float('inf'), np.nan) if return_frequency else float('inf')
        value, freq = (_linf_discrete(sys, tol) if sys.isdtime()
                       else _linf_continuous(sys, tol, nsteps))
        return (value, freq) if return_frequency else value
    if p == 2:
        if not sys.is_stable():                  # python-control: inf, with a warning
            if print_warning:
                warnings.warn("System is unstable!", UserWarning, stacklevel=2)
            return float('inf')
        return _h2(sys, nsteps, print_warning)
    return _hankel(sys, nsteps)


#
# H2
#

def _h2(sys, nsteps, print_warning):
    if sys.isdtime():
        N = sys.nsteps
        A, B, C, D = (M.sample(N) for M in (sys.A, sys.B, sys.C, sys.D))
        _require_stable(A, 2)
        Xo = cyclic_lyap(A, np.swapaxes(C, 1, 2) @ C, adjoint=True, check=False)
        Bt = np.swapaxes(B, 1, 2)
        total = np.einsum('kij,kji->', Bt @ np.roll(Xo, -1, axis=0), B) + np.sum(D * D)
        return float(np.sqrt(max(total, 0.0) / N))
    if sys.nstates and _has_feedthrough(sys):
        if print_warning:
            warnings.warn("System has a direct feedthrough term!", UserWarning, stacklevel=3)
        return float('inf')
    if sys.nstates == 0:
        return 0.0
    grid = step_grid(sys.A, [sys.B, sys.C], nsteps)
    Phi, W, V, S = step_integrals(sys.A, grid[:-1], np.diff(grid),
                                  Qf=gram_weight(sys.B), Qa=gram_weight(sys.C, True))
    _require_stable(Phi, 2)
    Xo = cyclic_lyap(Phi, V, adjoint=True, check=False)
    total = np.einsum('kij,kji->', np.roll(Xo, -1, axis=0), W) + S.sum()
    return float(np.sqrt(max(total, 0.0) / sys.period))


def _require_stable(Phi, p):
    """Raise unless every multiplier of ``Φ_{M-1} ... Φ_0`` has ``|μ| < 1 - 1e-10``."""
    logmod, _ = _log_multipliers(None, None, grid=None, factors=Phi)
    if logmod.size and logmod.max() >= np.log1p(-1e-10):
        raise ValueError(f"norm(p={p!r}): the system is unstable; the "
                         f"{'H2' if p == 2 else 'Hankel'} norm needs a stable system")


def _has_feedthrough(sys):
    D = sys.D
    if D.is_constant:
        return bool(np.any(D(0.0) != 0))
    probe = np.concatenate([np.arange(64) * sys.period / 64, D.breakpoints])
    return bool(np.any(D(probe) != 0))


#
# Hankel
#

def _hankel(sys, nsteps):
    if sys.nstates == 0:
        return 0.0
    if sys.isdtime():
        N = sys.nsteps
        A, B, C = (M.sample(N) for M in (sys.A, sys.B, sys.C))
        _require_stable(A, 'hankel')
        P = cyclic_lyap(A, B @ np.swapaxes(B, 1, 2), check=False)
        Q = cyclic_lyap(A, np.swapaxes(C, 1, 2) @ C, adjoint=True, check=False)
        return float(np.sqrt(max(_lam_max(P, Q).max(), 0.0)))
    A = sys.A
    Qf, Qa = gram_weight(sys.B), gram_weight(sys.C, True)
    grid = step_grid(A, [sys.B, sys.C], nsteps)
    Phi, W, V, _ = step_integrals(A, grid[:-1], np.diff(grid), Qf=Qf, Qa=Qa)
    _require_stable(Phi, 'hankel')
    Pk, Qk = cyclic_lyap(Phi, W, check=False), cyclic_lyap(Phi, V, adjoint=True, check=False)
    P = periodic_solution(A, Qf, grid, Pk, False)
    Q = periodic_solution(A, Qa, grid, Qk, True)
    values = _lam_max(Pk, Qk)
    best = float(values.max())
    # refine the maximum of the smooth λ_max(P(t)Q(t)) around the best grid
    # points by successive zooming (its maximum may lie between grid points)
    for k in np.argsort(values)[::-1][:2]:
        lo, hi = grid[k] - (grid[k] - grid[k - 1] if k else grid[-1] - grid[-2]), grid[k + 1]
        for _ in range(8):
            ts = np.linspace(lo, hi, 9)
            vals = _lam_max(P(ts), Q(ts))
            j = int(np.argmax(vals))
            best = max(best, float(vals[j]))
            step = (hi - lo) / 8
            lo, hi = ts[j] - step, ts[j] + step
    return float(np.sqrt(max(best, 0.0)))


def _lam_max(P, Q):
    # eigenvalues of P Q are those of the symmetric L^T Q L, P = L L^T
    w, U = np.linalg.eigh(P)
    L = U * np.sqrt(np.maximum(w, 0.0))[..., None, :]
    return np.linalg.eigvalsh(np.swapaxes(L, -1, -2) @ Q @ L)[..., -1]


#
# L∞
#

def _linf_continuous(sys, tol, nsteps):
    T, n = sys.period, sys.nstates
    probe = np.concatenate([np.arange(64) * T / 64, sys.D.breakpoints])
    dmax = float(np.linalg.norm(sys.D(probe), ord=2, axis=(1, 2)).max(initial=0.0))
    if n == 0 or sys.ninputs == 0 or sys.noutputs == 0:
        return dmax, np.inf
    # estimate from the HTF, then certify: γ with unit-circle multipliers is a
    # lower bound (so is sup σ(D)), γ without them an upper bound
    gc, freq = _htf_peak(sys)
    values = _cached_values(sys)
    # steps short for the Hamiltonian near the norm (h ‖H_γ‖ <= 1)
    guess = max(gc, dmax * (1 + 1e-3), 1e-300)
    grid = step_grid(_hamiltonian(sys, guess, values), [sys.B, sys.C, sys.D], nsteps)

    def lower(gamma):
        # True (and the peak frequency) when γ is below the norm
        angles = _unit_circle_angles(sys, gamma, grid, values)
        return (False, None) if angles is None else (True, _peak(angles, T))

    lo, hi = dmax, np.inf
    for g in (gc * (1 + tol / 4), gc * (1 - tol / 4)):
        if lo < g < hi:
            below, w = lower(g)
            if below:
                lo, freq = g, w
            else:
                hi = g
    step = 1e-3
    while not np.isfinite(hi):                   # grow an upper bound
        g = max(lo, gc) * (1 + step)
        below, w = lower(g)
        if below:
            lo, freq = g, w
        else:
            hi = g
        step *= 4
    step = 1e-3
    while lo == dmax and hi * (1 - step) > dmax:  # certify a lower bound
        g = hi * (1 - step)
        below, w = lower(g)
        if below:
            lo, freq = g, w
        else:
            hi = g
        step = min(4 * step, 0.5)
    while hi - lo > tol * hi:                     # bisection
        mid = 0.5 * (lo + hi)
        below, w = lower(mid)
        if below:
            lo, freq = mid, w
        else:
            hi = mid
    return hi, freq


def _htf_peak(sys):
    """Largest σ_max of the HTF (4 harmonics) over ω ∈ [0, ω_p/2] and its ω."""
    w = sys.omega_p
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        # the harmonic state space of htf(sys, 4), without its checks (the
        # estimate needs no accuracy guarantee: the Hamiltonian certifies)
        H = _HarmonicStateSpace.continuous(sys, 4, _internal_order(sys, 4, None), 'auto')
        sigma = lambda x: np.linalg.norm(H.evaluate(1j * np.atleast_1d(x)), ord=2,
                                         axis=(1, 2))
        grid = np.linspace(0.0, w / 2, 257)
        try:
            vals = sigma(grid)
        except ValueError:                       # a pole on the imaginary axis
            return 0.0, np.nan
        k = int(np.argmax(vals))
        a, b = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
        res = minimize_scalar(lambda x: -sigma(x)[0], bounds=(a, b), method='bounded',
                              options={'xatol': 1e-12 * w})
    if -res.fun > vals[k]:
        return float(-res.fun), float(res.x)
    return float(vals[k]), float(grid[k])


def _cached_values(sys):
    """``t -> (A, B, C, D)(t)``, remembering the node sets of the bisection."""
    cache = {}

    def values(t):
        key = t.tobytes()
        if key not in cache:
            cache[key] = tuple(M._eval(t) for M in (sys.A, sys.B, sys.C, sys.D))
        return cache[key]
    return values


def _hamiltonian(sys, gamma, values):
    A, B, C, D, T = sys.A, sys.B, sys.C, sys.D, sys.period
    n, m = sys.nstates, sys.ninputs

    def H(t):
        a, b, c, d = values(np.atleast_1d(np.asarray(t, float)))
        bt, dt = np.swapaxes(b, 1, 2), np.swapaxes(d, 1, 2)
        R = gamma ** 2 * np.eye(m) - dt @ d
        RiBt = np.linalg.solve(R, bt)               # R⁻¹Bᵀ
        RiDtC = np.linalg.solve(R, dt @ c)          # R⁻¹DᵀC
        F = a + b @ RiDtC
        out = np.empty((len(a), 2 * n, 2 * n))
        out[:, :n, :n] = F
        out[:, :n, n:] = b @ RiBt
        # Cᵀ(I + D R⁻¹ Dᵀ)C
        out[:, n:, :n] = -np.swapaxes(c, 1, 2) @ (c + d @ RiDtC)
        out[:, n:, n:] = -np.swapaxes(F, 1, 2)
        return out
    breaks = np.concatenate([M.breakpoints for M in (A, B, C, D)])
    return PeriodicMatrix.from_function(H, T, (2 * n, 2 * n), breakpoints=breaks,
                                        check=False)


def _unit_circle_angles(sys, gamma, grid, values):
    """Angles of the unit-circle multipliers of H_γ, or None if there are none."""
    H = _hamiltonian(sys, gamma, values)
    if all(M.is_constant for M in (sys.A, sys.B, sys.C, sys.D)):
        # constant data: the multipliers are e^{λT}, λ the eigenvalues of H
        # (no product of stiff step factors needed)
        # (an eigenvalue on the axis is computed to about eps ‖H‖ off it;
        # counting one within 1e-11 ‖H‖ as on it can only raise the bound)
        Hc = H(0.0)
        lam = np.linalg.eigvals(Hc)
        near = np.abs(lam.real) <= 1e-11 * np.linalg.norm(Hc, 1)
        lam = np.where(near, 1j * lam.imag, lam) * sys.period
        logmod, arg = lam.real, np.angle(np.exp(1j * lam.imag))
    else:
        # the test needs the multipliers' moduli to well below _UNIT only
        Phi, _, _ = step_transitions(H, None, grid[:-1], np.diff(grid), rtol=1e-9)
        logmod, arg = _log_multipliers(None, None, grid=grid, factors=Phi)
    on = np.abs(logmod) < _UNIT
    return arg[on] if np.any(on) else None


def _peak(angles, T):
    # the unit-circle multipliers e^{±jωT} close in on the peak as γ grows
    a = np.sort(np.abs(angles))
    if len(a) >= 2:
        j = int(np.argmin(np.diff(a)))
        return float(0.5 * (a[j] + a[j + 1]) / T)
    return float(a[0] / T)


def _linf_discrete(sys, tol):
    value, freq = ct.linfnorm(lift(sys, method='time'), tol)
    return float(value), float(freq)
