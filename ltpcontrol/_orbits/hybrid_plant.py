"""Hybrid plants: modes with a flow, a guard and a reset, evaluated with checks.

A hybrid plant (thesis §3.2.2) is a set of charts (modes), each with a smooth
flow ``dx/dt = f_i(t, x, u, params)``, one threshold (guard) function
``g_i(t, x, u, params)`` and a transition (reset) map ``x⁺ = r_i(t, x⁻, u,
params)`` leading to a target mode.  A mode is left when its guard crosses
zero from positive to negative.  Periodic forcing enters through the explicit
time argument ("clock-driven" plants, thesis eq. 3.1).  Jacobians a mode
does not give are central differences.  Simulation: ``_orbits/hybrid.py``.
"""

import numbers

import numpy as np
from control.exception import ControlArgument, ControlDimension

from .._core.validation import check_positive_int

__all__ = ['HybridMode', 'HybridPlant']

# relative step of central differences: eps^(1/3) balances truncation and roundoff
_FD_STEP = np.finfo(float).eps ** (1 / 3)


class HybridMode:
    """One chart (mode) of a `HybridPlant`.

    Parameters
    ----------
    updfcn : callable
        Vector field ``updfcn(t, x, u, params) -> dx/dt`` of the mode.
    guard : callable, optional
        Threshold function ``guard(t, x, u, params) -> float``.  It is
        positive while the mode is active; the transition fires when it
        crosses zero from positive to negative.  Without a guard the mode is
        never left.
    reset : callable, optional
        Transition map ``reset(t, x, u, params) -> x⁺`` applied at the event
        (state jumps such as a touchdown impact).  Identity when omitted.
    target : int or str, optional
        Index or name of the mode entered at the event.  Required with a
        guard.
    name : str, optional
        Mode name (``'mode[i]'`` when omitted).
    jacobian : callable, optional
        Analytic ``jacobian(t, x, u, params) -> ∂f/∂x`` (n x n).  Central
        finite differences are used when omitted.
    input_jacobian : callable, optional
        Analytic ``input_jacobian(t, x, u, params) -> ∂f/∂u`` (n x m).

    Examples
    --------
    >>> up = ltp.HybridMode(lambda t, x, u, p: [x[1], -1.0],
    ...                     guard=lambda t, x, u, p: x[0],
    ...                     reset=lambda t, x, u, p: [0.0, -0.8 * x[1]],
    ...                     target='air', name='air')
    >>> up.name
    'air'
    """

    def __init__(self, updfcn, guard=None, reset=None, target=None, name=None,
                 jacobian=None, input_jacobian=None):
        for arg, label in [(updfcn, 'updfcn'), (guard, 'guard'), (reset, 'reset'),
                           (jacobian, 'jacobian'), (input_jacobian, 'input_jacobian')]:
            if arg is not None and not callable(arg):
                raise ControlArgument(f"{label} must be callable, got {type(arg).__name__}")
        if updfcn is None:
            raise ControlArgument("updfcn must be callable, got None")
        if guard is None and (reset is not None or target is not None):
            raise ValueError("reset and target need a guard (the mode is never left without one)")
        if guard is not None and target is None:
            raise ValueError("target must name the mode entered when the guard fires")
        if target is not None and not isinstance(target, (str, numbers.Integral)):
            raise ControlArgument(f"target must be a mode index or name, got {target!r}")
        if name is not None and not isinstance(name, str):
            raise ControlArgument(f"name must be a string, got {name!r}")
        self.updfcn, self.guard, self.reset = updfcn, guard, reset
        self.target, self.name = target, name
        self.jacobian, self.input_jacobian = jacobian, input_jacobian

    def __repr__(self):
        return f"<HybridMode {self.name!r} -> {self.target!r}>"


