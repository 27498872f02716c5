"""Convex (LMI) state-feedback design for discrete-time periodic systems.

Plant ``x_{k+1} = A_kx_k + B_ku_k + G_kw_k`` with the performance output
``z_k = C_kx_k + D_ku_k``, ``C_k = [Q_k^{1/2}; 0]``, ``D_k = [0; R_k^{1/2}]``
(so that ``‖z‖² = Σ xᵀQx + uᵀRu``) and the periodic gain ``u_k = -K_kx_k``.
With the periodic matrices ``P_k ≻ 0`` and ``Y_k = K_kP_k`` (indices
modulo N) the closed-loop conditions are linear:

* decay rate ρ (``‖x_k‖ ≤ c ρ^k``, multipliers ``|μ| ≤ ρ^N``):
  ``[[ρ²P_{k+1}, A_kP_k - B_kY_k], [⋆, P_k]] ⪰ 0``;
* H2 (per-period average, see the Conventions page): ``P_k`` bounds the
  closed-loop controllability gramian,
  ``[[P_{k+1} - G_kG_kᵀ, A_kP_k - B_kY_k], [⋆, P_k]] ⪰ 0``,
  ``[[W_k, C_kP_k + D_kY_k], [⋆, P_k]] ⪰ 0``, minimize ``(1/N) Σ tr W_k``
  (the bound is its square root);
* H∞ (the ℓ2 gain from w to z; periodic bounded real lemma)
  ``[[P_{k+1}, A_kP_k - B_kY_k, G_k, 0], [⋆, P_k, 0, (C_kP_k + D_kY_k)ᵀ],
  [⋆, ⋆, γI, 0], [⋆, ⋆, ⋆, γI]] ⪰ 0``, minimize γ.

The gain is recovered as ``K_k = Y_kP_k⁻¹``.  After the solve, the
constraints are re-evaluated with the recovered numbers: a violation beyond
the solver tolerance is reported in the status and by a warning, and an
infeasible problem raises, so no failure is returned unflagged.
"""

import warnings
from dataclasses import dataclass

import numpy as np
from control.exception import ControlArgument

from .._core.floquet import _log_multipliers
from .._core.periodic_matrix import PeriodicMatrix
from .._core.coerce import as_ltp

__all__ = ['lmi_statefbk', 'LMIDesign']

# constraint violation (relative) accepted as solver round-off
_VIOLATION_TOL = 1e-6


@dataclass
class LMIDesign:
    """Result of `lmi_statefbk`.

    Attributes
    ----------
    K : PeriodicMatrix
        State-feedback gain ``u_k = -K_k x_k`` (held samples).
    bound : float
        Certified bound: the H2 or H∞ norm bound, or the decay rate ρ.
    certificate : ndarray, shape (N, n, n)
        The periodic matrices ``P_k`` of the LMIs (module notes); for the
        decay rate ``V_k(x) = xᵀP_k⁻¹x`` is a periodic Lyapunov function
        with ``V_{k+1} ≤ ρ² V_k``.
    status : str
        cvxpy status of the (last) solve, with ' (constraints violated by
        ...)' appended when the re-evaluated constraints fail.
    solver : str
        Solver used.
    objective : str
        'h2', 'hinf' or 'decay'.
    multipliers : ndarray of complex
        Closed-loop Floquet multipliers.

    Examples
    --------
    >>> sysd = ltp.ltpss(np.array([[[1.1]], [[0.9]]]), [[1.0]], [[1.0]], 0,
    ...                  period=2.0, dt=1.0)
    >>> res = ltp.lmi_statefbk(sysd, objective='h2')
    >>> res.objective, res.certificate.shape, res.K.shape
    ('h2', (2, 1, 1), (1, 1))
    """

    K: PeriodicMatrix
    bound: float
    certificate: np.ndarray
    status: str
    solver: str
    objective: str
    multipliers: np.ndarray


