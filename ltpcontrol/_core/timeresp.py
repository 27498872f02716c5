"""Time responses of LTP systems.

Continuous-time systems are simulated exactly for inputs that are linear
between samples (first-order hold, as `control.forced_response`) or constant
(zero-order hold).  On a uniform grid whose step divides the period, the
transition data of one period, ``x_{k+1} = Φ_k x_k + Γ0_k u_k + Γ1_k (u_{k+1} - u_k)``
(see ``_transition``), is computed once and reused: the states and outputs
of all samples and traces then come from blocks of steps as matrix products
(``_march``).

A reference path (``method='solve_ivp'``) integrates with
`scipy.integrate.solve_ivp` between samples and switching instants (the
held input and A, B are smooth there).
"""

import functools
import numbers
import warnings

import numpy as np
import control as ct
from control.config import _process_kwargs
from control.exception import ControlDimension
from control.timeresp import _default_time_vector, _timeresp_aliases
from scipy.integrate import solve_ivp

from .cellmarch import outputs
from .gridmarch import grid_march
from .march import periodic_march
from .coerce import as_ltp
from .validation import check_kwargs, check_positive, real_array
from .registry import overridden

__all__ = ['forced_response', 'step_response', 'initial_response', 'impulse_response']


def _aliases(func):
    """Accept python-control's keyword aliases (``T``, ``U``, ``X0``, ``return_x``,
    ``input``, ``output``) as `control.forced_response` and its siblings do."""
    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        _process_kwargs(kwargs, _timeresp_aliases)
        return func(*args, **kwargs)
    return wrapper


@_aliases
def forced_response(sys, timepts=None, inputs=0.0, initial_state=0.0, *,
                    method='transition', input_hold='foh', rtol=1e-12,
                    compute_states=True, return_states=False, squeeze=None,
                    transpose=False, **kwargs):
    """Response of an LTP system to arbitrary inputs, for one or many traces.

    Parameters
    ----------
    sys : LTPStateSpace
        System to simulate.
    timepts : array_like or float, optional
        Increasing time points (1D).  A scalar gives ``[0, timepts]`` with
        50 samples per period.  Discrete-time systems need multiples of `dt`;
        without `timepts` they take ``k dt`` for the samples of `inputs`,
        as `control.forced_response`.
    inputs : array_like or float
        Input values, shape ``(ninputs, len(timepts))``, or ``(ninputs,
        ntraces, len(timepts))`` to simulate several input signals in one
        call.  SISO inputs may be 1D.
    initial_state : array_like or float
        Initial state, shape ``(nstates,)`` or ``(nstates, ntraces)``.
    method : {'transition', 'solve_ivp'}
        'transition' (default) is exact for the chosen input hold and
        reuses one period of transition matrices; 'solve_ivp' is a
        reference integration (DOP853, tolerance `rtol`).
    input_hold : {'foh', 'zoh'}
        Inputs linear between samples (default, as `control.forced_response`)
        or constant (zero-order hold).
    rtol : float
        Relative accuracy of the transition matrices or of the integrator.
    compute_states : bool
        Compute the states (default).  False computes the outputs only
        (``resp.states`` is then empty, with zero rows), about three times less work and
        memory for a large batch of traces.
    return_states : bool
        Keep the legacy tuple form ``t, y, x`` when unpacking.
    squeeze, transpose : bool, optional
        As in `control.forced_response`.

    Returns
    -------
    resp : control.TimeResponseData
        ``resp.time``, ``resp.outputs``, ``resp.states``, ``resp.inputs``;
        with several traces the arrays have shape ``(signals, ntraces,
        len(timepts))``.  ``resp.plot()`` draws the response.

    Notes
    -----
    Any time grid runs at about the speed of a uniform grid whose step
    divides the period (within 2x on the benchmark records, up to about 3x
    for one long trace): the transition data are computed once per phase
    pattern, or from a table of one period's cells (see the Performance
    page).

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> t = np.linspace(0, 5, 501)
    >>> resp = ltp.forced_response(sys, t, np.ones_like(t))
    >>> bool(np.isclose(resp.outputs[-1], 1 - np.exp(-5)))
    True
    """
    if (own := overridden('forced_response', sys)) is not None:   # systems with delays
        return own(sys, timepts, inputs, initial_state, method=method, input_hold=input_hold,
                   rtol=rtol, compute_states=compute_states, return_states=return_states,
                   squeeze=squeeze, transpose=transpose, **kwargs)
    check_kwargs(kwargs, 'forced_response')
    sys = as_ltp(sys, lti_hint='control.forced_response')
    if timepts is None and sys.isdtime(strict=True) and np.ndim(inputs) > 0:
        # python-control: a discrete-time input without timepts is sampled at k dt
        timepts = np.arange(np.shape(inputs)[-1]) * sys.dt
    t, u, ntraces, x0 = forced_arguments(sys, timepts, inputs, initial_state, method,
                                         ('transition', 'solve_ivp'), input_hold)
    if not isinstance(compute_states, (bool, np.bool_)):
        raise ValueError(f"compute_states must be True or False, got {compute_states!r}")
    if return_states and not compute_states:
        raise ValueError("return_states=True needs compute_states=True")
    x, y = _simulate(sys, t, u, x0, method, input_hold, rtol, bool(compute_states))
    return forced_result(sys, t, x, y, u, inputs, transpose, return_states, squeeze)


