"""Periodic ARX models: discrete LTP identification by phase-wise least squares.

A SISO discrete LTP system sampled ``N = T/dt`` times a period is described
by the periodic difference equation

    y[k] = Σ_{i=1}^{na} a_i(k) y[k−i] + Σ_{j=1}^{nb} b_j(k) u[k−j],

with coefficients of period N.  The equation is linear in the coefficients
of each phase ``p = k mod N``, which are fitted by least squares over all
samples of that phase (all periods of all records).  The model is realized
with the past data as its state,

    x[k] = [y[k−1], ..., y[k−na], u[k−1], ..., u[k−nb]],

so ``y[k] = C_k x[k]`` with ``C_k = [a(k), b(k)]`` and ``x[k+1]`` shifts
``y[k]`` and ``u[k]`` in.  The realization is not minimal, but every state
is a measured or applied signal, which makes it a natural model for an
estimator-based (LQG) controller.
"""

from dataclasses import dataclass

import numpy as np
from control.exception import ControlDimension

from .._core.ltpsys import LTPStateSpace
from .records import as_records, common_grid, refuse_ambiguous
from .._core.validation import (check_period, check_positive_int, real_array,
                          steps_per_period)

__all__ = ['identify_arx', 'ARXInfo']


@dataclass(frozen=True)
class ARXInfo:
    """Diagnostics of `identify_arx` (``return_info=True``).

    ``success`` and ``message`` follow `scipy.optimize.OptimizeResult`.

    Attributes
    ----------
    success : bool
        True: the fit is one regularized least-squares solve per phase, and
        a phase that cannot be solved raises instead.
    message : str
        Description of the outcome.
    nsteps : int
        Number N of samples per period (phases).
    nrecords : int
        Number of records (experiments).
    nequations : ndarray of int, shape (N,)
        Equations (samples) of each phase.
    cond : ndarray, shape (N,)
        Condition number of the (regularized) normal equations of each
        phase.
    residual : ndarray, shape (N,)
        Root-mean-square one-step prediction error ``y[k] - ŷ[k]`` of each
        phase.
    ridge : float
        Tikhonov weight used (relative to the mean squared regressor).

    Examples
    --------
    >>> N, rng = 4, np.random.default_rng(1)
    >>> u = rng.standard_normal(200)
    >>> y = np.concatenate([[0.0], 0.5 * u[:-1]])
    >>> _, info = ltp.identify_arx((np.arange(200) * 0.25, u, y), 1.0, 1, 1,
    ...                            return_info=True)
    >>> info.success, info.nsteps, info.nequations.tolist()
    (True, 4, [49, 50, 50, 50])
    """

    success: bool
    message: str
    nsteps: int
    nrecords: int
    nequations: np.ndarray
    cond: np.ndarray
    residual: np.ndarray
    ridge: float



def _records(data):
    """``(t, U, Y)`` with U, Y of shape (nexp, L): SISO records on one time grid."""
    refuse_ambiguous(data, 'data', 'identify_arx')
    t, _, U, Y = common_grid(as_records(data, 'data'), 'data')
    if U.shape[0] != 1 or Y.shape[0] != 1:
        raise ControlDimension(f"identify_arx identifies SISO models: data has {U.shape[0]} "
                               f"inputs and {Y.shape[0]} outputs")
    return t, U[0], Y[0]


