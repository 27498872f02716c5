"""Event-detecting simulation of hybrid plants (``_orbits/hybrid_plant.py``).

A mode's flow is integrated until its guard crosses zero from positive to
negative; the reset then maps the state into the target mode.  The module
also holds the saltation matrix of an event, the building block of the
exact Jacobian of the period map.
"""

import warnings

import numpy as np
from control import TimeResponseData
from control.exception import ControlArgument, ControlDimension
from scipy.integrate import solve_ivp

from .._core.validation import real_array
from .hybrid_plant import _FD_STEP, HybridPlant, central_jacobian
from .settings import solver_settings

__all__ = ['simulate_hybrid', 'saltation_matrix']

#: a transition factor restarts when its condition number exceeds c (or its norm leaves [1e-2, c])
_RESTART = 1e5


def _derivative(func, t):
    """d func/dt by a central difference."""
    h = _FD_STEP * max(1.0, abs(t))
    return (np.asarray(func(t + h), float) - np.asarray(func(t - h), float)) / (2 * h)


def saltation_matrix(plant, mode, t, x, u=None, params=None):
    """Saltation matrix of the event leaving `mode` at time `t` in state `x`.

    For the guard ``g``, reset ``r`` and vector fields ``f⁻`` (before) and
    ``f⁺`` (after, evaluated at ``x⁺ = r(x)``) the first-order map from a
    state perturbation just before the nominal event to one just after it is

    ``S = Dr + (f⁺ − Dr f⁻ − ∂r/∂t) ∂g/∂x / (∂g/∂x f⁻ + ∂g/∂t)``.

    Derivatives of ``g`` and ``r`` are taken by central differences.

    Parameters
    ----------
    plant : HybridPlant
        The plant.
    mode : int or str
        Mode left at the event (it must have a guard).
    t : float
        Event time.
    x : array_like
        State just before the event (on the guard surface).
    u : array_like, optional
        Input at the event (zeros when omitted).
    params : dict, optional
        Parameters overriding the plant's defaults.

    Returns
    -------
    ndarray, shape (n, n)

    Raises
    ------
    ValueError
        When the flow is tangent to the guard (grazing).

    Warns
    -----
    UserWarning
        When the flow is nearly tangent to the guard, where the saltation
        matrix is ill-conditioned.

    Examples
    --------
    A ball bouncing with restitution e: ``S = [[-e, 0], [-(1+e)g/v, -e]]``
    (velocity ``v < 0`` at impact).

    >>> e, g = 0.5, 9.81
    >>> air = ltp.HybridMode(lambda t, x, u, p: [x[1], -g],
    ...                      guard=lambda t, x, u, p: x[0],
    ...                      reset=lambda t, x, u, p: [x[0], -e * x[1]],
    ...                      target=0)
    >>> ball = ltp.HybridPlant([air], states=2)
    >>> v = -2.0
    >>> S = ltp.saltation_matrix(ball, 0, 1.0, [0.0, v])
    >>> bool(np.allclose(S, [[-e, 0], [-(1 + e) * g / v, -e]]))
    True
    """
    if not isinstance(plant, HybridPlant):
        raise ControlArgument(f"plant must be a HybridPlant, got {type(plant).__name__}")
    i = plant.mode_index(mode)
    if plant.modes[i].guard is None:
        raise ValueError(f"mode={plant.mode_names[i]!r} has no guard, so no event leaves it")
    x = real_array(x, 'x', ndim=1)
    if x.size != plant.nstates:
        raise ControlDimension(f"x must have {plant.nstates} entries, got {x.size}")
    t = float(real_array(t, 't', ndim=0))
    u = constant_input(plant, u, 'u')
    params = plant_params(plant, params)
    return _saltation(plant, i, t, x, u, params, lambda s: u)