@_aliases
def step_response(sys, timepts=None, initial_state=0.0, input_indices=None,
                  output_indices=None, *, method='transition', input_hold='foh',
                  rtol=1e-12, return_states=False, squeeze=None, transpose=False,
                  **kwargs):
    """Step response of an LTP system, one trace per input.

    The step is applied at the first time point; for an LTP system the
    response depends on that phase of the period.

    Parameters
    ----------
    sys : LTPStateSpace
        System to simulate.
    timepts : array_like or float, optional
        Time points, or a final time.  Default: five periods or the
        settling time of the slowest Floquet exponent, whichever is
        longer; a final time gives 50 samples per period (one per step in
        discrete time).  A system with constant matrices gets python-control's
        default grids (`control.step_response`).
    initial_state : array_like or float
        Initial state.
    input_indices, output_indices : int or list of int, optional
        Inputs to step and outputs to keep (default all).
    method, input_hold, rtol : optional
        As in `forced_response`.
    return_states, squeeze, transpose : bool, optional
        As in `control.step_response`.

    Returns
    -------
    resp : control.TimeResponseData
        Outputs of shape ``(noutputs, ninputs, len(timepts))``.

    Examples
    --------
    >>> sys = ltp.ltpss([[-2.0]], [[2.0]], [[1.0]], 0, period=1.0)
    >>> resp = ltp.step_response(sys, 4.0)
    >>> round(float(resp.outputs[-1]), 3)
    1.0
    """
    check_kwargs(kwargs, 'step_response')
    sys = as_ltp(sys, lti_hint='control.step_response')
    t = _time_vector(sys, timepts, is_step=True)
    ins = _indices(input_indices, sys.ninputs, 'input_indices')
    outs = _indices(output_indices, sys.noutputs, 'output_indices')
    u = np.zeros((sys.ninputs, len(ins), len(t)))
    for trace, i in enumerate(ins):
        u[i, trace] = 1.0
    x0 = _initial_state(sys, initial_state, len(ins))
    x, y = _simulate(sys, t, u, x0, method, input_hold, rtol)
    return _trace_response(sys, t, u, x, y, ins, outs, 'step', 'Step response',
                           return_states, squeeze, transpose)