class HybridPlant:
    """Periodically forced hybrid plant: modes, guards and reset maps.

    Parameters
    ----------
    modes : sequence of HybridMode
        The charts.  Mode targets are resolved to indices.
    outfcn : callable, optional
        Output map ``outfcn(t, x, u, params) -> y`` shared by all modes; the
        full state is the output when omitted.
    states : int or list of str
        Number or names of the states.
    inputs : int or list of str, optional
        Number or names of the inputs (default 0).
    outputs : int or list of str, optional
        Number or names of the outputs (default: the states).
    params : dict, optional
        Default parameters passed to every callable.
    name : str, optional
        Plant name.

    Attributes
    ----------
    modes : list of HybridMode
    mode_names : list of str
    nstates, ninputs, noutputs : int
    state_labels, input_labels, output_labels : list of str
    params : dict
    name : str
    mode_targets : list of int or None
        Index of the mode entered when each mode's guard fires (None for a
        mode without a guard).

    Notes
    -----
    The methods ``dynamics``, ``guard``, ``reset``, ``output``,
    ``state_jacobian`` and ``input_jacobian`` evaluate the charts with validated shapes, as
    python-control's ``sys.dynamics(t, x, u, params)`` and
    ``sys.output(t, x, u, params)`` do; the mode is the keyword ``mode``.

    Examples
    --------
    Bouncing ball with restitution 0.8:

    >>> air = ltp.HybridMode(lambda t, x, u, p: [x[1], -9.81],
    ...                      guard=lambda t, x, u, p: x[0],
    ...                      reset=lambda t, x, u, p: [x[0], -0.8 * x[1]],
    ...                      target='air', name='air')
    >>> ball = ltp.HybridPlant([air], states=['h', 'v'])
    >>> ball.nstates, ball.ninputs, ball.mode_names
    (2, 0, ['air'])
    """

    def __init__(self, modes, outfcn=None, *, states, inputs=0, outputs=None,
                 params=None, name=None):
        if isinstance(modes, HybridMode):
            modes = [modes]
        try:
            modes = list(modes)
        except TypeError:
            raise ControlArgument(f"modes must be a sequence of HybridMode, got {modes!r}") from None
        if not modes or not all(isinstance(m, HybridMode) for m in modes):
            raise ControlArgument("modes must be a non-empty sequence of HybridMode")
        if outfcn is not None and not callable(outfcn):
            raise ControlArgument(f"outfcn must be callable, got {type(outfcn).__name__}")
        if params is not None and not isinstance(params, dict):
            raise ControlArgument(f"params must be a dict, got {type(params).__name__}")
        if name is not None and not isinstance(name, str):
            raise ControlArgument(f"name must be a string, got {name!r}")
        self.state_labels = _labels(states, 'states', 'x')
        self.input_labels = _labels(inputs, 'inputs', 'u', allow_zero=True)
        if outputs is None:
            if outfcn is not None:
                raise ValueError("outputs must be given together with outfcn")
            self.output_labels = list(self.state_labels)
        else:
            self.output_labels = _labels(outputs, 'outputs', 'y')
            if outfcn is None and len(self.output_labels) != len(self.state_labels):
                raise ControlDimension("without outfcn the outputs are the states: outputs must "
                                       f"have {len(self.state_labels)} entries")
        self.nstates, self.ninputs = len(self.state_labels), len(self.input_labels)
        self.noutputs = len(self.output_labels)
        self.outfcn, self.params = outfcn, dict(params or {})
        self.name = name if name is not None else 'hybrid'
        self.mode_names = [m.name if m.name is not None else f'mode[{i}]'
                           for i, m in enumerate(modes)]
        if len(set(self.mode_names)) != len(self.mode_names):
            raise ValueError(f"mode names must be unique, got {self.mode_names}")
        self.modes = modes
        self.mode_targets = [None if m.target is None else self.mode_index(m.target, 'target')
                             for m in modes]

    def __repr__(self):
        return (f"<HybridPlant {self.name!r}: {self.nstates} states, {self.ninputs} inputs, "
                f"modes {self.mode_names}>")

    def mode_index(self, mode, name='mode'):
        """Index of a mode given by index or name.

        Examples
        --------
        >>> m = ltp.HybridMode(lambda t, x, u, p: -x, name='only')
        >>> ltp.HybridPlant([m], states=1).mode_index('only')
        0
        """
        if isinstance(mode, str):
            if mode not in self.mode_names:
                raise ValueError(f"{name}={mode!r} is not one of the modes {self.mode_names}")
            return self.mode_names.index(mode)
        if isinstance(mode, (bool, np.bool_)) or not isinstance(mode, (numbers.Integral, np.integer)):
            raise ControlArgument(f"{name} must be a mode index or name, got {mode!r}")
        if not 0 <= int(mode) < len(self.modes):
            raise ValueError(f"{name}={mode} is out of range for {len(self.modes)} modes")
        return int(mode)

    #
    # Evaluation of the charts: the interface of the integrator, the orbit
    # solvers and the closed loops.  `params` is the complete parameter dict
    # (default: the plant's own); `mode` an index or a name.
    #

    def _mode(self, mode):
        return mode if type(mode) is int else self.mode_index(mode)

    def dynamics(self, t, x, u, params=None, *, mode=0):
        """Vector field ``f_i(t, x, u, params)`` of one mode, as a float vector.

        Parameters
        ----------
        t : float
            Time.
        x, u : array_like
            State and input.
        params : dict, optional
            The complete parameters (default: the plant's `params`).
        mode : int or str, optional
            The mode i (default 0).

        Returns
        -------
        ndarray, shape (nstates,)

        Examples
        --------
        >>> air = ltp.HybridMode(lambda t, x, u, p: [x[1], -p['g']], name='air')
        >>> ball = ltp.HybridPlant([air], states=2, params={'g': 9.81})
        >>> ball.dynamics(0.0, [1.0, 2.0], [], mode='air')
        array([ 2.  , -9.81])
        """
        i = self._mode(mode)
        dx = np.asarray(self.modes[i].updfcn(t, x, u, self.params if params is None else params),
                        float).reshape(-1)
        if dx.size != self.nstates:
            raise ControlDimension(f"updfcn of mode {self.mode_names[i]!r} returned "
                                   f"{dx.size} values, expected {self.nstates}")
        return dx

    def guard(self, t, x, u, params=None, *, mode=0):
        """Guard value ``g_i(t, x, u, params)`` of a mode with a guard (a finite float).

        The mode is left when it crosses zero from positive to negative.
        """
        i = self._mode(mode)
        where = f"guard of mode {self.mode_names[i]!r}"
        if self.modes[i].guard is None:
            raise ValueError(f"mode {self.mode_names[i]!r} has no guard")
        value = self.modes[i].guard(t, x, u, self.params if params is None else params)
        try:
            arr = np.asarray(value, float) if value is not None else None
        except (TypeError, ValueError):
            arr = None
        if arr is None:
            raise ControlArgument(f"{where} must return a real scalar, got {value!r}")
        if arr.size != 1:
            raise ControlArgument(f"{where} must return a real scalar, got an array of "
                                  f"shape {arr.shape}")
        value = float(arr.reshape(()))
        if not np.isfinite(value):
            raise ValueError(f"{where} returned {value} at t={t:.6g}")
        return value

    def reset(self, t, x, u, params=None, *, mode=0):
        """State ``x⁺ = r_i(t, x, u, params)`` after leaving a mode (x without a reset map)."""
        i = self._mode(mode)
        if self.modes[i].reset is None:
            return np.array(x, float)
        xp = np.asarray(self.modes[i].reset(t, x, u, self.params if params is None else params),
                        float).reshape(-1)
        if xp.size != self.nstates:
            raise ControlDimension(f"reset of mode {self.mode_names[i]!r} returned "
                                   f"{xp.size} values, expected {self.nstates}")
        return xp

    def output(self, t, x, u, params=None):
        """Output ``y = h(t, x, u, params)`` (the state without an output function).

        Examples
        --------
        >>> m = ltp.HybridMode(lambda t, x, u, p: -x)
        >>> ltp.HybridPlant([m], lambda t, x, u, p: [2 * x[0]], states=1,
        ...                 outputs=1).output(0.0, [1.5], [])
        array([3.])
        """
        if self.outfcn is None:
            return np.array(x, float)
        y = np.asarray(self.outfcn(t, x, u, self.params if params is None else params),
                       float).reshape(-1)
        if y.size != self.noutputs:
            raise ControlDimension(f"outfcn returned {y.size} values, expected {self.noutputs}")
        return y

    def state_jacobian(self, t, x, u, params=None, *, mode=0):
        """``∂f_i/∂x``: the mode's `jacobian` or central differences."""
        return self._jacobian('jacobian', t, x, u, params, mode)

    def input_jacobian(self, t, x, u, params=None, *, mode=0):
        """``∂f_i/∂u``: the mode's `input_jacobian` or central differences."""
        return self._jacobian('input_jacobian', t, x, u, params, mode)

    def _jacobian(self, name, t, x, u, params, mode):
        """The mode's Jacobian `name` (in x or in u), or its central differences."""
        i = self._mode(mode)
        params = self.params if params is None else params
        jac = getattr(self.modes[i], name)
        wrt_x = name == 'jacobian'
        if jac is not None:
            cols = self.nstates if wrt_x else self.ninputs
            return _matrix(jac(t, x, u, params), (self.nstates, cols), name)
        if wrt_x:
            return central_jacobian(lambda z: self.dynamics(t, z, u, params, mode=i), x)
        return central_jacobian(lambda v: self.dynamics(t, x, v, params, mode=i), u)


