"""Pure delay elements and block diagrams of periodic systems with delays.

`delay` is the transfer ``e^{-sτ}`` (``z^{-k}`` in a discrete loop).
`ltpcontrol.series`, `parallel`, `feedback` and `interconnect` hand any
diagram holding a delay element or a delayed system to the functions here
(through `ltpcontrol._core.registry.override`).  In continuous time the
result is an `LTPDelayStateSpace`: the formulas of the undelayed diagrams
hold with every matrix a delay polynomial (`ltpcontrol._delays.terms`), so
a loop closed through a delay gives state delays, and delays outside loops
give input and output delays.  A loop whose algebraic part passes through a
delay (``u(t)`` depending on ``u(t - τ)``: a neutral equation) is refused.
In a discrete-time diagram a delay of k = τ/dt steps (k an integer) is a
shift register of k states, and the result is an ordinary `LTPStateSpace`.
"""

import numbers

import numpy as np
import control as ct
from control.exception import ControlArgument, ControlDimension

from .._core.ltpsys import (LTPStateSpace, _loop_inverse, _merge_period, feedback as _feedback,
                            parallel as _parallel, series as _series)
from .._core.interconnect import _control_interconnect, interconnect as _interconnect
from .._core.periodic_matrix import PeriodicMatrix
from .._core.registry import override
from .ltpdsys import LTPDelayStateSpace, as_delayed, check_delay
from . import terms as tm

__all__ = ['Delay', 'delay']


class Delay(ct.InputOutputSystem):
    """Pure delay ``y(t) = u(t - τ)`` on each channel (built by `delay`).

    Parameters
    ----------
    tau : float
        The delay τ > 0.
    dt : float, optional
        0 or None (default): the timebase of the diagram it joins; a
        positive sampling time makes it discrete (τ must be a whole number
        of steps).
    name, inputs, outputs : optional
        Signal names; the number of channels is the number of inputs
        (default one, which widens to any number of channels in `series`
        and `feedback`).

    Attributes
    ----------
    tau : float
        The delay.
    gain : float
        A scalar gain (``k * delay(tau)``), 1 by default.

    Examples
    --------
    >>> ltp.delay(0.1)
    <Delay: ['u[0]'] -> ['y[0]'], tau=0.1>
    """

    def __init__(self, tau, dt=None, *, name=None, inputs=None, outputs=None):
        self.tau = check_delay(tau)
        if dt is not None and dt is not True:
            if isinstance(dt, bool) or not isinstance(dt, numbers.Real) or dt < 0 \
                    or not np.isfinite(dt):
                raise ValueError(f"dt must be None, 0 or a positive sampling time, got {dt!r}")
        inputs = 1 if inputs is None else inputs
        width = inputs if isinstance(inputs, int) else (1 if isinstance(inputs, str)
                                                         else len(inputs))
        outputs = width if outputs is None else outputs
        super().__init__(name=name, inputs=inputs, outputs=outputs, states=0,
                         dt=None if dt in (None, 0) else dt)
        if self.noutputs != self.ninputs:
            raise ControlDimension(f"a delay has as many outputs as inputs, got "
                                   f"{self.ninputs} inputs and {self.noutputs} outputs")
        self._broadcast = self.ninputs == 1 and inputs == 1 and outputs == 1
        self.gain = 1.0

    def _scaled(self, c):
        out = Delay(self.tau, self.dt, name=self.name,
                    inputs=1 if self._broadcast else self.input_labels,
                    outputs=1 if self._broadcast else self.output_labels)
        out.gain = self.gain * float(c)
        return out

    def __repr__(self):
        gain = f", gain={self.gain:g}" if self.gain != 1 else ""
        return f"<Delay: {self.input_labels} -> {self.output_labels}, tau={self.tau:g}{gain}>"

    __str__ = __repr__

    def __mul__(self, other):
        if isinstance(other, numbers.Real) and not isinstance(other, bool):
            return self._scaled(other)
        return series(other, self)

    def __rmul__(self, other):
        if isinstance(other, numbers.Real) and not isinstance(other, bool):
            return self._scaled(other)
        return series(self, other)

    def __add__(self, other):
        return parallel(self, other)

    __radd__ = __add__

    def __neg__(self):
        return self._scaled(-1.0)