@_aliases
def initial_response(sys, timepts=None, initial_state=0.0, output_indices=None, *,
                     method='transition', input_hold='foh', rtol=1e-12,
                     return_states=False, squeeze=None, transpose=False, **kwargs):
    """Free response of an LTP system from an initial state.

    Parameters
    ----------
    sys : LTPStateSpace
        System to simulate.
    timepts : array_like or float, optional
        Time points (default as in `step_response`).
    initial_state : array_like or float
        Initial state at the first time point.
    output_indices : int or list of int, optional
        Outputs to keep (default all).
    method, input_hold, rtol : optional
        As in `forced_response`.
    return_states, squeeze, transpose : bool, optional
        As in `control.initial_response`.

    Returns
    -------
    resp : control.TimeResponseData

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> resp = ltp.initial_response(sys, 1.0, initial_state=2.0)
    >>> bool(np.isclose(resp.outputs[-1], 2 * np.exp(-1)))
    True
    """
    if (own := overridden('initial_response', sys)) is not None:  # systems with delays
        return own(sys, timepts, initial_state, output_indices, method=method,
                   input_hold=input_hold, rtol=rtol, return_states=return_states,
                   squeeze=squeeze, transpose=transpose, **kwargs)
    check_kwargs(kwargs, 'initial_response')
    sys = as_ltp(sys, lti_hint='control.initial_response')
    t = _time_vector(sys, timepts, is_step=False)
    outs = _indices(output_indices, sys.noutputs, 'output_indices')
    u = np.zeros((sys.ninputs, 1, len(t)))
    x, y = _simulate(sys, t, u, _initial_state(sys, initial_state, 1), method, input_hold, rtol)
    # as control.initial_response: no inputs, SISO when one output is selected
    return ct.TimeResponseData(
        t, y[outs, 0], x[:, 0], None, issiso=sys.issiso() or output_indices is not None,
        output_labels=[sys.output_labels[i] for i in outs], input_labels=None,
        state_labels=sys.state_labels, title="Initial response for " + sys.name,
        trace_types=['initial'], transpose=transpose, return_x=return_states,
        squeeze=squeeze, sysname=sys.name)


@_aliases
def impulse_response(sys, timepts=None, input_indices=None, output_indices=None, *,
                     method='transition', input_hold='foh', rtol=1e-12,
                     return_states=False, squeeze=None, transpose=False, **kwargs):
    """Impulse response of an LTP system, one trace per input.

    Continuous time: a unit impulse at the first time point ``t0`` sets
    ``x(t0+) = B(t0) e_j``; the impulse in the output through ``D(t0)`` is
    not representable and gives a warning.  Discrete time: a unit-area
    pulse ``u[0] = 1/dt`` as in `control.impulse_response`.

    Parameters
    ----------
    sys : LTPStateSpace
        System to simulate.
    timepts : array_like or float, optional
        Time points (default as in `step_response`).
    input_indices, output_indices : int or list of int, optional
        Inputs to excite and outputs to keep (default all).
    method, input_hold, rtol : optional
        As in `forced_response`.
    return_states, squeeze, transpose : bool, optional
        As in `control.impulse_response`.

    Returns
    -------
    resp : control.TimeResponseData

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> resp = ltp.impulse_response(sys, 1.0)
    >>> bool(np.isclose(resp.outputs[-1], np.exp(-1)))
    True
    """
    check_kwargs(kwargs, 'impulse_response')
    sys = as_ltp(sys, lti_hint='control.impulse_response')
    t = _time_vector(sys, timepts, is_step=False)
    ins = _indices(input_indices, sys.ninputs, 'input_indices')
    outs = _indices(output_indices, sys.noutputs, 'output_indices')
    u = np.zeros((sys.ninputs, len(ins), len(t)))
    if sys.isdtime():
        for trace, i in enumerate(ins):
            u[i, trace, 0] = 1.0 / sys.dt
        x0 = np.zeros((sys.nstates, len(ins)))
    else:
        if np.any(sys.D(t[0])[np.ix_(outs, ins)] != 0):
            warnings.warn("the system has direct feedthrough D(t0) != 0: the impulse in "
                          "the output at t0 is not shown", UserWarning, stacklevel=2)
        x0 = sys.B(t[0])[:, ins]
    x, y = _simulate(sys, t, u, x0, method, input_hold, rtol)
    return _trace_response(sys, t, u, x, y, ins, outs, 'impulse', 'Impulse response',
                           return_states, squeeze, transpose)


