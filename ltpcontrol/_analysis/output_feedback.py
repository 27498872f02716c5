"""Periodic static output feedback: stabilization and LQ-optimal gains.

The plant ``ẋ = A(t)x + B(t)u``, ``y = C(t)x + D(t)u`` (discrete time
``x_{k+1} = A_kx_k + B_ku_k``) is closed by ``u = -K(t) y``.  With
``F = (I + KD)⁻¹K`` the loop is ``u = -F C x`` whatever D, so the design
variable is F and the implemented gain is ``K = (I - FD)⁻¹F`` (K = F when
D = 0).  F is one of two periodic families with parameters ``F_i`` (m x p):

* switching: ``F(t) = F_i`` for ``t_i <= t mod T < t_{i+1}`` on a given
  partition ``0 = t_0 < ... < t_{s-1} < T`` (discrete: step boundaries);
* harmonic of order q: ``F(t) = F_0 + Σ_{j=1}^q (F_{2j-1} cos jω_pt +
  F_{2j} sin jω_pt)`` (discrete: ``t = k dt``).

Closed loop ``A_c = A - BFC``, weight ``Q_c = Q + CᵀFᵀRFC``.

**LQ cost** (`oflqr`): ``J = E ∫_0^∞ (xᵀQx + uᵀRu) dt = tr(P(0) X_0)``
for ``E[x(0)x(0)ᵀ] = X_0``, P the periodic solution of the adjoint
Lyapunov equation ``-Ṗ = A_cᵀP + PA_c + Q_c`` (discrete ``P_k =
A_{c,k}ᵀP_{k+1}A_{c,k} + Q_{c,k}``).  Its exact gradient uses the
period-folded state covariance ``Y(t) = Σ_{j>=0} E[x(t + jT)x(t + jT)ᵀ]``,
the periodic solution of ``Ẏ = A_cY + YA_cᵀ`` with the jump
``Y(0⁺) = Y(T⁻) + X_0`` (discrete ``Y_{k+1} = A_{c,k}Y_kA_{c,k}ᵀ + X_0``
at ``k + 1 ≡ 0``):

    ∂J/∂F(t) = 2 (R F C - Bᵀ P) Y Cᵀ           (continuous, pointwise)
    ∂J/∂F_k  = 2 (R_k F_k C_k - B_kᵀ P_{k+1} A_{c,k}) Y_k C_kᵀ   (discrete)

and ``∂J/∂F_i = ∫_0^T φ_i(t) ∂J/∂F(t) dt`` (sum over k).  Both Lyapunov
equations are solved on the step grid by the cyclic solver of
`ltpcontrol.lyap`; inside the steps P and Y are propagated exactly to
Gauss–Legendre nodes (so the gradient is exact to quadrature accuracy).

**Stabilization** (`ofstab`) minimizes ``f = log|μ_max|``, μ_max the
dominant closed-loop multiplier of the monodromy ``Ψ``, i.e. the spectral
abscissa ``f/T`` of the Floquet exponents (discrete: the per-step spectral
radius ``e^{f/N}``).  For a simple μ with right and left eigenvectors u, v,
``dμ = vᴴ dΨ u / (vᴴu)`` and ``dΨ = -∫ Φ(T, t) B δF C Φ(t, 0) dt`` (a sum
over steps in discrete time) give the gradient.  The function is not
smooth where dominant multipliers of different moduli cross; BFGS copes in
practice, and the result is judged only by the closed-loop multipliers.

**Verification.** Whatever the optimizer says, the returned gain K is
closed around the plant with `ltpcontrol.feedback` and the multipliers of
that loop are computed independently (`floquet_multipliers`); `success`
requires all of them strictly inside the unit circle.
"""

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as la
from scipy.optimize import minimize
from control.exception import ControlArgument, ControlDimension

from .._core.coerce import as_ltp
from .._core.floquet import _log_multipliers, floquet_multipliers
from .._core.ltpsys import feedback
from .._core.periodic_matrix import PeriodicMatrix, as_periodic
from .._core.steps import step_grid, step_integrals
from .._core.validation import real_array
from .design import dlqr
from .lyapunov import cyclic_lyap
from .output_feedback_basis import Basis as _Basis
from .output_feedback_inputs import _check_weights, _covariance, _is_zero, _per_step, _surrogate
from .output_feedback_lq import DiscreteLQ, _minimize_lq, _stabilize_lq

__all__ = ['ofstab', 'oflqr', 'OutputFeedbackResult']

