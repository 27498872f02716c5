"""Multirate sampled-data models: per-channel hold and sampling periods.

A plant is driven by zero-order holds whose input i is updated every
``k_i`` base steps of length ``T_s`` and held in between, and its output j is
sampled every ``k_j`` base steps and held (an output hold, so that the
digital controller always reads the latest sample).  With the plant's step
matrices ``A_k, B_k, C_k, D_k`` at the base rate (the exact ZOH
discretization ``[[A_k, B_k], [0, I]] = expm([[A, B], [0, 0]] T_s)`` of a
continuous LTI plant, `ltpcontrol.sample_system` of a continuous LTP plant,
or the matrices of a discrete plant), the selection matrices
``S_k = diag(k mod k_i == 0)`` (inputs) and ``S°_k = diag(k mod k_j == 0)``
(outputs) give

    ū_k = S_k u_k + (I - S_k) ū_{k-1},          (held inputs)
    x_{k+1} = A_k x_k + B_k ū_k,
    ȳ_k = S°_k (C_k x_k + D_k ū_k) + (I - S°_k) ȳ_{k-1},     y_k = ȳ_k,

a discrete periodic system with state ``[x_k; ū_{k-1}; ȳ_{k-1}]`` (hold
states only for the channels with ``k > 1``) and period ``N T_s``, ``N =
lcm(k_i, k_j, N_plant)`` (the model of Varga's ``psmrc2d``, after Longhi).
At the sampling instants of output j, ``y_j[k]`` is the plant output at
``t = k T_s`` exactly; in between it repeats the last sample.  The lifted
LTI equivalent is ``lift(model, method='time')``.
"""

import numbers

import numpy as np
import scipy.linalg as la
import control as ct
from control.exception import ControlArgument, ControlDimension

from .ltpsys import LTPStateSpace
from .subperiods import common_steps
from .validation import check_positive, steps_per_period

__all__ = ['sample_multirate']


def sample_multirate(sys, Ts=None, input_periods=None, output_periods=None, *, name=None):
    """Multirate discretization with per-channel hold and sampling periods.

    Parameters
    ----------
    sys : control.StateSpace, control.TransferFunction or LTPStateSpace
        Continuous-time LTI or LTP plant, or a discrete-time plant (its
        ``dt`` is the base step).
    Ts : float, optional
        Base sampling time (required for a continuous-time plant; for a
        discrete one it must equal ``sys.dt`` if given).  A continuous LTP
        plant needs ``period / Ts`` to be an integer.
    input_periods : sequence of int, optional
        ``k_i``: input i is updated every ``k_i Ts`` (default all 1).
    output_periods : sequence of int, optional
        ``k_j``: output j is sampled every ``k_j Ts`` (default all 1).
    name : str, optional

    Returns
    -------
    LTPStateSpace
        Discrete-time periodic model with ``dt = Ts`` and period
        ``lcm(k_i, k_j, N_plant) Ts``; states ``x`` of the plant, then
        ``'hold_<input>'`` and ``'hold_<output>'`` for the channels held
        longer than one step (module notes).

    Raises
    ------
    ValueError
        If a period is not a positive integer (the message names
        `input_periods` or `output_periods`), or `Ts` does not fit the plant.
    ControlDimension
        If the lengths of the periods do not match the inputs or outputs.

    Examples
    --------
    The plant of Longhi (IEEE TAC 1994) with inputs held 2 and 3 steps and
    outputs sampled every 1 and 2 steps has period 6 Ts:

    >>> G = ct.ss([[0, -np.pi / 6], [np.pi / 6, 0]], np.eye(2), np.eye(2), 0)
    >>> sysd = ltp.sample_multirate(G, 1.0, [2, 3], [1, 2])
    >>> sysd.nsteps, sysd.period, sysd.nstates
    (6, 6.0, 5)
    """
    steps = _plant_steps(sys, Ts)
    Ad, Bd, Cd, Dd, Ts, labels = steps
    m, p = Bd.shape[2], Cd.shape[1]
    ki = _periods(input_periods, m, 'input_periods')
    ko = _periods(output_periods, p, 'output_periods')
    N = common_steps([Ad.shape[0]] + ki + ko,
                     ['sys'] + [f'input_periods[{i}]' for i in range(m)]
                     + [f'output_periods[{j}]' for j in range(p)])
    hu = [i for i in range(m) if ki[i] > 1]
    hy = [j for j in range(p) if ko[j] > 1]
    n = Ad.shape[1]
    nz = n + len(hu) + len(hy)
    Pu = np.eye(m)[:, hu]
    Py = np.eye(p)[:, hy]
    A = np.zeros((N, nz, nz))
    B = np.zeros((N, nz, m))
    C = np.zeros((N, p, nz))
    D = np.zeros((N, p, m))
    for k in range(N):
        a, b, c, d = (M[k % M.shape[0]] for M in (Ad, Bd, Cd, Dd))
        S = np.diag([float(k % q == 0) for q in ki])
        So = np.diag([float(k % q == 0) for q in ko])
        # ū = Mz z + Mu u
        Mz = np.zeros((m, nz))
        Mz[:, n:n + len(hu)] = (np.eye(m) - S) @ Pu
        Mz[:, :n] = 0.0
        Mu = S
        Xz = np.zeros((n, nz))
        Xz[:, :n] = np.eye(n)
        Yz = np.zeros((len(hy), nz))
        Yz[:, n + len(hu):] = np.eye(len(hy))
        # plant output v = c x + d ū; held output ȳ = So v + (I - So) Py ȳ_prev
        Vz = c @ Xz + d @ Mz
        Vu = d @ Mu
        C[k] = So @ Vz + (np.eye(p) - So) @ Py @ Yz
        D[k] = So @ Vu
        A[k, :n] = a @ Xz + b @ Mz
        B[k, :n] = b @ Mu
        A[k, n:n + len(hu)] = Pu.T @ Mz
        B[k, n:n + len(hu)] = Pu.T @ Mu
        A[k, n + len(hu):] = Py.T @ C[k]
        B[k, n + len(hu):] = Py.T @ D[k]
    inputs, outputs, states = labels
    states = list(states) + [f'hold_{inputs[i]}' for i in hu] + \
        [f'hold_{outputs[j]}' for j in hy]
    return LTPStateSpace(A, B, C, D, N * Ts, dt=Ts, inputs=inputs, outputs=outputs,
                         states=states, name=name)