#
# Simulation engines
#

def _simulate(sys, t, u, x0, method, hold, rtol, states=True):
    """States (nstates, ntraces, len(t)), or None, and outputs by the requested engine."""
    if method not in ('transition', 'solve_ivp'):
        raise ValueError(f"method must be 'transition' or 'solve_ivp', got {method!r}")
    if hold not in ('foh', 'zoh'):
        raise ValueError(f"input_hold must be 'foh' or 'zoh', got {hold!r}")
    rtol = check_positive(rtol, 'rtol', below=1)
    if sys.isdtime():
        return _march_discrete(sys, t, u, x0, states)
    if method == 'solve_ivp':
        x = _solve_ivp(sys, t, u, x0, hold, rtol)
        return x if states else None, _outputs(sys, t, x, u)
    return _march_continuous(sys, t, u, x0, hold, rtol, states)


def _march_continuous(sys, t, u, x0, hold, rtol, states=True):
    if len(t) == 1:
        x = x0[:, :, None].copy()
        return x if states else None, _outputs(sys, t, x, u)
    # exact step data reused wherever the grid's phases repeat (``_gridmarch``)
    return grid_march(sys.A, sys.B, sys.C, sys.D, t, u, x0, hold, rtol, states)


def _march_discrete(sys, t, u, x0, states=True):
    N = sys.nsteps
    k0 = int(round(t[0] / sys.dt))
    phase = (k0 + np.arange(N)) % N
    A, B, C, D = (M.sample(N)[phase] for M in (sys.A, sys.B, sys.C, sys.D))
    return periodic_march(A, B, None, C, D, u, x0, states=states)


def _solve_ivp(sys, t, u, x0, hold, rtol):
    n, R = sys.nstates, u.shape[1]
    bps = np.unique(np.concatenate([sys.A.breakpoints, sys.B.breakpoints]))
    cuts = np.array([])
    if bps.size:
        shifts = np.arange(np.floor(t[0] / sys.period), np.floor(t[-1] / sys.period) + 1)
        cuts = (bps[None, :] + sys.period * shifts[:, None]).ravel()
        cuts = cuts[(cuts > t[0]) & (cuts < t[-1])]
    # the held input is smooth between samples, A and B between switching
    # instants: the integration restarts at both (no step across a jump or kink)
    edges = np.unique(np.concatenate([t, cuts]))
    at = np.searchsorted(edges, t)                   # t[k] == edges[at[k]]
    x = np.empty((n, R, len(t)))
    for r in range(R):
        xr = x0[:, r]
        x[:, r, 0] = xr
        for i, (a, b) in enumerate(zip(edges[:-1], edges[1:])):
            k = min(np.searchsorted(t, a, side='right') - 1, len(t) - 2)
            u0, u1 = u[:, r, k], u[:, r, k + 1]
            tk, hk = t[k], t[k + 1] - t[k]

            def rhs(tau, xx):
                uu = u0 if hold == 'zoh' else u0 + (tau - tk) / hk * (u1 - u0)
                return sys.A(tau) @ xx + sys.B(tau) @ uu
            sol = solve_ivp(rhs, (a, b), xr, method='DOP853', rtol=rtol, atol=rtol * 1e-3)
            if not sol.success:
                raise RuntimeError(f"solve_ivp failed: {sol.message}")
            xr = sol.y[:, -1]
            x[:, r, at == i + 1] = xr[:, None]
    return x