# Gauss–Legendre nodes per step of the continuous-time gradient quadrature
_GAUSS = 6
# log|μ_max| a stabilizing start for the LQ phase must reach
_STAB_TARGET = -1e-3


@dataclass
class OutputFeedbackResult:
    """Result of `ofstab` and `oflqr`.

    Attributes
    ----------
    success : bool
        True when the returned gain stabilizes the plant, checked on the
        loop ``feedback(sys, K)`` by independently computed multipliers
        (and, for `oflqr`, the optimizer converged).
    message : str
        What happened (the optimizer's message, or why the design failed).
    cost : float
        LQ cost ``tr(P(0) X_0)`` (`oflqr`; inf when not stabilizing, nan
        for `ofstab`).
    sdeg : float
        Stability degree of the loop: largest real part of the Floquet
        exponents (continuous time) or largest per-step multiplier modulus
        ``|μ|^{1/N}`` (discrete time), from `multipliers`.
    multipliers : ndarray of complex
        Closed-loop Floquet multipliers of ``feedback(sys, K)``.
    params : ndarray, shape (s, m, p)
        The parameters ``F_i`` of the gain family (module notes).
    gradient : ndarray, shape (s, m, p)
        Gradient of the objective at `params`.
    nit : int
        Optimizer iterations (all phases).

    Examples
    --------
    >>> sysd = ltp.ltpss(np.array([[[1.5]], [[0.9]]]), [[1.0]], [[1.0]], 0,
    ...                  period=2.0, dt=1.0)
    >>> K, info = ltp.oflqr(sysd, [[1.0]], [[1.0]], times=[0.0, 1.0])
    >>> info.success, info.params.shape, bool(np.all(np.abs(info.multipliers) < 1))
    (True, (2, 1, 1), True)
    """

    success: bool
    message: str
    cost: float
    sdeg: float
    multipliers: np.ndarray
    params: np.ndarray
    gradient: np.ndarray
    nit: int


def ofstab(sys, *, times=None, order=None, K0=None, target=None, maxiter=100, gtol=1e-8,
           nsteps=None):
    """Periodic static output-feedback stabilization ``u = -K(t) y``.

    Minimizes the dominant closed-loop multiplier's modulus (the spectral
    abscissa of the Floquet exponents; discrete time the spectral radius)
    over a switching or harmonic gain, with exact gradients (module notes).

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous- or discrete-time plant with m inputs and p outputs.
    times : array_like, optional
        Switching gain: the instants ``0 = t_0 < t_1 < ... < T`` where the
        gain switches (discrete time: multiples of dt).  Default ``[0]``,
        a constant gain.
    order : int, optional
        Harmonic gain of this order instead (2 order + 1 parameter
        matrices).  Give `times` or `order`, not both.
    K0 : array_like, optional
        Initial parameters ``F_i``, shape (s, m, p) or (m, p) (the same for
        all); zero by default (for a discrete plant that the homotopy
        from zero does not stabilize, then the projected periodic LQR gain
        ``K_k C_k⁺`` of smallest multiplier over a log-spaced scale).
    target : float, optional
        Stop as soon as the stability degree (`OutputFeedbackResult.sdeg`)
        is below this value; by default it is minimized as far as the
        optimizer gets.
    maxiter : int, optional
        Iterations of the optimizer (BFGS).
    gtol : float, optional
        Gradient tolerance of the optimizer.
    nsteps : int, optional
        Continuous time: steps of the period grid (see `lyap`).

    Returns
    -------
    K : PeriodicMatrix or None
        Gain (m, p) for ``u = -K y``: switching, a Fourier series (D = 0),
        or held samples (discrete time); None (with ``success=False``) when
        the loop gain found needs an unbounded K (``I - F(t)D(t)`` singular).
    info : OutputFeedbackResult
        `success` only if the loop ``feedback(sys, K)`` is verified stable.

    Raises
    ------
    ValueError
        If `times` does not partition the period or is off the sample grid,
        `order` is negative or too large for the samples of a period.
    ControlDimension
        If `K0` has the wrong shape.

    Examples
    --------
    A constant output gain cannot stabilize this plant (Bittanti and
    Colaneri's chocolate example with D = 0, sampled 8 times per period); a
    gain that switches once per period does:

    >>> d = 0.9
    >>> plant = ltp.sample_system(ltp.ltpss([[0, 1], [-1, 2 * d]], [[0], [1]],
    ...                                     [[-2, 2 * d]], 0, period=2.0), 0.25)
    >>> K, info = ltp.ofstab(plant, times=[0.0, 1.0], target=0.95)
    >>> info.success, bool(info.sdeg < 0.95)
    (True, True)
    """
    prob = _problem(sys, times, order, None, None, None, nsteps)
    goal = None
    if target is not None:
        if not np.isfinite(target) or (prob.discrete and target <= 0):
            raise ValueError(f"target must be a finite number (positive in discrete time), "
                             f"got {target!r}")
        goal = target * sys.nsteps if prob.discrete else target * sys.period
        goal = np.log(target) * sys.nsteps if prob.discrete else goal
    theta, nit, message = _stabilize(prob, prob.initial(K0), maxiter, gtol, goal)
    return prob.result(theta, nit, message, objective='stab')


