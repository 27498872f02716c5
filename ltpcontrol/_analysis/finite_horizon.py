"""Finite-horizon Riccati and Lyapunov differential equations, finite-horizon H2 norm.

On ``[t_0, t_f]`` with a terminal condition ``X(t_f) = X_f``:

* Riccati ``-Ẋ = AᵀX + XA - XBR⁻¹BᵀX + Q``: with the Hamiltonian
  ``H = [[A, -BR⁻¹Bᵀ], [-Q, -Aᵀ]]`` and its transition ``Ψ_k`` over the
  step ``[t_k, t_{k+1}]``, ``[U; V] = Ψ_k⁻¹ [I; X_{k+1}]`` gives
  ``X_k = V U⁻¹`` (the backward flow restarted from the graph at every
  step, so no long product of the Hamiltonian flow is formed);
* Lyapunov ``-Ẋ = AᵀX + XA + Q``: ``X_k = Φ_kᵀX_{k+1}Φ_k + V_k`` with the
  Van Loan integrals of `ltpcontrol.lyap`;
* H2 norm of ``ẋ = Ax + Bw``, ``z = Cx`` over the horizon from ``x(t_0) = 0``:
  ``‖G‖²_{[t_0, t_f]} = ∫ tr(BᵀX_oB) dt`` with the observability solution
  ``X_o`` (``Q = CᵀC``, ``X_o(t_f) = 0``), integrated exactly per step as in
  `ltpcontrol.norm`.

The steps are the intervals between the requested times, subdivided so that
``h ‖H‖ <= 1``.  The data are periodic matrices (any horizon) or constant.
"""

import numpy as np
from control.exception import ControlArgument, ControlDimension

from .._core.coerce import as_ltp
from .._core.periodic_matrix import PeriodicMatrix, as_periodic
from .._core.steps import gram_weight, step_integrals
from .._core.transition import step_transitions
from .._core.validation import real_array
from .riccati import _check_weights
from .riccati_solution import _graph, _stack

__all__ = ['care_finite', 'lyap_finite', 'h2norm_finite']


def care_finite(A, B, Q, R, Xf, t, *, period=None):
    """Finite-horizon Riccati differential equation with a terminal condition.

    ``-Ẋ = AᵀX + XA - XBR⁻¹BᵀX + Q`` on ``[t[0], t[-1]]`` with
    ``X(t[-1]) = Xf`` (the cost-to-go of the finite-horizon LQ problem).

    Parameters
    ----------
    A, B, Q, R : PeriodicMatrix, callable or array_like
        Data, shapes (n, n), (n, m), (n, n), (m, m); R(t) ≻ 0.
    Xf : array_like, shape (n, n)
        Symmetric terminal value.
    t : array_like
        Increasing times; the horizon is ``[t[0], t[-1]]``.
    period : float, optional
        Period of the data when none of them is a `PeriodicMatrix`.

    Returns
    -------
    X : ndarray, shape (len(t), n, n)
        ``X(t_i)``.

    Raises
    ------
    ValueError
        If t is not increasing, a weight is not symmetric, R is not
        positive definite, or the solution escapes (U singular).

    Examples
    --------
    Scalar ``-ẋ = -x² + 1`` from ``X(1) = 0``: ``X(t) = tanh(1 - t)``.

    >>> X = ltp.care_finite([[0.0]], [[1.0]], [[1.0]], [[1.0]], [[0.0]], [0.0, 0.5, 1.0],
    ...                     period=1.0)
    >>> bool(np.allclose(X[:, 0, 0], np.tanh([1.0, 0.5, 0.0])))
    True
    """
    A, B, Q, R, T = _data((A, B, Q, R), ('A', 'B', 'Q', 'R'), period)
    n, m = A.shape[0], B.shape[1]
    _shape(B, (n, m), 'B')
    _shape(Q, (n, n), 'Q')
    _shape(R, (m, m), 'R')
    times, Xf = _times(t), _terminal(Xf, n)
    probe = np.linspace(times[0], times[-1], 17)
    _check_weights(Q(probe), R(probe), 'Q', 'R')

    def ham(a, b, q, r):
        out = np.empty((len(a), 2 * n, 2 * n))
        out[:, :n, :n] = a
        out[:, :n, n:] = -b @ np.linalg.solve(r, np.swapaxes(b, 1, 2))
        out[:, n:, :n] = -q
        out[:, n:, n:] = -np.swapaxes(a, 1, 2)
        return out
    H = PeriodicMatrix.pointwise(ham, [A, B, Q, R], (2 * n, 2 * n))
    grid, at = _grid(times, H)
    Psi, _, _ = step_transitions(H, None, grid[:-1], np.diff(grid))
    X = np.empty((len(grid), n, n))
    X[-1] = Xf
    for k in range(len(grid) - 2, -1, -1):
        UV = np.linalg.solve(Psi[k], _stack(X[k + 1]))
        if np.linalg.cond(UV[:n]) > 1e12:
            raise ValueError(f"the Riccati solution escapes to infinity near t = {grid[k]}")
        X[k] = _graph(UV, n)
    return X[at]