def _outputs(sys, t, x, u):
    if not sys.isdtime():
        return outputs(sys.C, sys.D, t, x, u)
    N = sys.nsteps
    idx = np.round(t / sys.dt).astype(int) % N
    C, D = sys.C.sample(N)[idx], sys.D.sample(N)[idx]
    # y_l = C_l x_l + D_l u_l, batched over time
    y = C @ x.transpose(2, 0, 1) + D @ u.transpose(2, 0, 1)
    return y.transpose(1, 2, 0)


#
# Argument processing
#

def forced_result(sys, t, x, y, u, inputs, transpose, return_states, squeeze):
    """The `TimeResponseData` of a forced response (x None: no states).

    ``x``, ``y``, ``u`` are (signals, traces, time); one trace of a 2-D
    `inputs` comes back as a single response.

    Examples
    --------
    >>> from ltpcontrol._core.timeresp import forced_result
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> t = np.linspace(0, 1, 3)
    >>> u = np.ones((1, 1, 3))
    >>> forced_result(sys, t, None, u, u, u[:, 0], False, False, None).outputs.shape
    (3,)
    """
    if x is None:                               # no states: an empty signal array
        x = np.empty((0,) + y.shape[1:])
    multi = u.shape[1] > 1 or np.ndim(inputs) == 3
    if not multi:
        x, y, u = x[:, 0], y[:, 0], u[:, 0]
    return ct.TimeResponseData(
        t, y, x, u, issiso=sys.issiso() and not multi, output_labels=sys.output_labels,
        input_labels=sys.input_labels, state_labels=sys.state_labels if len(x) else [],
        title="Forced response for " + sys.name, transpose=transpose,
        return_x=return_states, squeeze=squeeze, multi_trace=multi,
        trace_types=['forced'] * u.shape[1] if multi else None,
        sysname=sys.name, plot_inputs=True)


def forced_arguments(sys, timepts, inputs, initial_state, method, methods, input_hold,
                     rtol=None):
    """The validated arguments of a forced response: ``(t, u, ntraces, x0)``.

    Checks `method` (one of `methods`), `input_hold` ('foh' or 'zoh') and,
    when given, `rtol` (in (0, 1)), then builds the time vector, the input
    array ``(ninputs, ntraces, len(t))`` and the initial states ``(n,
    ntraces)``, as every ``forced_response`` of the library does.

    Examples
    --------
    >>> from ltpcontrol._core.timeresp import forced_arguments
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> t, u, ntraces, x0 = forced_arguments(sys, [0.0, 0.5, 1.0], 1.0, 0.0,
    ...                                      'transition', ('transition',), 'foh')
    >>> u.shape, ntraces, x0.shape
    ((1, 1, 3), 1, (1, 1))
    """
    if method not in methods:
        raise ValueError(f"method must be {' or '.join(repr(m) for m in methods)}, "
                         f"got {method!r}")
    if input_hold not in ('foh', 'zoh'):
        raise ValueError(f"input_hold must be 'foh' or 'zoh', got {input_hold!r}")
    if rtol is not None and (isinstance(rtol, (bool, np.bool_))
                             or not isinstance(rtol, numbers.Real) or not 0 < rtol < 1):
        raise ValueError(f"rtol must be a number in (0, 1), got {rtol!r}")
    t = _time_vector(sys, timepts)
    u, ntraces = _input_array(sys, inputs, len(t))
    return t, u, ntraces, _initial_state(sys, initial_state, ntraces)