def oflqr(sys, Q, R, *, X0=None, times=None, order=None, K0=None, maxiter=500, gtol=1e-8,
          nsteps=None):
    """Periodic LQ-optimal static output feedback ``u = -K(t) y``.

    Minimizes ``J = E ∫_0^∞ (xᵀQx + uᵀRu) dt`` (discrete time the sum over
    k) from an initial state of covariance X0 at t = 0, over a switching or
    harmonic gain, with exact gradients from periodic Lyapunov adjoints
    (module notes).  A non-stabilizing start is first stabilized by
    `ofstab`'s objective; without `K0`, a switching or harmonic family
    starts from the best constant gain when that one stabilizes.  Discrete
    time, BFGS works in variables whitened by the Levine–Athans curvature
    and a trust-region Newton step with the exact Hessian finishes.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous- or discrete-time plant with m inputs and p outputs.
    Q, R : array_like, PeriodicMatrix or callable
        State and input weights (n, n) and (m, m); Q ⪰ 0, R ≻ 0 (discrete
        time also one matrix per step, shape (N, ., .)).
    X0 : array_like, optional
        Covariance of the initial state (n, n); identity by default.
    times, order, K0
        As in `ofstab`.  A discrete plant that the homotopy from zero does
        not stabilize is restarted from the projected periodic LQR gain
        ``K_k C_k⁺`` of smallest closed-loop multiplier over a log-spaced
        scale.
    maxiter : int, optional
        Iterations of each phase (stabilization, BFGS; discrete time also
        at most ``min(100, maxiter)`` Newton steps after each BFGS stage,
        then trust-region Newton rounds along negative curvature when both
        stall).
    gtol : float, optional
        Discrete time: relative tolerance of the Newton decrement
        ``gᵀH⁻¹g <= gtol·J`` (exact Hessian H, positive definite: a
        certified local minimum), or of the gradient whitened by the
        Levine–Athans curvature Ĥ, ``gᵀĤ⁻¹g <= gtol·J`` (a stationary
        point, reported as such); continuous time: BFGS gradient tolerance.
    nsteps
        As in `ofstab`.

    Returns
    -------
    K : PeriodicMatrix
        Gain (m, p) for ``u = -K y``.
    info : OutputFeedbackResult
        `cost` is the optimal J; `success` requires a verified stable loop
        and a converged optimizer.

    Examples
    --------
    With the whole state measured, a gain that switches at every step of a
    discrete plant reaches the periodic LQR cost ``tr(X_0 P_0)`` of `dlqr`:

    >>> A = np.array([[[1.1, 0.2], [0.0, 0.9]], [[0.7, 0.0], [0.3, 1.2]]])
    >>> sysd = ltp.ltpss(A, [[0.0], [1.0]], np.eye(2), 0, period=2.0, dt=1.0)
    >>> K, info = ltp.oflqr(sysd, np.eye(2), [[1.0]], times=[0.0, 1.0])
    >>> Kd, X, _ = ltp.dlqr(sysd, np.eye(2), [[1.0]])
    >>> bool(abs(info.cost - np.trace(X(0.0))) < 1e-6 * info.cost)
    True
    """
    return _oflqr(sys, Q, R, X0, times, order, K0, maxiter, gtol, nsteps, seed=True)