def _saltation(plant, i, t, x, u, params, ufun):
    j = plant.mode_targets[i]
    xp = plant.reset(t, x, u, params, mode=i)
    f_minus = plant.dynamics(t, x, u, params, mode=i)
    f_plus = plant.dynamics(t, xp, u, params, mode=j)
    # gradient of the guard in x and t (t-dependence includes the input signal)
    dg_dx = central_jacobian(lambda z: plant.guard(t, z, u, params, mode=i), x)[0]
    dg_dt = float(_derivative(lambda s: plant.guard(s, x, ufun(s), params, mode=i), t))
    dr_dx = central_jacobian(lambda z: plant.reset(t, z, u, params, mode=i), x)
    dr_dt = _derivative(lambda s: plant.reset(s, x, ufun(s), params, mode=i), t)
    rate = dg_dx @ f_minus + dg_dt
    scale = np.linalg.norm(dg_dx) * np.linalg.norm(f_minus) + abs(dg_dt)
    if rate == 0:
        raise ValueError(f"the flow is tangent to the guard of mode {plant.mode_names[i]!r} "
                         f"at t={t:.6g}: no saltation matrix exists at a grazing point")
    if abs(rate) <= 1e-8 * scale:
        warnings.warn(f"grazing event leaving mode {plant.mode_names[i]!r} at t={t:.6g}: "
                      f"the guard changes at rate {rate:.3g}; the saltation matrix is "
                      "ill-conditioned", UserWarning, stacklevel=3)
    # S = Dr + (f⁺ − Dr f⁻ − ∂r/∂t) ∂g/∂x / (∂g/∂x f⁻ + ∂g/∂t)
    return dr_dx + np.outer(f_plus - dr_dx @ f_minus - dr_dt, dg_dx) / rate


def plant_params(plant, params):
    """The plant's parameters updated by `params` (a dict or None).

    Examples
    --------
    >>> from ltpcontrol._orbits.hybrid import plant_params
    >>> air = ltp.HybridMode(lambda t, x, u, p: [x[1], -p['g']], name='air')
    >>> ball = ltp.HybridPlant([air], states=2, params={'g': 9.81, 'm': 1.0})
    >>> plant_params(ball, {'g': 1.62}), plant_params(ball, None)
    ({'g': 1.62, 'm': 1.0}, {'g': 9.81, 'm': 1.0})
    >>> ball.params                                  # left unchanged
    {'g': 9.81, 'm': 1.0}
    """
    if params is None:
        return dict(plant.params)
    if not isinstance(params, dict):
        raise ControlArgument(f"params must be a dict, got {type(params).__name__}")
    return {**plant.params, **params}


def constant_input(plant, u, name):
    """Constant input vector of `plant` from None (zero), a scalar or one entry per input.

    Examples
    --------
    >>> from ltpcontrol._orbits.hybrid import constant_input
    >>> plant = ltp.HybridPlant([ltp.HybridMode(lambda t, x, u, p: -x + u)], states=2, inputs=2)
    >>> constant_input(plant, None, 'u0'), constant_input(plant, 3.0, 'u0')
    (array([0., 0.]), array([3., 3.]))
    >>> constant_input(plant, [1.0, 2.0, 3.0], 'u0')
    Traceback (most recent call last):
    ...
    control.exception.ControlDimension: u0 must have 2 entries, got 3
    """
    if u is None:
        return np.zeros(plant.ninputs)
    u = real_array(u, name, ndim=(0, 1)).reshape(-1)
    if u.size == 1 and plant.ninputs > 1:
        u = np.full(plant.ninputs, u[0])
    if u.size != plant.ninputs:
        raise ControlDimension(f"{name} must have {plant.ninputs} entries, got {u.size}")
    return u


def input_function(plant, inputs, timepts):
    """Return ``u(t)`` from a scalar, an array on `timepts` or a callable.

    Examples
    --------
    Samples on `timepts` are interpolated linearly:

    >>> from ltpcontrol._orbits.hybrid import input_function
    >>> plant = ltp.HybridPlant([ltp.HybridMode(lambda t, x, u, p: -x + u)], states=1, inputs=1)
    >>> u = input_function(plant, [0.0, 1.0, 4.0], [0.0, 1.0, 2.0])
    >>> u(0.5), u(1.5)
    (array([0.5]), array([2.5]))
    >>> input_function(plant, np.cos, None)(0.0), input_function(plant, 2.0, None)(7.0)
    (array([1.]), array([2.]))
    """
    m = plant.ninputs
    if callable(inputs):
        def ufun(t):
            u = np.asarray(inputs(t), float)
            if u.size != m:
                raise ControlDimension(f"inputs(t) returned shape {u.shape}, expected ({m}, 1)")
            return u.reshape(m)
        return ufun
    arr = real_array(inputs, 'inputs', ndim=(0, 1, 2))
    if arr.ndim == 0:
        value = np.full(m, float(arr))
        return lambda t: value
    if arr.ndim == 1:
        if m != 1:
            raise ControlDimension(f"inputs must have shape ({m}, {len(timepts)}), got {arr.shape}")
        arr = arr[np.newaxis]
    if arr.shape != (m, len(timepts)):
        raise ControlDimension(f"inputs must have shape ({m}, {len(timepts)}), got {arr.shape}")
    # linear interpolation between the given samples, as input_output_response does
    return lambda t: np.array([np.interp(t, timepts, row) for row in arr])