def _time_vector(sys, timepts, is_step=None):
    if is_step is not None and sys.is_lti and np.ndim(timepts) == 0:
        # an LTI system written as periodic: python-control's default grid
        if timepts is not None:
            timepts = check_positive(float(real_array(timepts, 'timepts', ndim=0)), 'timepts')
        return _default_time_vector(sys.to_ss(), tfinal=timepts, is_step=is_step)
    if timepts is None:
        timepts = _default_final_time(sys)
    t = real_array(timepts, 'timepts', ndim=(0, 1))
    if t.ndim == 0:
        if t <= 0:
            raise ValueError(f"timepts as a final time must be positive, got {float(t)}")
        step = sys.dt if sys.isdtime() else sys.period / 50
        t = np.arange(int(np.floor(float(t) / step + 1e-9)) + 1) * step
    if len(t) == 0:
        raise ValueError("timepts is empty")
    if np.any(np.diff(t) <= 0):
        raise ValueError("timepts must be strictly increasing")
    if sys.isdtime():
        k = t / sys.dt
        if np.any(np.abs(k - np.round(k)) > 1e-9 * np.maximum(1, np.abs(k))):
            raise ValueError(f"timepts must be multiples of dt={sys.dt} for a "
                             "discrete-time system")
        if np.any(np.diff(np.round(k)) != 1):
            raise ValueError(f"timepts must be consecutive samples spaced by dt={sys.dt}")
    return t


def _default_final_time(sys):
    # five periods, or five time constants of the slowest multiplier |μ| = e^{σT}
    try:
        mu = np.max(np.abs(sys.floquet_multipliers()))
    except Exception:
        mu = 1.0
    settle = 5 * sys.period / -np.log(mu) if 0 < mu < 1 else 0.0
    return min(max(5 * sys.period, settle), 1000 * sys.period)


def _input_array(sys, inputs, L):
    u = real_array(inputs, 'inputs', ndim=(0, 1, 2, 3))
    m = sys.ninputs
    if u.ndim == 0:
        return np.full((m, 1, L), float(u)), 1
    if u.ndim == 1:
        if m != 1:
            raise ControlDimension(f"inputs must have shape ({m}, {L}) for a system with "
                                   f"{m} inputs, got {u.shape}")
        u = u[np.newaxis]
    if u.ndim == 2:
        u = u[:, np.newaxis, :]
    if u.shape[0] != m or u.shape[2] != L:
        raise ControlDimension(f"inputs must have shape ({m}, [ntraces,] {L}), got {u.shape}")
    return u, u.shape[1]


def _initial_state(sys, x0, ntraces):
    x0 = real_array(x0, 'initial_state', ndim=(0, 1, 2))
    n = sys.nstates
    if x0.ndim == 0:
        return np.full((n, ntraces), float(x0))
    if x0.ndim == 1:
        if x0.shape[0] != n:
            raise ControlDimension(f"initial_state must have {n} entries, got {x0.shape[0]}")
        return np.repeat(x0[:, None], ntraces, axis=1)
    if x0.shape != (n, ntraces):
        raise ControlDimension(f"initial_state must have shape ({n}, {ntraces}), got {x0.shape}")
    return x0.copy()


def _indices(spec, count, name):
    if spec is None:
        return list(range(count))
    spec = [spec] if np.isscalar(spec) else list(spec)
    for i in spec:
        if not isinstance(i, (int, np.integer)) or not 0 <= i < count:
            raise ValueError(f"{name} must contain integers in [0, {count}), got {i!r}")
    return [int(i) for i in spec]


def _trace_response(sys, t, u, x, y, ins, outs, trace_type, title, return_states,
                    squeeze, transpose):
    # as python-control: the inputs and outputs of the selected channels only
    y, u = y[outs], u[ins]
    return ct.TimeResponseData(
        t, y, x, u, issiso=len(outs) == 1 and len(ins) == 1,
        output_labels=[sys.output_labels[i] for i in outs],
        input_labels=[sys.input_labels[i] for i in ins],
        state_labels=sys.state_labels, title=f"{title} for {sys.name}",
        transpose=transpose, return_x=return_states, squeeze=squeeze, multi_trace=True,
        trace_labels=[f"From {sys.input_labels[i]}" for i in ins],
        trace_types=[trace_type] * len(ins), sysname=sys.name, plot_inputs=False)