def _oflqr(sys, Q, R, X0, times, order, K0, maxiter, gtol, nsteps, seed):
    prob = _problem(sys, times, order, Q, R, X0, nsteps)
    theta = prob.initial(K0)
    nit, message = 0, ''
    if K0 is None and prob.basis.size > 1:
        # warm start: the best constant gain, when the homotopy from zero
        # finds one (the family's own homotopy is tried before any seed)
        _, const = _oflqr(sys, Q, R, X0, None, None, None, maxiter, gtol, nsteps, seed=False)
        nit = const.nit
        if np.isfinite(const.cost):
            theta = prob.basis.lift(const.params[0]).ravel()
    if not prob.log_radius(theta) < _STAB_TARGET:
        theta, k, message = _stabilize(prob, theta, maxiter, gtol, _STAB_TARGET, seed=seed)
        nit += k
        if not prob.log_radius(theta) < 0:
            return prob.result(theta, nit, "no stabilizing gain found in the family: "
                               + message, objective='lq')
    if prob.discrete:
        theta, nit2, converged, message = _minimize_lq(prob.lq, theta, maxiter, gtol)
        message = message if converged else message + ' (not converged)'
    else:
        theta, nit2, message = _minimize(prob.lq_objective, theta, maxiter, gtol)
    return prob.result(theta, nit + nit2, message, objective='lq')


#
# Optimization
#

class _Stop(Exception):
    pass


def _stabilize(prob, theta, maxiter, gtol, target, rounds=8, seed=True):
    """Lower the dominant multiplier by a homotopy on the shift α (module notes):
    minimize the smooth shifted cost with α just above ``log|μ_max|``, then
    lower α; finish with BFGS on ``log|μ_max|`` itself.  Stops early once
    ``log|μ_max| < target`` (when given).  Discrete plants use whitened
    variables and the LQ weights (`output_feedback_lq._stabilize_lq`)."""
    if prob.discrete:
        theta, nit, message = _stabilize_discrete(prob, theta, maxiter, gtol, target)
        if seed and not prob.log_radius(theta) < 0 and not np.any(theta):
            # the homotopy from zero failed: restart from the best projected
            # state-feedback gain
            seed = _state_feedback_seed(prob)
            if seed is not None:
                seeded, k, message = _stabilize_discrete(prob, seed, maxiter, gtol, target)
                nit += k
                if prob.log_radius(seeded) < prob.log_radius(theta):
                    theta = seeded
        return theta, nit, message
    f = prob.log_radius(theta)
    nit, message = 0, ''
    for _ in range(rounds):
        if target is not None and f < target:
            return theta, nit, 'stabilized'
        prob.shift = f + max(0.1, 0.2 * abs(f))
        try:
            theta_new, k, message = _minimize(prob.lq_objective, theta, 20, gtol)
        finally:
            prob.shift = None
        nit += k
        f_new = prob.log_radius(theta_new)
        if not f_new < f - 1e-6 * max(1.0, abs(f)):
            break
        theta, f = theta_new, f_new
    theta_new, k, message = _minimize(prob.stab_objective, theta, maxiter, gtol,
                                      stop_below=target)
    nit += k
    if prob.log_radius(theta_new) <= f:
        theta = theta_new
    return theta, nit, message


def _minimize(fun, theta0, maxiter, gtol, stop_below=None):
    """BFGS on ``fun(θ) -> (f, g)``; keeps the best finite point; ``(θ, nit, message)``."""
    best = {'f': np.inf, 'x': theta0.copy(), 'calls': 0}

    def wrapped(x):
        best['calls'] += 1
        if best['calls'] > 3 * maxiter + 10:          # line searches stuck at a kink
            raise _Stop
        f, g = fun(x)
        if np.isfinite(f) and f < best['f']:
            best['f'], best['x'] = f, x.copy()
            if stop_below is not None and f < stop_below:
                raise _Stop
        if not np.isfinite(f):
            return 1e300, np.zeros_like(x)
        return f, g
    try:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', RuntimeWarning)
            res = minimize(wrapped, theta0, jac=True, method='BFGS',
                           options={'maxiter': maxiter, 'gtol': gtol})
        nit, message = int(res.nit), str(res.message)
        converged = bool(res.success) or 'precision loss' in message
    except _Stop:
        if best['calls'] > 3 * maxiter + 10:
            nit, message, converged = maxiter, 'evaluation budget exhausted', False
        else:
            nit, message, converged = 0, 'stabilized', True
    return best['x'], nit, message if converged else message + ' (not converged)'


#
# Problems
#

def _stabilize_discrete(prob, theta, maxiter, gtol, target):
    theta, f, nit = _stabilize_lq(prob.shifted_lq, theta, prob.log_radius,
                                 -np.inf if target is None else target, maxiter)
    if target is not None and f < target:
        return theta, nit, 'stabilized'
    theta_new, k, message = _minimize(prob.stab_objective, theta, maxiter, gtol,
                                      stop_below=target)
    if prob.log_radius(theta_new) <= f:
        theta = theta_new
    return theta, nit + k, message