class IntegrationError(RuntimeError):
    """The hybrid integrator could not continue: solver failure, a state that
    is no longer finite, or more events than allowed (a diverging or Zeno
    trajectory)."""


class Flow:
    """One integration of a hybrid plant over ``[t0, tf]`` with event handling.

    With ``variational=True`` the state transition matrix is propagated
    alongside: ``dΦ/dt = ∂f/∂x Φ`` in each mode and ``Φ⁺ = S Φ⁻`` at events,
    so that `phi` is the Jacobian of the flow map ``x(t0) -> x(tf)``.  It is
    also kept in product form, `factors` (first to last): one transition
    matrix per mode interval and the saltation matrices.  With
    ``factored=True`` ``Φ`` also restarts from the identity whenever its
    condition number exceeds ``c = _RESTART`` or its norm leaves ``[1e-2,
    c]``, so that every factor is computed to about ``c rtol`` relative to
    each of its singular values (multipliers of stiff orbits).

    With sorted ``samples`` (times in ``[t0, tf]``) the flow keeps only the
    states and modes at those times (`sampled`, right-continuous at events)
    and no dense output: the solver then interpolates only in the steps that
    hold a sample, with the same interpolants and so the same values as
    `evaluate` of a dense flow.
    """

    def __init__(self, plant, t0, tf, x0, mode, ufun, params, rtol, atol, method,
                 max_events, variational=False, factored=False, samples=None):
        n = plant.nstates
        self.segments, self.events, self.saltations = [], [], []
        sampled_t, sampled_x, sampled_modes = [], [], []
        self.factors, self.trace_integral = [], 0.0
        t, x, i = t0, np.array(x0, float), mode
        phi = np.eye(n)
        while True:
            if not (np.all(np.isfinite(x)) and np.all(np.isfinite(phi))):
                raise IntegrationError(f"the state is no longer finite at t={t:.6g} "
                                       f"(mode {plant.mode_names[i]!r}): the trajectory diverges")
            rhs, z0 = self._system(plant, i, ufun, params, x, variational, factored)
            events = []
            if plant.modes[i].guard is not None:
                def event(s, z, i=i):
                    return plant.guard(s, z[:n], ufun(s), params, mode=i)
                event.terminal, event.direction = True, -1
                events.append(event)
            if variational and factored:
                events.append(_restart_event(n))
            t_eval = None
            if samples is not None:
                t_eval = samples[np.searchsorted(samples, t, side='left'):
                                 np.searchsorted(samples, tf, side='right')]
            sol = solve_ivp(rhs, (t, tf), z0, method=method, rtol=rtol,
                            atol=_variational_atol(atol, n, len(z0)) if variational else atol,
                            events=events or None, dense_output=samples is None,
                            t_eval=t_eval if t_eval is not None and t_eval.size else None)
            if sol.status == -1:
                raise IntegrationError(f"integration failed in mode {plant.mode_names[i]!r} "
                                       f"at t={sol.t[-1]:.6g}: {sol.message}")
            if samples is None:
                t_end, z_end = sol.t[-1], sol.y[:, -1]
            else:
                # the solver's own end of the segment (an event or tf), not a sample
                # (samples end at tf: the last one is the state there)
                t_end = sol.t_events[0][-1] if sol.status == 1 else tf
                z_end = sol.y_events[0][-1] if sol.status == 1 else sol.y[:, -1]
                if t_eval is not None and t_eval.size:
                    # (none when the segment ends before its first sample)
                    ts = np.asarray(sol.t, float)
                    ys = np.asarray(sol.y, float).reshape(len(z0), ts.size)
                    # a sample at the event belongs to the mode entered there
                    keep = ts < t_end if sol.status == 1 else slice(None)
                    sampled_t.append(ts[keep])
                    sampled_x.append(ys[:n, keep])
                    sampled_modes.append(np.full(sampled_t[-1].size, i))
            self.segments.append((t, t_end, i, sol.sol))
            x = z_end[:n]
            if variational:
                # one more factor: the transition matrix over [t, t_end]
                self.factors.append(z_end[n:n + n * n].reshape(n, n))
                phi = self.factors[-1] @ phi
                if factored:
                    self.trace_integral += z_end[-1]
            if sol.status != 1 or t_end >= tf:
                break
            guard_hit = plant.modes[i].guard is not None and sol.t_events[0].size > 0
            if not guard_hit:
                # restart of the transition matrix: same mode, same state
                t = t_end
                continue
            # transition: x⁺ = r(t, x⁻), Φ⁺ = S Φ⁻
            u = ufun(t_end)
            j = plant.mode_targets[i]
            if variational:
                S = _saltation(plant, i, t_end, x, u, params, ufun)
                self.saltations.append(S)
                self.factors.append(S)
                phi = S @ phi
            x_plus = plant.reset(t_end, x, u, params, mode=i)
            self.events.append((t_end, i, j, x.copy(), x_plus.copy()))
            x, i, t = x_plus, j, t_end
            if len(self.events) > max_events:
                raise IntegrationError(f"more than max_events={max_events} events before "
                                       f"t={t:.6g} (Zeno or chattering behaviour?)")
        self.x_final, self.mode_final, self.phi = x, i, phi
        if samples is not None:
            self.sampled = (np.concatenate(sampled_x, axis=1) if sampled_x else np.empty((n, 0)),
                            np.concatenate(sampled_modes) if sampled_modes else np.empty(0, int))
        self.nstates, self.rtol, self.factored = n, rtol, bool(variational and factored)

    @staticmethod
    def _system(plant, i, ufun, params, x, variational, factored):
        n = plant.nstates
        if not variational:
            # `HybridPlant.dynamics` without its per-call mode dispatch: the
            # solver calls this a dozen times per step
            f, name = plant.modes[i].updfcn, plant.mode_names[i]

            def field(s, z):
                dx = np.asarray(f(s, z, ufun(s), params), float).reshape(-1)
                if dx.size != n:
                    raise ControlDimension(f"updfcn of mode {name!r} returned "
                                           f"{dx.size} values, expected {n}")
                return dx
            return field, x

        def rhs(s, z):
            u = ufun(s)
            A = plant.state_jacobian(s, z[:n], u, params, mode=i)
            parts = [plant.dynamics(s, z[:n], u, params, mode=i),
                     (A @ z[n:n + n * n].reshape(n, n)).ravel()]
            # factored flows also integrate tr A (Liouville: d log det Φ/dt = tr A)
            return np.concatenate(parts + [[np.trace(A)]] if factored else parts)
        return rhs, np.concatenate([x, np.eye(n).ravel()] + ([[0.0]] if factored else []))

    def evaluate(self, t):
        """States and modes at sorted times ``t`` (right-continuous at events)."""
        t = np.asarray(t, float)
        states = np.empty((self.nstates, t.size))
        modes = np.empty(t.size, int)
        starts = np.array([seg[0] for seg in self.segments])
        idx = np.clip(np.searchsorted(starts, t, side='right') - 1, 0, len(starts) - 1)
        for k, (_, _, i, sol) in enumerate(self.segments):
            mask = idx == k
            if np.any(mask):
                states[:, mask] = sol(t[mask])[:self.nstates].reshape(self.nstates, -1)
                modes[mask] = i
        return states, modes