def delay(tau, dt=None, *, name=None, inputs=None, outputs=None):
    """Pure delay element ``e^{-sτ}`` for block diagrams with LTP systems.

    Use it in `series`, `parallel`, `feedback` and `interconnect` (or with
    ``*`` and ``+``) next to `LTPStateSpace` systems: the result is an
    `LTPDelayStateSpace` (continuous time), whose analysis keeps the delay
    exact; a loop closed through it gives a state delay.  In a
    discrete-time diagram the delay must be a whole number k of sampling
    steps and becomes a shift register ``z^{-k}``.

    Parameters
    ----------
    tau : float
        The delay τ > 0.
    dt : float, optional
        Sampling time for a discrete delay (default: that of the diagram).
    name, inputs, outputs : optional
        Signal names (default one channel ``u[0] -> y[0]``, widened in
        `series` and `feedback` to the channels it meets).

    Returns
    -------
    Delay

    Raises
    ------
    ValueError
        For a delay that is not finite and positive, and (when combined)
        for a delay that is not a whole number of steps of a discrete loop.

    Examples
    --------
    A first-order plant with a periodic gain and 0.2 s of computation
    delay in its feedback loop:

    >>> P = ltp.ltpss([[0.0]], lambda t: np.array([[1 + 0.5 * np.cos(2 * np.pi * t)]]),
    ...               [[1.0]], 0, period=1.0)
    >>> loop = ltp.feedback(P, 2.0 * ltp.delay(0.2))
    >>> loop.delays
    (0.2,)
    >>> ltp.is_stable(loop)
    True
    """
    return Delay(tau, dt, name=name, inputs=inputs, outputs=outputs)


#
# Conversion of the operands
#

def _is_discrete(obj):
    return isinstance(obj, (LTPStateSpace, ct.StateSpace, ct.TransferFunction)) \
        and obj.isdtime(strict=True) and getattr(obj, 'nstates', 1) > 0


def _period(objs, where):
    """Common period of the periodic operands (constant ones fit any period)."""
    period, lti = None, None
    for o in objs:
        if isinstance(o, (LTPStateSpace, LTPDelayStateSpace, PeriodicMatrix)):
            if _constant(o):
                lti = o.period if lti is None else lti
                continue
            period = o.period if period is None else _merge_period(period, o.period)
    if period is None:
        period = lti
    if period is None:
        if not any(isinstance(o, Delay) for o in objs):
            raise ControlArgument(f"{where}: at least one system must be periodic "
                                  "(LTPStateSpace, LTPDelayStateSpace or PeriodicMatrix)")
        period = 1.0        # a diagram of delays and LTI blocks: constant, any period
    return period


def _constant(o):
    if isinstance(o, PeriodicMatrix):
        return o.is_constant
    return o.is_lti


def _rebase(o, period):
    """A periodic operand with the diagram's period."""
    if isinstance(o, PeriodicMatrix):
        return o.with_period(period) if not o.is_constant else \
            PeriodicMatrix.constant(o(0.0), period)
    if o.period == period:
        return o
    fix = (lambda M: PeriodicMatrix.constant(M(0.0), period)) if _constant(o) else \
        (lambda M: M.with_period(period))
    names = dict(name=o.name, inputs=o.input_labels, outputs=o.output_labels,
                 states=o.state_labels)
    if isinstance(o, LTPStateSpace):
        return LTPStateSpace(fix(o.A), fix(o.B), fix(o.C), fix(o.D), period, dt=o.dt, **names)
    return LTPDelayStateSpace({k: {a: fix(M) for a, M in X.items()}
                               for k, X in o.terms.items()}, period, **names)


def _shift_register(d, period, dt, width):
    """Discrete delay z^{-k} (k = τ/dt steps) as an LTPStateSpace."""
    if d.dt not in (None, True) and d.dt != dt:
        raise ValueError(f"the delay has dt={d.dt} but the diagram dt={dt}")
    k = d.tau / dt
    if abs(k - round(k)) > 1e-9 * max(1.0, k):
        raise ValueError(f"a delay of tau={d.tau:g} in a discrete-time diagram with "
                         f"dt={dt:g} is {k:.6g} steps; it must be a whole number of steps")
    k = int(round(k))
    n = k * width
    A = np.zeros((n, n))
    A[width:, :-width] = np.eye(n - width)
    B = np.zeros((n, width))
    B[:width] = np.eye(width)
    C = np.zeros((width, n))
    C[:, -width:] = d.gain * np.eye(width)
    names = {} if d._broadcast else dict(inputs=d.input_labels, outputs=d.output_labels)
    return LTPStateSpace(A, B, C, np.zeros((width, width)), period, dt=dt, name=d.name,
                         **names)