def lmi_statefbk(sysd, Q=None, R=None, *, objective='h2', G=None, rate=None, solver=None):
    """Periodic state feedback by convex optimization (LMIs, cvxpy).

    Parameters
    ----------
    sysd : LTPStateSpace
        Discrete-time plant (A, B are used).  Sample a continuous-time plant
        with `ltpcontrol.sample_system` first.
    Q, R : array_like, optional
        State and input weights of the performance output (2D, or one
        matrix per step, shape (N, ., .)); identity by default.  Q ⪰ 0,
        R ≻ 0.
    objective : {'h2', 'hinf', 'decay'}
        Minimize the H2 or H∞ norm from the disturbance w to z, or the decay
        rate (module notes).
    G : array_like, optional
        Disturbance input matrix (2D or per step); identity by default.
    rate : float, optional
        For 'decay': the rate ρ in (0, 1] to certify (feasibility problem).
        When omitted the smallest certifiable ρ is found by bisection.
    solver : str, optional
        cvxpy solver name; default 'CLARABEL' (installed with cvxpy), else
        'SCS'.

    Returns
    -------
    LMIDesign

    Raises
    ------
    ValueError
        If the LMIs are infeasible (plant not stabilizable, or `rate` too
        small), a weight has the wrong shape or sign, or `objective` is
        unknown.
    ControlArgument
        If `sysd` is not a discrete-time `LTPStateSpace`.

    Notes
    -----
    In the H2 case the optimal gain is the periodic LQR gain of `dlqr`
    with the same Q and R (for any G with ``G_kG_kᵀ ≻ 0``), and the optimal
    bound is ``sqrt((1/N) Σ_k tr(G_kᵀ X_{k+1} G_k))``; the LMI route adds
    constraints that Riccati equations cannot (e.g. a decay rate).

    Examples
    --------
    >>> A = np.array([[[1.2, 0.3], [0.0, 0.5]], [[0.8, 0.0], [0.4, 1.1]]])
    >>> B = np.array([[[0.0], [1.0]], [[1.0], [0.0]]])
    >>> sysd = ltp.ltpss(A, B, np.eye(2), 0, period=2.0, dt=1.0)
    >>> res = ltp.lmi_statefbk(sysd, objective='decay', rate=0.9)
    >>> res.status, bool(np.all(np.abs(res.multipliers) <= 0.9 ** 2))
    ('optimal', True)
    """
    import cvxpy as cp
    if not as_ltp(sysd, 'sysd').isdtime(strict=True):
        raise ControlArgument("sysd must be a discrete-time LTPStateSpace (sample a "
                              "continuous-time plant with sample_system)")
    if objective not in ('h2', 'hinf', 'decay'):
        raise ValueError(f"objective must be 'h2', 'hinf' or 'decay', got {objective!r}")
    N, n, m = sysd.nsteps, sysd.nstates, sysd.ninputs
    A, B = sysd.A.sample(N), sysd.B.sample(N)
    Qh = _sqrt_psd(_per_step(np.eye(n) if Q is None else Q, N, (n, n), 'Q'), 'Q', strict=False)
    Rh = _sqrt_psd(_per_step(np.eye(m) if R is None else R, N, (m, m), 'R'), 'R', strict=True)
    Gw = _per_step(np.eye(n) if G is None else G, N, None, 'G')
    if Gw.shape[1] != n:
        raise ValueError(f"G must have {n} rows, got shape {Gw.shape[1:]}")
    C = np.concatenate([Qh, np.zeros((N, m, n))], axis=1)
    D = np.concatenate([np.zeros((N, n, m)), Rh], axis=1)
    if solver is None:
        solver = 'CLARABEL' if 'CLARABEL' in cp.installed_solvers() else 'SCS'
    data = dict(A=A, B=B, C=C, D=D, G=Gw)
    if objective == 'decay' and rate is None:
        return _bisect_rate(data, solver, sysd)
    if objective == 'decay':
        if not 0 < rate <= 1:
            raise ValueError(f"rate must be in (0, 1], got {rate!r}")
        problem, P, Y, bound = _problem(cp, data, 'decay', rate)
    else:
        problem, P, Y, bound = _problem(cp, data, objective, None)
    status = _solve(problem, solver)
    if status in ('infeasible', 'infeasible_inaccurate', 'unbounded', 'solver_error'):
        raise ValueError(f"the LMIs are infeasible (status {status!r}): "
                         + ("no gain certifies this rate" if objective == 'decay'
                            else "the plant is not stabilizable"))
    return _result(problem, P, Y, bound, data, objective, rate, solver, sysd)