def _state_feedback_seed(prob):
    """A start for discrete stabilization: the periodic LQR gains ``K_k`` (the
    problem's weights, else identities) at up to ten steps, projected on the
    outputs (``K_k C_k⁺``) and used as constant gains scaled by 10^-3..10^3;
    the one of smallest ``|μ_max|`` (parameters θ), None when dlqr fails."""
    n, m = prob.n, prob.m
    Q = prob.Q.mean(0) if hasattr(prob, 'Q') else np.eye(n)
    R = prob.R.mean(0) if hasattr(prob, 'R') else np.eye(m)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            Kd = dlqr(prob.sys, Q, R)[0]
    except (ValueError, ArithmeticError, np.linalg.LinAlgError, ControlArgument):
        return None
    N = prob.N
    steps = np.unique(np.linspace(0, N - 1, min(N, 10)).astype(int))
    Ks = np.asarray(Kd.sample(N), float).reshape(N, m, n)
    F0 = Ks[steps] @ np.linalg.pinv(prob.C[steps])                  # (k, m, p)
    F = (np.logspace(-3, 3, 25)[:, None, None, None] * F0).reshape(-1, m, prob.p)
    if not np.all(np.isfinite(F)):
        return None
    M = np.broadcast_to(np.eye(n), (F.shape[0], n, n))
    with np.errstate(all='ignore'):
        for k in range(N):
            M = (prob.A[k] - prob.B[k] @ F @ prob.C[k]) @ M
        r = np.abs(np.linalg.eigvals(np.nan_to_num(M, nan=1e300, posinf=1e300,
                                                   neginf=-1e300))).max(-1)
    best = F[int(np.argmin(r))]
    return prob.basis.lift(best).ravel()


def _problem(sys, times, order, Q, R, X0, nsteps):
    sys = as_ltp(sys)
    if sys.nstates == 0 or sys.ninputs == 0 or sys.noutputs == 0:
        raise ControlDimension("output feedback needs states, inputs and outputs, got "
                               f"n={sys.nstates}, m={sys.ninputs}, p={sys.noutputs}")
    basis = _Basis(sys, times, order)
    cls = _DiscreteProblem if sys.isdtime(strict=True) else _ContinuousProblem
    return cls(sys, basis, Q, R, X0, nsteps)


class _Problem:
    """Shared parts: parameters, result and verification.

    With ``shift = α`` (log per period) `lq_objective` is the smooth
    stabilization objective: the cost with Q = I, R = 0 of the loop whose
    multipliers are scaled by ``e^{-α}`` (finite iff ``log|μ_max| < α``).
    """

    shift = None

    def initial(self, K0):
        s, m, p = self.basis.size, self.m, self.p
        if K0 is None:
            return np.zeros(s * m * p)
        K0 = real_array(K0, 'K0', ndim=(2, 3))
        if K0.ndim == 2:
            K0 = np.broadcast_to(K0, (s,) + K0.shape)
        if K0.shape != (s, m, p):
            raise ControlDimension(f"K0 must have shape {(s, m, p)} or {(m, p)}, got "
                                   f"{K0.shape}")
        return K0.ravel().copy()

    def unpack(self, theta):
        return np.asarray(theta, float).reshape(self.basis.size, self.m, self.p)

    def log_radius(self, theta):
        return self.stab_objective(theta, gradient=False)[0]

    def result(self, theta, nit, message, objective):
        sys = self.sys
        params = self.unpack(theta)
        K = self.gain(params)
        if objective == 'lq':
            cost, grad = self.lq_objective(theta)
        else:
            (_, grad), cost = self.stab_objective(theta), np.nan
        mu, stable = np.full(sys.nstates, np.nan + 0j), False
        if K is not None:
            with warnings.catch_warnings():
                warnings.simplefilter('ignore')
                mu = floquet_multipliers(feedback(sys, K))
            stable = bool(np.all(np.abs(mu) < 1 - 1e-10))
        with np.errstate(divide='ignore'):
            logmax = float(np.log(np.abs(mu).max())) if np.all(np.isfinite(mu)) else np.inf
        sdeg = (float(np.exp(logmax / sys.nsteps)) if self.discrete
                else logmax / sys.period)
        if K is None:
            message = ("the gain K = (I - FD)⁻¹F is unbounded (I - F(t)D(t) singular at some "
                       "t): no bounded gain of this family realizes the loop")
        elif not stable:
            message = ("the closed loop is not stable (verified multipliers, max |mu| = "
                       f"{np.abs(mu).max():.6g}); " + message)
        success = stable and (objective == 'stab' or 'not converged' not in message)
        if objective == 'lq' and not stable:
            cost = np.inf
        return K, OutputFeedbackResult(success, message, float(cost), sdeg, mu, params,
                                       self.unpack(grad), nit)