def _delay_terms(d, period, width):
    width = (width or 1) if d._broadcast else d.ninputs
    I = PeriodicMatrix.constant(d.gain * np.eye(width), period)
    Z = lambda r, c: PeriodicMatrix.constant(np.zeros((r, c)), period)  # noqa: E731
    names = {} if d._broadcast else dict(inputs=d.input_labels, outputs=d.output_labels)
    return LTPDelayStateSpace({'A': {0.0: Z(0, 0)}, 'B': {0.0: Z(0, width)},
                               'C': {0.0: Z(width, 0)}, 'D': {d.tau: I}}, period,
                              name=d.name, **names)


def _convert(objs, where, widths):
    """Operands as delayed systems (continuous) or LTP systems (discrete), and a flag."""
    period = _period(objs, where)
    objs = [_rebase(o, period) if isinstance(o, (LTPStateSpace, LTPDelayStateSpace,
                                                 PeriodicMatrix)) else o for o in objs]
    discrete = [o for o in objs if _is_discrete(o)]
    if discrete:
        if any(isinstance(o, LTPDelayStateSpace) for o in objs):
            raise ValueError(f"{where}: a continuous-time system with delays cannot be "
                             "combined with a discrete-time one")
        dt = discrete[0].dt
        return [(_shift_register(o, period, dt, w or 1) if isinstance(o, Delay) else o)
                for o, w in zip(objs, widths)], True
    out = []
    for o, w in zip(objs, widths):
        if isinstance(o, Delay):
            out.append(_delay_terms(o, period, w))
        else:
            out.append(as_delayed(o, period, w))
    return out, False


def _result(terms, period, **kwargs):
    return LTPDelayStateSpace(terms, period, **kwargs)


#
# The connections
#

@override('series', Delay)
@override('series', LTPDelayStateSpace)
def series(*systems, **kwargs):
    """`ltpcontrol.series` of a diagram with delays (see the module notes).

    Examples
    --------
    An input delay of an LTI plant written as periodic:

    >>> P = ltp.ltpss(ct.ss([[-1.0]], [[1.0]], [[1.0]], 0), 1.0)
    >>> Pd = ltp.series(ltp.delay(0.3), P)
    >>> Pd.delays, float(Pd.terms['B'][0.3](0.0)[0, 0]), float(Pd.B(0.0)[0, 0])
    ((0.3,), 1.0, 0.0)
    """
    if len(systems) < 2:
        raise ControlArgument(f"series needs at least two systems, got {len(systems)}")
    out = systems[0]
    for k, s in enumerate(systems[1:]):
        last = k == len(systems) - 2
        out = _series2(out, s, **(kwargs if last else {}))
    return out


def _series2(sys1, sys2, **kwargs):
    w1 = _known_width(sys1, 'out')
    w2 = _known_width(sys2, 'in')
    (s1, s2), discrete = _convert([sys1, sys2], 'series', [w2, w1])
    if discrete:
        return _series(s1, s2, **kwargs)
    if s1.noutputs != s2.ninputs:
        raise ControlDimension(f"series: sys1 has {s1.noutputs} outputs but sys2 has "
                               f"{s2.ninputs} inputs")
    T = s1.period
    a, b = s1.terms, s2.terms
    n1, n2 = s1.nstates, s2.nstates
    A = tm.block([[a['A'], np.zeros((n1, n2))], [tm.matmul(b['B'], a['C']), b['A']]], T)
    B = tm.block([[a['B']], [tm.matmul(b['B'], a['D'])]], T)
    C = tm.block([[tm.matmul(b['D'], a['C']), b['C']]], T)
    D = tm.matmul(b['D'], a['D'])
    kwargs.setdefault('inputs', s1.input_labels)
    kwargs.setdefault('outputs', s2.output_labels)
    return _result({'A': A, 'B': B, 'C': C, 'D': D}, T, **kwargs)


def _known_width(obj, side):
    if isinstance(obj, Delay):
        return None if obj._broadcast else obj.ninputs
    if isinstance(obj, (numbers.Real, np.ndarray, list)):
        return None
    return obj.noutputs if side == 'out' else obj.ninputs


@override('parallel', Delay)
@override('parallel', LTPDelayStateSpace)
def parallel(*systems, **kwargs):
    """`ltpcontrol.parallel` of a diagram with delays (see the module notes).

    Examples
    --------
    >>> P = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> (P + ltp.delay(0.5)).delays
    (0.5,)
    """
    if len(systems) < 2:
        raise ControlArgument(f"parallel needs at least two systems, got {len(systems)}")
    out = systems[0]
    for k, s in enumerate(systems[1:]):
        last = k == len(systems) - 2
        out = _parallel2(out, s, **(kwargs if last else {}))
    return out


