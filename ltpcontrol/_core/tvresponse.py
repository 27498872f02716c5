"""Time responses of discrete periodic systems whose dimensions vary over the period.

`ltpcontrol.forced_response` and `ltpcontrol.initial_response` take a
`DiscreteLTPSystem` through the registry's overrides (as systems with delays
do), with python-control's conventions for discrete time: the time points
are consecutive multiples ``t_j = (k_0 + j) dt`` of the sampling time (by
default ``k dt`` for the samples of `inputs`), the first one fixing the step
of the period, ``k_0 mod N``, at which `initial_state` (``n_{k_0}``
entries) is given; ``y_j = C_k x_j + D_k u_j`` and ``x_{j+1} = A_k x_j +
B_k u_j`` with ``k = (k_0 + j) mod N``; several traces are simulated at
once when `inputs` has shape ``(m, ntraces, K)``.

The signals of a `control.TimeResponseData` are arrays, so the numbers of
inputs and outputs must be the same at every step; the states are returned
when the state dimension is constant too, and otherwise left out (zero
rows): `DiscreteLTPSystem.forced_response` returns the states of every step
as a list.
"""

import control as ct
import numpy as np
from control.exception import ControlDimension

from .registry import override
from .timeresp import _indices, _initial_state, _input_array, _time_vector
from .tvsystem import DiscreteLTPSystem
from .validation import check_kwargs

__all__ = []


class _Constant:
    """The system seen with its constant input, output (and state) counts, as the
    argument checks of `ltpcontrol.forced_response` expect."""

    def __init__(self, sys, nstates):
        for label, dims in (('inputs', sys.ninputs), ('outputs', sys.noutputs)):
            if len(set(dims)) > 1:
                raise ControlDimension(
                    f"the number of {label} varies with the step ({dims}): a "
                    "TimeResponseData needs the same number at every step; use "
                    "sys.forced_response(U), which takes and returns lists")
        self.sys, self.dt, self.period = sys, sys.dt, sys.period
        self.nstates, self.ninputs, self.noutputs = nstates, sys.ninputs[0], sys.noutputs[0]

    def isdtime(self, strict=False):
        return True

    def floquet_multipliers(self):
        return self.sys.floquet_multipliers()


def _grid(sys, timepts, inputs):
    if timepts is None and np.ndim(inputs) > 0:
        timepts = np.arange(np.shape(inputs)[-1]) * sys.dt      # python-control's k dt
    t = _time_vector(_Constant(sys, sys.nstates[0]), timepts)
    k0 = int(round(t[0] / sys.dt)) % sys.nsteps
    return t, k0


def _march(sys, k0, u, x):
    """States (list, one ``(n_k, ntraces)`` array per sample) and outputs ``(p, ntraces, K)``."""
    N, K = sys.nsteps, u.shape[2]
    y = np.empty((sys.noutputs[0], u.shape[1], K))
    xs = []
    for j in range(K):
        k = (k0 + j) % N
        xs.append(x)
        y[:, :, j] = sys.C[k] @ x + sys.D[k] @ u[:, :, j]
        x = sys.A[k] @ x + sys.B[k] @ u[:, :, j]
    return xs, y


@override('forced_response', DiscreteLTPSystem)
def forced_response(sys, timepts=None, inputs=0.0, initial_state=0.0, *, method='transition',
                    input_hold='foh', rtol=1e-12, compute_states=True, return_states=False,
                    squeeze=None, transpose=False, **kwargs):
    """`ltpcontrol.forced_response` of a `DiscreteLTPSystem` (module notes).

    `method`, `input_hold` and `rtol` do not apply (the recursion is exact)
    and are accepted for the common signature.

    Examples
    --------
    The states are 2, 1, 2 over a period of 3 steps; one input, one output:

    >>> sys = ltp.dltpss([[[0.5, 0.0]], [[1.0], [0.5]], [[0.5, 0.0], [0.0, 0.5]]],
    ...                  [[[1.0]], [[0.0], [1.0]], [[1.0], [0.0]]],
    ...                  [[[1.0, 0.0]], [[1.0]], [[0.0, 1.0]]], 0)
    >>> resp = ltp.forced_response(sys, inputs=np.ones(6))
    >>> np.asarray(resp.outputs)
    array([0.   , 1.   , 1.5  , 1.5  , 1.75 , 1.875])
    >>> resp.states.shape                  # the state dimension varies: left out
    (0, 6)
    """
    check_kwargs(kwargs, 'forced_response')
    if not isinstance(compute_states, (bool, np.bool_)):
        raise ValueError(f"compute_states must be True or False, got {compute_states!r}")
    if return_states and not compute_states:
        raise ValueError("return_states=True needs compute_states=True")
    t, k0 = _grid(sys, timepts, inputs)
    view = _Constant(sys, sys.nstates[k0])
    u, ntraces = _input_array(view, inputs, len(t))
    x0 = _initial_state(view, initial_state, ntraces)
    xs, y = _march(sys, k0, u, x0)
    constant = len(set(sys.nstates)) == 1 and compute_states
    x = np.stack(xs, axis=-1) if constant else np.empty((0, ntraces, len(t)))
    multi = ntraces > 1 or np.ndim(inputs) == 3
    if not multi:
        x, y, u = x[:, 0], y[:, 0], u[:, 0]
    return ct.TimeResponseData(
        t, y, x, u, issiso=view.ninputs == view.noutputs == 1 and not multi,
        title="Forced response for " + sys.name, transpose=transpose,
        return_x=return_states, squeeze=squeeze, multi_trace=multi,
        trace_types=['forced'] * ntraces if multi else None, sysname=sys.name,
        plot_inputs=True)


@override('initial_response', DiscreteLTPSystem)
def initial_response(sys, timepts=None, initial_state=0.0, output_indices=None, *,
                     method='transition', input_hold='foh', rtol=1e-12, return_states=False,
                     squeeze=None, transpose=False, **kwargs):
    """`ltpcontrol.initial_response` of a `DiscreteLTPSystem` (module notes).

    Examples
    --------
    >>> sys = ltp.dltpss([[[0.5, 0.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
    ...                  [[[1.0, 1.0]], [[1.0]]], 0)
    >>> np.asarray(ltp.initial_response(sys, 3.0, initial_state=[2.0, 1.0]).outputs)
    array([3. , 1. , 1.5, 0.5])
    """
    check_kwargs(kwargs, 'initial_response')
    if timepts is None:
        timepts = 5.0 * sys.period
    resp = forced_response(sys, timepts, 0.0, initial_state, return_states=return_states,
                           squeeze=squeeze, transpose=transpose)
    outs = _indices(output_indices, sys.noutputs[0], 'output_indices')
    y = np.asarray(resp.outputs).reshape(sys.noutputs[0], -1)[outs]
    return ct.TimeResponseData(
        resp.time, y if len(outs) > 1 else y[0], resp.states, None,
        issiso=len(outs) == 1, title="Initial response for " + sys.name,
        trace_types=['initial'], transpose=transpose, return_x=return_states,
        squeeze=squeeze, sysname=sys.name)