class _ContinuousProblem(_Problem):
    discrete = False

    def __init__(self, sys, basis, Q, R, X0, nsteps):
        self.sys, self.basis = sys, basis
        T, n, m, p = sys.period, sys.nstates, sys.ninputs, sys.noutputs
        self.n, self.m, self.p = n, m, p
        self.A, self.B, self.C, self.D = sys.A, sys.B, sys.C, sys.D
        self.Q = None if Q is None else as_periodic(Q, T, 'Q', shape=(n, n))
        self.R = None if R is None else as_periodic(R, T, 'R', shape=(m, m))
        self.X0 = _covariance(X0, n)
        extra = [M for M in (self.B, self.C, self.Q, self.R) if M is not None]
        if basis.kind == 'switching':
            extra.append(PeriodicMatrix.switching([np.zeros((1, 1))] * basis.size,
                                                  basis.times, T))
        self.grid = step_grid(self.A, extra, nsteps)
        # fast vectorised surrogates of the data: Chebyshev interpolants on
        # every step (the data are smooth between the step boundaries)
        self.data = _surrogate([M for M in (self.A, self.B, self.C, self.Q, self.R)
                                if M is not None], self.grid)
        x, w = np.polynomial.legendre.leggauss(_GAUSS)
        t0, h = self.grid[:-1], np.diff(self.grid)
        self.nodes = (t0[:, None] + h[:, None] * (x + 1) / 2).ravel()
        self.weights = (h[:, None] * w / 2).ravel()
        self.step_of = np.repeat(np.arange(len(h)), _GAUSS)
        # sub-intervals t_k, τ_1, ..., τ_G, t_{k+1} of every step: one batch of
        # short transitions gives the step factors and the node values
        edges = np.concatenate([t0[:, None], self.nodes.reshape(len(h), _GAUSS),
                                self.grid[1:, None]], axis=1)
        self.sub_start, self.sub_len = edges[:, :-1].ravel(), np.diff(edges, axis=1).ravel()
        self.phi = basis.values(self.nodes)
        values = self.data(self.nodes)
        self.Bn, self.Cn = values[1], values[2]
        if self.R is not None:
            self.Rn = values[4]
        if self.Q is not None:
            probe = np.arange(16) * T / 16
            _check_weights(self.Q(probe), self.R(probe))

    def gain(self, params):
        F = self.basis.matrix(params)
        if _is_zero(self.D):
            return F

        def implemented(f, d):
            M = np.eye(self.m) - f @ d
            return np.linalg.solve(M, f)
        # K has a pole where det(I - FD) vanishes: look for a near-zero, or a
        # sign change between neighbouring probes of the same smooth piece
        # (a switching gain may jump across zero without passing through it)
        T = self.sys.period
        breaks = np.unique(np.mod(np.concatenate([F.breakpoints, self.D.breakpoints]), T))
        probe = np.union1d(np.arange(4096) * T / 4096, breaks)
        det = np.linalg.det(np.eye(self.m) - F(probe) @ self.D(probe))
        piece = np.searchsorted(breaks, probe + 1e-12 * T, side='right')
        same = piece[1:] == piece[:-1]
        if np.min(np.abs(det)) < 1e-8 or np.any(same & (np.sign(det[1:]) != np.sign(det[:-1]))):
            return None
        return PeriodicMatrix.pointwise(implemented, [F, self.D], (self.m, self.p),
                                        breakpoints=F.breakpoints)

    def _closed(self, params, weight=False):
        """Closed-loop A_c (and Q_c) as fast periodic matrices."""
        T, basis, data, n = self.sys.period, self.basis, self.data, self.n
        breaks = self.grid[:-1]

        alpha = 0.0 if self.shift is None else self.shift / T

        def ac(t):
            a, b, c = data(t)[:3]
            f = np.einsum('ki,iab->kab', basis.values(t), params)
            return a - b @ f @ c - alpha * np.eye(n)

        def qc(t):
            if self.shift is not None:               # stabilization: Q = I, R = 0
                return np.broadcast_to(np.eye(n), (len(np.atleast_1d(t)), n, n)).copy()
            _, _, c, q, r = data(t)
            fc = np.einsum('ki,iab->kab', basis.values(t), params) @ c
            return q + np.swapaxes(fc, 1, 2) @ r @ fc
        Ac = PeriodicMatrix.from_function(ac, T, (n, n), breakpoints=breaks, check=False)
        if not weight:
            return Ac
        return Ac, PeriodicMatrix.from_function(qc, T, (n, n), breakpoints=breaks, check=False)

    def _propagate(self, Ac, Qc=None):
        """Step factors Φ_k, adjoint integrals V_k, and at the nodes τ of step k:
        ``Φ(τ, t_k)``, ``Φ(t_{k+1}, τ)`` and ``V(τ, t_{k+1})`` (None without Qc)."""
        M, G, n = len(self.grid) - 1, _GAUSS, self.n
        Phi_s, _, V_s, _ = step_integrals(Ac, self.sub_start, self.sub_len, Qa=Qc)
        Phi_s = Phi_s.reshape(M, G + 1, n, n)
        fwd = np.empty((M, G + 1, n, n))             # Φ(τ_q, t_k), τ_0 = t_k
        fwd[:, 0] = np.eye(n)
        for q in range(G):
            fwd[:, q + 1] = Phi_s[:, q] @ fwd[:, q]
        Phi = Phi_s[:, G] @ fwd[:, G]
        bwd = np.empty((M, G + 2, n, n))             # Φ(t_{k+1}, τ_q), τ_{G+1} = t_{k+1}
        bwd[:, G + 1] = np.eye(n)
        for q in range(G, -1, -1):
            bwd[:, q] = bwd[:, q + 1] @ Phi_s[:, q]
        Vb = None
        if Qc is not None:
            V_s = V_s.reshape(M, G + 1, n, n)
            Vb = np.zeros((M, G + 2, n, n))          # V(τ_q, t_{k+1})
            for q in range(G, -1, -1):
                Vb[:, q] = V_s[:, q] + np.swapaxes(Phi_s[:, q], 1, 2) @ Vb[:, q + 1] @ Phi_s[:, q]
            Vb = Vb[:, :G + 1]
        return Phi, fwd[:, 1:].reshape(M * G, n, n), bwd[:, 1:G + 1].reshape(M * G, n, n), \
            (None if Vb is None else (Vb[:, 0], Vb[:, 1:].reshape(M * G, n, n)))

    def stab_objective(self, theta, gradient=True):
        params = self.unpack(theta)
        Ac = self._closed(params)
        Phi, Phi0, Phi1, _ = self._propagate(Ac)
        logmod, _ = _log_multipliers(None, None, grid=None, factors=Phi)
        f = float(logmod.max())
        if not gradient:
            return f, None
        # dominant eigenvector pair of the monodromy
        mono = np.eye(self.n)
        for P in Phi:
            mono = P @ mono
        mu, vl, vr = la.eig(mono, left=True, right=True)
        j = int(np.argmax(np.abs(mu)))
        u, v = vr[:, j], vl[:, j]                   # vᴴ mono = μ vᴴ
        scale = mu[j] * (v.conj() @ u)
        M = len(Phi)
        w = np.empty((M + 1, self.n), complex)      # Φ(t_k, 0) u
        w[0] = u
        for k in range(M):
            w[k + 1] = Phi[k] @ w[k]
        z = np.empty((M + 1, self.n), complex)      # (vᴴ Φ(T, t_k))ᵀ
        z[M] = v.conj()
        for k in range(M - 1, -1, -1):
            z[k] = Phi[k].T @ z[k + 1]
        k = self.step_of
        wn = np.einsum('kij,kj->ki', Phi0, w[k])
        zn = np.einsum('kji,kj->ki', Phi1, z[k + 1])   # (vᴴ Φ(T, τ))ᵀ
        # d log|μ| = Re(dμ/μ),  dμ = -∫ vᴴΦ(T, τ) B δF C Φ(τ, 0)u dτ / (vᴴu)
        Cw = np.einsum('kij,kj->ki', self.Cn, wn)
        zB = np.einsum('kj,kji->ki', zn, self.Bn)
        G = -np.real(np.einsum('ka,kb->kba', Cw, zB) / scale)           # (nodes, m, p)
        grad = np.einsum('k,ki,kab->iab', self.weights, self.phi, G)
        return f, grad.ravel()

    def lq_objective(self, theta):
        params = self.unpack(theta)
        Ac, Qc = self._closed(params, weight=True)
        Phi, Phi0, Phi1, (V, V1) = self._propagate(Ac, Qc)
        logmod, _ = _log_multipliers(None, None, grid=None, factors=Phi)
        if not logmod.max() < 0:
            return np.inf, np.zeros_like(theta)
        M = len(Phi)
        P = cyclic_lyap(Phi, V, adjoint=True, check=False)
        Wf = np.zeros_like(Phi)
        Wf[-1] = self.X0
        Y = cyclic_lyap(Phi, Wf, check=False)
        cost = float(np.trace(P[0] @ self.X0))
        k = self.step_of
        Pn = np.swapaxes(Phi1, 1, 2) @ P[(k + 1) % M] @ Phi1 + V1
        Yn = Phi0 @ Y[k] @ np.swapaxes(Phi0, 1, 2)
        Fn = np.einsum('ki,iab->kab', self.phi, params)
        RFC = 0.0 if self.shift is not None else self.Rn @ Fn @ self.Cn
        G = 2 * (RFC - np.swapaxes(self.Bn, 1, 2) @ Pn) @ Yn @ np.swapaxes(self.Cn, 1, 2)
        grad = np.einsum('k,ki,kab->iab', self.weights, self.phi, G)
        return cost, grad.ravel()