#: absolute tolerance floor of the transition factors (entries of order 1)
_PHI_ATOL = 1e-12


def _variational_atol(atol, n, size):
    """Absolute tolerances: `atol` for the state, at least `_PHI_ATOL` for the rest.

    The transition factors are driven by ``∂f/∂x``, which central
    differences give to about 1e-10 only; asking more of them makes the
    step-size control chase that noise.  Restarted factors have entries of
    order 1, so this is a relative accuracy of about 1e-10 per factor.
    """
    out = np.full(size, max(atol, _PHI_ATOL))
    out[:n] = atol
    return out


def _restart_event(n):
    """Terminal event: the transition factor becomes ill-conditioned or leaves scale.

    Fires when ``σ_1/σ_n`` exceeds ``c = _RESTART`` or ``σ_1`` leaves
    ``[1e-2, c]`` (the absolute tolerance then stays small relative to the
    factor).  Rotations and oscillations of moderate stiffness do not fire it.
    """
    limit = np.log(_RESTART)

    def restart(s, z):
        sv = np.linalg.svd(z[n:n + n * n].reshape(n, n), compute_uv=False)
        if not np.all(np.isfinite(sv)) or sv[-1] <= 0:
            return -limit
        top = np.log(sv[0])
        return min(limit - (top - np.log(sv[-1])), top - np.log(1e-2), limit - top)
    restart.terminal, restart.direction = True, -1
    return restart