def _parallel2(sys1, sys2, **kwargs):
    w = _known_width(sys1, 'in') or _known_width(sys2, 'in') or 1
    (s1, s2), discrete = _convert([sys1, sys2], 'parallel', [w, w])
    if discrete:
        return _parallel(s1, s2, **kwargs)
    if s1.shape != s2.shape:
        raise ControlDimension(f"parallel: systems have shapes {s1.shape} and {s2.shape}")
    T = s1.period
    a, b = s1.terms, s2.terms
    n1, n2 = s1.nstates, s2.nstates
    A = tm.block([[a['A'], np.zeros((n1, n2))], [np.zeros((n2, n1)), b['A']]], T)
    B = tm.block([[a['B']], [b['B']]], T)
    C = tm.block([[a['C'], b['C']]], T)
    kwargs.setdefault('inputs', s1.input_labels)
    kwargs.setdefault('outputs', s1.output_labels)
    return _result({'A': A, 'B': B, 'C': C, 'D': tm.add(a['D'], b['D'])}, T, **kwargs)


@override('feedback', Delay)
@override('feedback', LTPDelayStateSpace)
def feedback(sys1, sys2=1, sign=-1, **kwargs):
    """`ltpcontrol.feedback` of a loop with delays (see the module notes).

    Examples
    --------
    ``ẋ = u - k x(t - τ)``: unity feedback of an integrator through a delay
    has the state delay ``-k`` at τ:

    >>> P = ltp.ltpss([[0.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> L = ltp.feedback(P, 0.5 * ltp.delay(0.4))
    >>> [(tau, float(M(0.0)[0, 0])) for tau, M in L.state_delays]
    [(0.4, -0.5)]
    """
    if sign not in (-1, 1):
        raise ValueError(f"sign must be -1 or 1, got {sign!r}")
    w1 = _known_width(sys1, 'out')
    w0 = _known_width(sys1, 'in')
    (s1, s2), discrete = _convert([sys1, sys2], 'feedback', [w0, w1])
    if discrete:
        return _feedback(s1, s2, sign, **kwargs)
    if s1.noutputs != s2.ninputs or s2.noutputs != s1.ninputs:
        raise ControlDimension("feedback: sys2 must map the outputs of sys1 to its inputs "
                               f"(sys1 {s1.shape}, sys2 {s2.shape})")
    T = s1.period
    a, b = s1.terms, s2.terms
    n1, n2 = s1.nstates, s2.nstates
    F = _inverse(tm.scale(tm.matmul(a['D'], b['D']), float(sign)), T, "feedback")
    Cy = tm.matmul(F, tm.block([[a['C'], tm.scale(tm.matmul(a['D'], b['C']), sign)]], T))
    Dy = tm.matmul(F, a['D'])
    G = tm.block([[tm.scale(tm.matmul(a['B'], b['D']), sign)], [b['B']]], T)
    A = tm.add(tm.block([[a['A'], tm.scale(tm.matmul(a['B'], b['C']), sign)],
                         [np.zeros((n2, n1)), b['A']]], T), tm.matmul(G, Cy))
    B = tm.add(tm.block([[a['B']], [np.zeros((n2, s1.ninputs))]], T), tm.matmul(G, Dy))
    kwargs.setdefault('inputs', s1.input_labels)
    kwargs.setdefault('outputs', s1.output_labels)
    return _result({'A': A, 'B': B, 'C': Cy, 'D': Dy}, T, **kwargs)


def _inverse(L, period, where):
    """``(I - L)^{-1}`` of a delay polynomial L whose delayed part is nilpotent."""
    p = next(iter(L.values())).shape[0]
    I = PeriodicMatrix.constant(np.eye(p), period)
    L0 = tm.undelayed(L, (p, p), period)
    F0 = {0.0: _loop_inverse(I - L0, where)}
    Ld = {a: M for a, M in L.items() if a > 0}
    if not Ld:
        return F0
    Y = tm.matmul(F0, Ld)
    out, power = dict(F0), dict(F0)
    for _ in range(p + 1):
        power = tm.matmul(Y, power)
        power = {a: M for a, M in power.items() if not tm.is_zero(M)}
        if not power:
            return out
        out = tm.add(out, power)
    raise ValueError(f"{where}: the loop's direct path passes through a delay (the signal "
                     "depends on its own delayed value: a neutral equation); add dynamics "
                     "to the loop")