def _problem(cp, data, objective, rate):
    A, B, C, D, G = (data[k] for k in 'ABCDG')
    N, n, m = B.shape
    P = [cp.Variable((n, n), symmetric=True) for _ in range(N)]
    Y = [cp.Variable((m, n)) for _ in range(N)]
    cons = []
    cost = 0
    gamma = cp.Variable(nonneg=True) if objective == 'hinf' else None
    for k in range(N):
        k1 = (k + 1) % N
        AP = A[k] @ P[k] - B[k] @ Y[k]
        CP = C[k] @ P[k] + D[k] @ Y[k]
        if objective == 'decay':
            cons += [P[k] >> np.eye(n),
                     _sym(cp, [[rate ** 2 * P[k1], AP], [AP.T, P[k]]]) >> 0]
        elif objective == 'h2':
            Wk = cp.Variable((C.shape[1],) * 2, symmetric=True)
            cons += [_sym(cp, [[P[k1] - G[k] @ G[k].T, AP], [AP.T, P[k]]]) >> 0,
                     _sym(cp, [[Wk, CP], [CP.T, P[k]]]) >> 0]
            cost = cost + cp.trace(Wk) / N
        else:
            q, w = C.shape[1], G.shape[2]
            Z = np.zeros
            blocks = [[P[k1], AP, G[k], Z((n, q))],
                      [AP.T, P[k], Z((n, w)), CP.T],
                      [G[k].T, Z((w, n)), gamma * np.eye(w), Z((w, q))],
                      [Z((q, n)), CP, Z((q, w)), gamma * np.eye(q)]]
            cons += [_sym(cp, blocks) >> 0]
    if objective == 'decay':
        problem = cp.Problem(cp.Minimize(0), cons)
        bound = None
    elif objective == 'h2':
        problem = cp.Problem(cp.Minimize(cost), cons)
        bound = cost
    else:
        problem = cp.Problem(cp.Minimize(gamma), cons)
        bound = gamma
    return problem, P, Y, bound


def _result(problem, P, Y, bound, data, objective, rate, solver, sysd):
    A, B = data['A'], data['B']
    Pk = np.array([p.value for p in P])
    Pk = 0.5 * (Pk + np.swapaxes(Pk, 1, 2))
    K = np.linalg.solve(Pk, np.swapaxes(np.array([y.value for y in Y]), 1, 2))
    K = np.swapaxes(K, 1, 2)                                # K_k = Y_k P_k⁻¹ (P symmetric)
    if objective == 'decay':
        value = float(rate)
    elif objective == 'h2':
        value = float(np.sqrt(max(bound.value, 0.0)))
    else:
        value = float(bound.value)
    status = problem.status
    violation = _violation(data, objective, Pk, K, value)
    if violation > _VIOLATION_TOL:
        status = f"{status} (constraints violated by {violation:.1e})"
    logmod, arg = _log_multipliers(None, None, factors=A - B @ K)
    mult = np.exp(logmod + 1j * arg)
    if status != 'optimal' or np.max(np.abs(mult), initial=0.0) >= 1:
        warnings.warn(f"lmi_statefbk: the solution is not certified (status {status!r}, "
                      f"largest closed-loop multiplier {np.max(np.abs(mult)):.6g})",
                      UserWarning, stacklevel=3)
    return LMIDesign(PeriodicMatrix.from_samples(K, sysd.period, kind='hold'), value, Pk,
                     status, solver, objective, mult)