def simulate_hybrid(plant, timepts, initial_state, mode0=0, inputs=0.0, params=None, *,
                    rtol=1e-10, atol=1e-12, method='DOP853', max_events=10000):
    """Simulate a `HybridPlant` with event detection.

    Each mode is integrated with `scipy.integrate.solve_ivp` (tight default
    tolerances) until its guard crosses zero from positive to negative; the
    event time is located by the solver's root finder, the reset map is
    applied and integration continues in the target mode.

    Parameters
    ----------
    plant : HybridPlant
        The plant.
    timepts : array_like
        Increasing time points at which the response is reported; the
        simulation runs from ``timepts[0]`` to ``timepts[-1]``.
    initial_state : array_like
        State at ``timepts[0]``.
    mode0 : int or str, optional
        Initial mode (default 0).
    inputs : float, array_like or callable, optional
        Input: a constant, an array of shape ``(ninputs, len(timepts))``
        (linearly interpolated) or a callable ``u(t)``.
    params : dict, optional
        Parameters overriding the plant's defaults.
    rtol, atol : float, optional
        `solve_ivp` tolerances (defaults 1e-10 and 1e-12).
    method : str, optional
        `solve_ivp` method (default ``'DOP853'``).
    max_events : int, optional
        Maximum number of events (default 10000); exceeding it raises
        `RuntimeError` (Zeno behaviour).

    Returns
    -------
    resp : control.TimeResponseData
        Time response with ``time``, ``outputs``, ``states`` and ``inputs``
        and these extra attributes:

        * ``modes`` : int array, index of the active mode at each time point
          (the mode entered at an event owns the event instant);
        * ``event_times`` : array of event times;
        * ``event_modes`` : list of ``(from, to)`` mode index pairs;
        * ``final_state``, ``final_mode`` : state and mode at ``timepts[-1]``;
        * ``mode_names`` : the plant's mode names.

    Examples
    --------
    A bouncing ball dropped from 1 m hits the ground at ``sqrt(2/g)``:

    >>> air = ltp.HybridMode(lambda t, x, u, p: [x[1], -9.81],
    ...                      guard=lambda t, x, u, p: x[0],
    ...                      reset=lambda t, x, u, p: [x[0], -0.5 * x[1]],
    ...                      target=0)
    >>> ball = ltp.HybridPlant([air], states=['h', 'v'])
    >>> resp = ltp.simulate_hybrid(ball, np.linspace(0, 0.6, 61), [1.0, 0.0])
    >>> bool(abs(resp.event_times[0] - np.sqrt(2 / 9.81)) < 1e-9)
    True
    >>> resp.modes[:3], resp.states.shape
    (array([0, 0, 0]), (2, 61))
    """
    opts = solver_settings('simulate_hybrid', rtol, atol, method, max_events)
    if not isinstance(plant, HybridPlant):
        raise ControlArgument(f"plant must be a HybridPlant, got {type(plant).__name__}")
    timepts = real_array(timepts, 'timepts', ndim=1)
    if timepts.size < 2 or np.any(np.diff(timepts) <= 0):
        raise ValueError("timepts must be strictly increasing with at least 2 points")
    x0 = real_array(initial_state, 'initial_state', ndim=(0, 1)).reshape(-1)
    if x0.size != plant.nstates:
        raise ControlDimension(f"initial_state must have {plant.nstates} entries, got {x0.size}")
    mode0 = plant.mode_index(mode0, 'mode0')
    params = plant_params(plant, params)
    ufun = input_function(plant, inputs, timepts)
    flow = Flow(plant, timepts[0], timepts[-1], x0, mode0, ufun, params, variational=False,
                samples=timepts, **opts)
    states, modes = flow.sampled
    states[:, -1], modes[-1] = flow.x_final, flow.mode_final
    u = np.array([ufun(t) for t in timepts]).reshape(len(timepts), plant.ninputs).T
    y = np.column_stack([plant.output(t, states[:, k], u[:, k], params)
                         for k, t in enumerate(timepts)])
    resp = TimeResponseData(
        timepts, y, states, u if plant.ninputs else None,
        issiso=plant.ninputs == 1 and plant.noutputs == 1,
        output_labels=plant.output_labels, state_labels=plant.state_labels,
        input_labels=plant.input_labels if plant.ninputs else None,
        sysname=plant.name, params=params, return_x=True, plot_inputs=plant.ninputs > 0,
        title=f"Hybrid response of {plant.name}")
    resp.modes = modes
    resp.event_times = np.array([e[0] for e in flow.events])
    resp.event_modes = [(e[1], e[2]) for e in flow.events]
    resp.final_state, resp.final_mode = flow.x_final, flow.mode_final
    resp.mode_names = list(plant.mode_names)
    return resp