@override('interconnect', Delay)
@override('interconnect', LTPDelayStateSpace)
def interconnect(syslist, connections=None, inplist=None, outlist=None, **kwargs):
    """`ltpcontrol.interconnect` of a diagram with delays (see the module notes).

    Examples
    --------
    >>> P = ltp.ltpss([[0.0]], [[1.0]], [[1.0]], 0, period=1.0, inputs='u', outputs='y')
    >>> Dl = ltp.delay(0.25, inputs='y', outputs='ym', name='D')
    >>> err = ct.summing_junction(['r', '-ym'], 'u')
    >>> L = ltp.interconnect([P, Dl, err], inplist='r', outlist='y')
    >>> L.state_delays[0][0], L.shape
    (0.25, (1, 1))
    """
    if kwargs.pop('params', None):
        raise ControlArgument("interconnect: LTP blocks have no parameters")
    blocks = list(syslist)
    if any(_is_discrete(b) for b in blocks):
        period = _period(blocks, 'interconnect')
        dt = next(b.dt for b in blocks if _is_discrete(b))
        blocks = [_shift_register(b, period, dt, b.ninputs) if isinstance(b, Delay) else b
                  for b in blocks]
        return _interconnect(blocks, connections, inplist, outlist, **kwargs)
    period = _period(blocks, 'interconnect')
    blocks = [_rebase(b, period) if isinstance(b, (LTPStateSpace, LTPDelayStateSpace,
                                                   PeriodicMatrix)) else b for b in blocks]
    proxies, delayed = [], []
    for i, b in enumerate(blocks):
        if isinstance(b, ct.TransferFunction):
            b = ct.ss(b, name=b.name)
        if isinstance(b, Delay):
            d = _delay_terms(b, period, b.ninputs)
            d = LTPDelayStateSpace(d.terms, period, name=b.name, inputs=b.input_labels,
                                   outputs=b.output_labels)
        elif isinstance(b, ct.InputOutputSystem) and not isinstance(
                b, (LTPStateSpace, LTPDelayStateSpace, ct.StateSpace)):
            raise ControlArgument(f"interconnect: block {i} is a {type(b).__name__}")
        elif isinstance(b, ct.InputOutputSystem):
            d = as_delayed(b, period)
            d = LTPDelayStateSpace(d.terms, period, name=b.name, inputs=b.input_labels,
                                   outputs=b.output_labels, states=b.state_labels)
        else:
            d = as_delayed(b, period)
            d = LTPDelayStateSpace(d.terms, period, name=f"sys[{i}]")
        delayed.append(d)
        # a named stand-in with the block's signals for python-control's name resolution
        proxies.append(ct.ss(np.zeros((d.nstates, d.nstates)), np.zeros((d.nstates, d.ninputs)),
                             np.zeros((d.noutputs, d.nstates)), np.zeros(d.shape),
                             name=d.name, inputs=d.input_labels, outputs=d.output_labels,
                             states=d.state_labels))
    ic = _control_interconnect()(proxies, connections=connections, inplist=inplist,
                                  outlist=outlist, **kwargs)
    order = [next(d for d, p in zip(delayed, proxies) if p.name == s.name) for s in ic.syslist]
    T = period
    big = {k: tm.block([[_diag_term(order, k, i, j, T) for j in range(len(order))]
                        for i in range(len(order))], T) for k in 'ABCD'}
    M, N = ic.connect_map, ic.input_map
    nw = sum(d.noutputs for d in order)
    Pw, Pv = ic.output_map[:, :nw], ic.output_map[:, nw:]
    c = lambda X: {0.0: PeriodicMatrix.constant(np.asarray(X, float), T)}  # noqa: E731
    F = _inverse(tm.matmul(c(M), big['D']), T, "interconnect")
    Ux = tm.matmul(F, tm.matmul(c(M), big['C']))
    Uu = tm.matmul(F, c(N))
    A = tm.add(big['A'], tm.matmul(big['B'], Ux))
    B = tm.matmul(big['B'], Uu)
    C = tm.add(tm.matmul(c(Pw), tm.add(big['C'], tm.matmul(big['D'], Ux))),
               tm.matmul(c(Pv), Ux))
    D = tm.matmul(tm.add(tm.matmul(c(Pw), big['D']), c(Pv)), Uu)
    return LTPDelayStateSpace({'A': A, 'B': B, 'C': C, 'D': D}, T, name=ic.name,
                              inputs=ic.input_labels, outputs=ic.output_labels,
                              states=ic.state_labels)


def _diag_term(blocks, key, i, j, period):
    """Block (i, j) of the block-diagonal `key` matrix of the appended blocks."""
    rows = {'A': 'nstates', 'B': 'nstates', 'C': 'noutputs', 'D': 'noutputs'}[key]
    cols = {'A': 'nstates', 'B': 'ninputs', 'C': 'nstates', 'D': 'ninputs'}[key]
    if i == j:
        return blocks[i].terms[key]
    return np.zeros((getattr(blocks[i], rows), getattr(blocks[j], cols)))