def _violation(data, objective, P, K, value):
    """Largest relative violation of the LMIs at the recovered (P, K, bound)."""
    A, B, C, D, G = (data[k] for k in 'ABCDG')
    N, n, _ = B.shape
    worst = 0.0
    for k in range(N):
        k1 = (k + 1) % N
        Acl, Ccl = A[k] - B[k] @ K[k], C[k] + D[k] @ K[k]
        if objective == 'decay':
            M = value ** 2 * P[k1] - Acl @ P[k] @ Acl.T
        else:
            M = P[k1] - Acl @ P[k] @ Acl.T - (G[k] @ G[k].T if objective == 'h2' else 0)
        if objective == 'hinf':
            # the bounded real inequality at the recovered numbers, as one matrix
            q, w = Ccl.shape[0], G.shape[2]
            M = np.block([[P[k1], Acl @ P[k], G[k], np.zeros((n, q))],
                          [(Acl @ P[k]).T, P[k], np.zeros((n, w)), (Ccl @ P[k]).T],
                          [G[k].T, np.zeros((w, n)), value * np.eye(w), np.zeros((w, q))],
                          [np.zeros((q, n)), Ccl @ P[k], np.zeros((q, w)), value * np.eye(q)]])
        scale = max(1.0, np.abs(M).max())
        worst = max(worst, -np.linalg.eigvalsh(0.5 * (M + M.T)).min() / scale)
    if objective == 'h2':
        h2 = np.mean([np.trace((C[k] + D[k] @ K[k]) @ P[k] @ (C[k] + D[k] @ K[k]).T)
                      for k in range(N)])
        worst = max(worst, (h2 - value ** 2) / max(1.0, value ** 2))
    return worst


def _bisect_rate(data, solver, sysd, tol=1e-4):
    """Smallest certifiable decay rate by bisection on ρ in (0, 1]."""
    import cvxpy as cp
    best = None
    lo, hi = 0.0, 1.0
    rho = 1.0
    while True:
        problem, P, Y, _ = _problem(cp, data, 'decay', rho)
        if _solve(problem, solver) == 'optimal':
            best, hi = (problem, P, Y, rho), rho
        elif best is None:
            raise ValueError("the LMIs are infeasible for the rate 1: the plant is not "
                             "stabilizable")
        else:
            lo = rho
        if hi - lo < tol:
            break
        rho = 0.5 * (lo + hi)
    problem, P, Y, rho = best
    return _result(problem, P, Y, None, data, 'decay', rho, solver, sysd)


def _solve(problem, solver):
    """Solve; a solver breakdown (typical near infeasibility) is a status, not an error."""
    import cvxpy as cp
    try:
        problem.solve(solver=solver)
        return problem.status
    except cp.error.SolverError:
        return 'solver_error'


def _sym(cp, blocks):
    M = cp.bmat(blocks)
    return 0.5 * (M + M.T)


def _per_step(M, N, shape, name):
    arr = np.asarray(M, float)
    if arr.ndim == 2:
        arr = np.broadcast_to(arr, (N,) + arr.shape)
    if arr.ndim != 3 or arr.shape[0] != N or (shape is not None and arr.shape[1:] != shape):
        raise ValueError(f"{name} must have shape {shape or '(n, w)'} or (N={N},) + that, "
                         f"got {np.shape(M)}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains NaN or inf")
    return arr


def _sqrt_psd(M, name, strict):
    """Symmetric square roots of a stack of positive (semi)definite matrices."""
    if np.abs(M - np.swapaxes(M, 1, 2)).max() > 1e-10 * max(1.0, np.abs(M).max()):
        raise ValueError(f"{name} must be symmetric")
    w, V = np.linalg.eigh(M)
    tol = 1e-14 * max(1.0, np.abs(M).max())
    if (strict and w.min() <= tol) or w.min() < -tol:
        raise ValueError(f"{name} must be positive {'definite' if strict else 'semidefinite'}")
    return (V * np.sqrt(np.clip(w, 0, None))[:, None, :]) @ np.swapaxes(V, 1, 2)