def lyap_finite(A, Q, Xf, t, *, period=None):
    """Finite-horizon Lyapunov differential equation with a terminal condition.

    ``-Ẋ = AᵀX + XA + Q`` on ``[t[0], t[-1]]`` with ``X(t[-1]) = Xf``.

    Parameters
    ----------
    A, Q : PeriodicMatrix, callable or array_like
        Data (n, n); Q symmetric.
    Xf : array_like, shape (n, n)
        Symmetric terminal value.
    t : array_like
        Increasing times; the horizon is ``[t[0], t[-1]]``.
    period : float, optional
        Period of the data when neither is a `PeriodicMatrix`.

    Returns
    -------
    X : ndarray, shape (len(t), n, n)

    Examples
    --------
    ``-ẋ = -2x + 2`` from ``X(1) = 0``: ``X(t) = 1 - e^{-2(1 - t)}``.

    >>> X = ltp.lyap_finite([[-1.0]], [[2.0]], [[0.0]], [0.0, 1.0], period=1.0)
    >>> bool(np.isclose(X[0, 0, 0], 1 - np.exp(-2.0)))
    True
    """
    A, Q, T = _data((A, Q), ('A', 'Q'), period)
    n = A.shape[0]
    _shape(Q, (n, n), 'Q')
    times, Xf = _times(t), _terminal(Xf, n)
    probe = np.linspace(times[0], times[-1], 17)
    _check_weights(Q(probe), np.ones((1, 1, 1)), 'Q', 'R')
    grid, at = _grid(times, A)
    Phi, _, V, _ = step_integrals(A, grid[:-1], np.diff(grid), Qa=Q)
    X = np.empty((len(grid), n, n))
    X[-1] = Xf
    for k in range(len(grid) - 2, -1, -1):
        X[k] = Phi[k].T @ X[k + 1] @ Phi[k] + V[k]
        X[k] = 0.5 * (X[k] + X[k].T)
    return X[at]


def h2norm_finite(sys, t0, tf):
    """H2 norm of a continuous-time LTP system over the horizon ``[t0, tf]``.

    ``sqrt(∫_{t0}^{tf} tr(B(t)ᵀ X_o(t) B(t)) dt)`` with ``-Ẋ_o = AᵀX_o +
    X_oA + CᵀC``, ``X_o(tf) = 0``: the root mean output energy on the
    horizon for white noise of unit intensity on every input (x(t0) = 0).
    Not divided by the horizon's length (the periodic H2 norm of `norm` is a
    per-period average).  D must be zero.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous-time system (stable or not: the horizon is finite).
    t0, tf : float
        Horizon, ``t0 < tf``.

    Returns
    -------
    float

    Examples
    --------
    ``ẋ = -x + w``, ``z = x`` over [0, τ]: ``∫ (1 - e^{-2(τ - t)})/2 dt``.

    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> tau = 3.0
    >>> exact = np.sqrt(tau / 2 - (1 - np.exp(-2 * tau)) / 4)
    >>> bool(np.isclose(ltp.h2norm_finite(sys, 0.0, tau), exact))
    True
    """
    sys = as_ltp(sys)
    if sys.isdtime():
        raise ControlArgument("h2norm_finite: sys must be a continuous-time system")
    probe = np.linspace(0, sys.period, 33)
    if np.any(sys.D(probe)):
        raise ValueError("h2norm_finite: the system has a feedthrough D; its H2 norm is "
                         "infinite")
    times = _times([t0, tf])
    if sys.nstates == 0:
        return 0.0
    grid, _ = _grid(times, sys.A)
    Phi, W, V, S = step_integrals(sys.A, grid[:-1], np.diff(grid), Qf=gram_weight(sys.B),
                                  Qa=gram_weight(sys.C, True))
    n = sys.nstates
    X = np.zeros((n, n))
    total = 0.0
    for k in range(len(grid) - 2, -1, -1):
        total += float(np.trace(X @ W[k]) + S[k])
        X = Phi[k].T @ X @ Phi[k] + V[k]
    return float(np.sqrt(max(total, 0.0)))


#
# Helpers
#

def _data(mats, names, period):
    T = period
    for M in mats:
        if isinstance(M, PeriodicMatrix):
            T = M.period
            break
    if T is None:
        raise ControlArgument("period must be given when no argument is a PeriodicMatrix")
    return tuple(as_periodic(M, T, name) for M, name in zip(mats, names)) + (T,)


def _shape(M, shape, name):
    if M.shape != shape:
        raise ControlDimension(f"{name} must have shape {shape}, got {M.shape}")


def _times(t):
    t = real_array(t, 't', ndim=1)
    if len(t) < 2 or np.any(np.diff(t) <= 0):
        raise ValueError("t must hold at least two strictly increasing times")
    return t


def _terminal(Xf, n):
    Xf = real_array(Xf, 'Xf', ndim=2)
    if Xf.shape != (n, n):
        raise ControlDimension(f"Xf must have shape {(n, n)}, got {Xf.shape}")
    if np.abs(Xf - Xf.T).max(initial=0.0) > 1e-10 * max(1.0, np.abs(Xf).max(initial=0.0)):
        raise ValueError("Xf must be symmetric")
    return 0.5 * (Xf + Xf.T)


def _grid(times, H):
    """The times refined so that ``h ‖H‖ <= 1``; indices of the times in it."""
    T = H.period
    probe = np.linspace(0, T, 65)[:-1]
    norm = max(np.linalg.norm(H(probe), ord=2, axis=(1, 2)).max(initial=0.0), 1e-300)
    pieces, at = [], [0]
    for a, b in zip(times[:-1], times[1:]):
        k = int(min(np.ceil((b - a) * norm), 100000)) or 1
        pieces.append(np.linspace(a, b, k + 1)[:-1])
        at.append(at[-1] + k)
    grid = np.concatenate(pieces + [times[-1:]])
    return grid, np.array(at)