def _periods(values, count, name):
    if values is None:
        return [1] * count
    if isinstance(values, numbers.Number) or np.ndim(values) != 1:
        raise ValueError(f"{name} must be a sequence of {count} positive integers, got "
                         f"{values!r}")
    out = []
    for v in values:
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (numbers.Integral, float,
                                                                  np.floating)) \
                or v != int(v) or v < 1:
            raise ValueError(f"{name} must hold positive integers (multiples of Ts), "
                             f"got {v!r}")
        out.append(int(v))
    if len(out) != count:
        raise ControlDimension(f"{name} must have {count} entries (one per channel), got "
                               f"{len(out)}")
    return out


def _plant_steps(sys, Ts):
    """Base-rate step matrices (N_plant, ., .), Ts and the signal labels."""
    if isinstance(sys, ct.TransferFunction):
        sys = ct.ss(sys)
    if isinstance(sys, LTPStateSpace):
        labels = (sys.input_labels, sys.output_labels, sys.state_labels)
        if sys.isdtime(strict=True):
            Ts = _discrete_Ts(sys.dt, Ts)
            N = sys.nsteps
            return tuple(M.sample(N) for M in (sys.A, sys.B, sys.C, sys.D)) + (Ts, labels)
        if Ts is None:
            raise ControlArgument("Ts must be given for a continuous-time plant")
        Ts = check_positive(Ts, 'Ts')
        steps_per_period(sys.period, Ts, 'Ts')
        sd = sys.sample(Ts)
        N = sd.nsteps
        return tuple(M.sample(N) for M in (sd.A, sd.B, sd.C, sd.D)) + (Ts, labels)
    if not isinstance(sys, ct.StateSpace):
        raise ControlArgument(f"sys must be a state-space or transfer-function system, got "
                              f"{type(sys).__name__}")
    labels = (sys.input_labels, sys.output_labels, sys.state_labels)
    if sys.isdtime(strict=True):
        Ts = _discrete_Ts(sys.dt, Ts)
        return sys.A[None], sys.B[None], sys.C[None], sys.D[None], Ts, labels
    if Ts is None:
        raise ControlArgument("Ts must be given for a continuous-time plant")
    Ts = check_positive(Ts, 'Ts')
    Ad, Bd = zoh(sys.A, sys.B, Ts)
    return Ad[None], Bd[None], sys.C[None], sys.D[None], Ts, labels


def zoh(A, B, h):
    """Exact zero-order-hold step ``(e^{Ah}, ∫_0^h e^{As} ds B)``.

    Examples
    --------
    >>> from ltpcontrol._core.multirate import zoh
    >>> Ad, Bd = zoh(np.array([[-1.0]]), np.array([[1.0]]), 1.0)
    >>> bool(np.isclose(Bd[0, 0], 1 - np.exp(-1.0)))
    True
    """
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = A, B
    E = la.expm(M * h)
    return E[:n, :n], E[:n, n:]


def _discrete_Ts(dt, Ts):
    if dt is True:
        raise ValueError("sys has an unspecified sampling time (dt=True); give it a value")
    if Ts is not None and abs(check_positive(Ts, 'Ts') - dt) > 1e-12 * dt:
        raise ValueError(f"Ts={Ts} differs from the sampling time {dt} of the discrete plant")
    return float(dt)