def _labels(spec, name, prefix, allow_zero=False):
    """Signal names from an int count or a list of names (python-control style)."""
    if isinstance(spec, str):
        return [spec]
    if isinstance(spec, (numbers.Integral, np.integer)) and not isinstance(spec, bool):
        check_positive_int(spec, name, minimum=0 if allow_zero else 1)
        return [f'{prefix}[{i}]' for i in range(int(spec))]
    try:
        labels = list(spec)
    except TypeError:
        raise ControlArgument(f"{name} must be an int or a list of names, got {spec!r}") from None
    if (not labels and not allow_zero) or not all(isinstance(s, str) for s in labels):
        raise ControlArgument(f"{name} must be an int or a non-empty list of str, got {spec!r}")
    return labels


def _matrix(value, shape, name):
    arr = np.asarray(value, float)
    if arr.size != shape[0] * shape[1]:
        raise ControlDimension(f"{name} returned shape {arr.shape}, expected {shape}")
    return arr.reshape(shape)


def central_jacobian(func, x):
    """∂func/∂x by central differences, ``(F(x + h e_j) − F(x − h e_j)) / 2h``.

    Examples
    --------
    >>> from ltpcontrol._orbits.hybrid_plant import central_jacobian
    >>> J = central_jacobian(lambda x: [x[0] * x[1], np.sin(x[0])], [1.0, 2.0])
    >>> bool(np.allclose(J, [[2.0, 1.0], [np.cos(1.0), 0.0]]))
    True
    """
    x = np.asarray(x, float)
    f0 = np.atleast_1d(func(x))
    jac = np.empty((f0.size, x.size))
    for j in range(x.size):
        h = _FD_STEP * max(1.0, abs(x[j]))
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        jac[:, j] = (np.atleast_1d(func(xp)) - np.atleast_1d(func(xm))) / (2 * h)
    return jac