def identify_arx(data, period, na, nb, *, ridge=0.0, return_info=False, name=None):
    """Identify a periodic ARX model of a SISO LTP system from sampled records.

    Parameters
    ----------
    data : tuple, control.TimeResponseData or list
        ``(timepts, inputs, outputs)``: uniform sample times (absolute:
        ``t = 0`` is the phase reference of the period), and input and
        output samples of shape ``(L,)``, or ``(1, nexp, L)`` for several
        records on the same time grid; or a `control.TimeResponseData`, or
        a list of records on the same grid.  The input is taken as held between samples
        (zero-order hold).
    period : float
        Period T; ``T / dt`` must be an integer N.
    na, nb : int
        Numbers of past outputs and inputs (both at least 1).
    ridge : float, optional
        Tikhonov weight relative to the mean squared regressor (default 0).
    return_info : bool, optional
        Also return the fit diagnostics (default False).
    name : str, optional
        Name of the model (default ``'arx'``).

    Returns
    -------
    sys : LTPStateSpace
        Discrete-time model (``dt`` of the data, N steps per period) with
        ``na + nb`` states (past outputs and inputs), one input and one
        output; step k of the model is the sample at ``t = k dt``.
    info : ARXInfo
        Only with ``return_info=True``: equations, condition number and
        one-step prediction residual of each phase.

    Raises
    ------
    ValueError
        If some phase has fewer equations than coefficients or linearly
        dependent regressors, or the data are not uniform or not
        commensurate with the period.

    Examples
    --------
    A first-order system with a periodic pole, identified exactly from a
    random input:

    >>> N, rng = 8, np.random.default_rng(0)
    >>> a = 0.5 + 0.3 * np.cos(2 * np.pi * np.arange(N) / N)
    >>> u = rng.standard_normal(400)
    >>> y = np.zeros(400)
    >>> for k in range(1, 400):
    ...     y[k] = a[k % N] * y[k - 1] + u[k - 1]
    >>> model = ltp.identify_arx((np.arange(400) * 0.1, u, y), 0.8, 1, 1)
    >>> bool(np.allclose(model.C.sample(N)[:, 0, 0], a))
    True

    With ``return_info=True`` the diagnostics of the fit come along:

    >>> model, info = ltp.identify_arx((np.arange(400) * 0.1, u, y), 0.8, 1, 1,
    ...                                return_info=True)
    >>> info.success, info.nsteps, bool(info.residual.max() < 1e-10)
    (True, 8, True)
    """
    t, U, Y = _records(data)
    period = check_period(period)
    na = check_positive_int(na, 'na')
    nb = check_positive_int(nb, 'nb')
    ridge = float(real_array(ridge, 'ridge', ndim=0))
    if ridge < 0:
        raise ValueError(f"ridge must be non-negative, got {ridge}")
    dt = float(np.mean(np.diff(t)))
    N = steps_per_period(period, dt, 'the sampling time of timepts')
    lag = max(na, nb)
    # regressors [y[k−1..k−na], u[k−1..k−nb]] and targets y[k] for k >= lag
    L = t.size
    cols = [Y[:, lag - i:L - i] for i in range(1, na + 1)] + \
           [U[:, lag - j:L - j] for j in range(1, nb + 1)]
    phi = np.stack(cols, axis=-1).reshape(-1, na + nb)
    target = Y[:, lag:].reshape(-1)
    phase = np.tile(np.round(t[lag:] / dt).astype(int) % N, Y.shape[0])
    theta = np.empty((N, na + nb))
    neq, cond, rms = np.zeros(N, int), np.empty(N), np.empty(N)
    scale = ridge * np.mean(phi ** 2)
    for p in range(N):
        rows = phase == p
        neq[p] = rows.sum()
        if rows.sum() < na + nb:
            raise ValueError(f"phase {p} of {N} has {rows.sum()} equations for {na + nb} "
                             "coefficients: record more periods")
        P = phi[rows]
        gram = P.T @ P + scale * np.eye(na + nb)
        cond[p] = np.linalg.cond(gram)
        if cond[p] > 1e12:
            raise ValueError(f"the regressors of phase {p} of {N} are (nearly) linearly "
                             "dependent: excite the input more richly, lower na or nb, or "
                             "give a ridge weight")
        theta[p] = np.linalg.solve(gram, P.T @ target[rows])
        rms[p] = np.sqrt(np.mean((target[rows] - P @ theta[p]) ** 2))
    sys = _realize(theta, na, nb, period, dt, name if name is not None else 'arx')
    if not return_info:
        return sys
    info = ARXInfo(success=True, message=f"{N} phases fitted by least squares, largest "
                   f"condition number {cond.max():.3g}", nsteps=N, nrecords=Y.shape[0],
                   nequations=neq, cond=cond, residual=rms, ridge=ridge)
    return sys, info


def _realize(theta, na, nb, period, dt, name):
    """Past-data realization of the periodic ARX coefficients ``theta[p] = [a, b]``."""
    N, n = theta.shape
    A = np.zeros((N, n, n))
    A[:, 0, :] = theta                                   # y[k] = C_k x[k] enters first
    A[:, 1:na, 0:na - 1] = np.eye(na - 1)
    if nb > 1:
        A[:, na + 1:, na:n - 1] = np.eye(nb - 1)
    B = np.zeros((n, 1))
    B[na, 0] = 1.0                                       # u[k] enters the input register
    C = theta[:, np.newaxis, :]
    states = [f'y[k-{i}]' for i in range(1, na + 1)] + [f'u[k-{j}]' for j in range(1, nb + 1)]
    return LTPStateSpace(A, B, C, 0, period, dt=dt, name=name, states=states)