class _DiscreteProblem(_Problem):
    discrete = True

    def __init__(self, sys, basis, Q, R, X0, nsteps):
        if nsteps is not None:
            raise ControlArgument("nsteps applies to continuous-time systems only")
        self.sys, self.basis = sys, basis
        N, n, m, p = sys.nsteps, sys.nstates, sys.ninputs, sys.noutputs
        self.n, self.m, self.p, self.N = n, m, p, N
        self.A, self.B, self.C, self.D = (M.sample(N) for M in (sys.A, sys.B, sys.C, sys.D))
        self.X0 = _covariance(X0, n)
        self.phi = basis.values(np.arange(N) * sys.dt)
        if Q is not None:
            self.Q = _per_step(Q, sys, 'Q', (n, n))
            self.R = _per_step(R, sys, 'R', (m, m))
            _check_weights(self.Q, self.R)
            self.lq = DiscreteLQ(self.A, self.B, self.C, self.Q, self.R, self.X0, self.phi)

    def gain(self, params):
        F = np.einsum('ki,iab->kab', self.phi, params)
        if np.any(self.D):
            M = np.eye(self.m) - F @ self.D
            if np.min(np.abs(np.linalg.det(M))) < 1e-12:
                return None
            F = np.linalg.solve(M, F)
        return PeriodicMatrix.from_samples(F, self.sys.period, kind='hold')

    def _closed(self, params):
        F = np.einsum('ki,iab->kab', self.phi, params)
        return F, self.A - self.B @ F @ self.C

    def stab_objective(self, theta, gradient=True):
        params = self.unpack(theta)
        F, Ac = self._closed(params)
        logmod, _ = _log_multipliers(None, None, grid=None, factors=Ac)
        f = float(logmod.max())
        if not gradient:
            return f, None
        N = self.N
        mono = np.eye(self.n)
        for a in Ac:
            mono = a @ mono
        mu, vl, vr = la.eig(mono, left=True, right=True)
        j = int(np.argmax(np.abs(mu)))
        u, v = vr[:, j], vl[:, j]
        scale = mu[j] * (v.conj() @ u)
        w = np.empty((N + 1, self.n), complex)
        w[0] = u
        for k in range(N):
            w[k + 1] = Ac[k] @ w[k]
        z = np.empty((N + 1, self.n), complex)      # (vᴴ A_{N-1} ... A_k)ᵀ
        z[N] = v.conj()
        for k in range(N - 1, -1, -1):
            z[k] = Ac[k].T @ z[k + 1]
        Cw = np.einsum('kij,kj->ki', self.C, w[:N])
        zB = np.einsum('kj,kji->ki', z[1:], self.B)
        G = -np.real(np.einsum('ka,kb->kba', Cw, zB) / scale)
        return f, np.einsum('ki,kab->iab', self.phi, G).ravel()

    def lq_objective(self, theta):
        return self.lq(theta) if self.shift is None else self.shifted_lq(self.shift)(theta)

    def shifted_lq(self, alpha):
        """LQ cost of the loop scaled by ``e^{-α}`` per period (A and B scaled by
        ``e^{-α/N}``), with the design weights, or Q = I, R = 0 (`ofstab`)."""
        c = np.exp(-alpha / self.N)
        n, N = self.n, self.N
        Q = getattr(self, 'Q', None)
        if Q is None:
            Q, R = np.broadcast_to(np.eye(n), (N, n, n)), np.zeros((N, self.m, self.m))
        else:
            R = self.R
        return DiscreteLQ(c * self.A, c * self.B, self.C, Q, R, self.X0, self.phi)
