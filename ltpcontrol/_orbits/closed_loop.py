"""Feedback loops of a hybrid plant and a controller about a periodic orbit.

A controller ``K`` (an `LTPStateSpace`, a python-control LTI system or a
`control.NonlinearIOSystem`; continuous or discrete time) closes the loop
around the nominal orbit ``x̄(t)``, ``u0``, ``ȳ(t) = h(t, x̄(t), u0)`` of a
`HybridPlant` (or a smooth `control.NonlinearIOSystem`), in the deviation
coordinates of `linearize_orbit`::

    e(t) = y(t) + v(t) − ȳ(t)      controller input (v: measurement noise)
    u(t) = sat(u0 + w(t))           plant input (w: controller output)

The controller output is added to the plant input as it is (no sign flip),
as for estimator-based controllers ``w = −K x̂``.

Phase lock: the controller runs on the plant's clock.  Its time argument is
the plant time t, so the controller's ``t = 0`` is the orbit's ``t = 0``
(the phase of the periodic forcing), whatever the simulation start.  A
discrete controller samples ``e`` at ``t = k dt`` and holds ``u`` on
``[k dt, (k+1) dt)``; it uses its matrices of step ``k mod N``.

A continuous controller makes the loop a `HybridPlant` with states
``[x, x_c]``, so orbits, saltation matrices and the exact return map come
from `periodic_orbit`.  A discrete controller gives a sampled-data loop whose
period map is the composition of its samples and hybrid flows between
samples, with the Jacobian composed alike.
"""

import numbers
import warnings
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Optional

import numpy as np
import control as ct
from control.exception import ControlArgument, ControlDimension
from tqdm.auto import tqdm

from .hybrid import Flow, input_function, IntegrationError, solver_settings, _RESTART
from .settings import newton_solver_settings
from .kinks import one_sided_saltations, side_factor_lists
from .multipliers import product_multipliers
from .loop import FeedbackLoop, SampledLoop
from .orbits import PeriodicOrbit, flow_multipliers, periodic_orbit
from .._core.validation import check_positive_int, real_array

__all__ = ['ClosedLoopOrbit', 'closed_loop_response', 'closed_loop_orbit']


@dataclass(repr=False)
class ClosedLoopOrbit:
    """Periodic orbit of a closed hybrid loop and its return map.

    Returned by `closed_loop_orbit`; not meant to be built directly.

    Attributes
    ----------
    period : float
        The period T of the loop (the plant's orbit period).
    x0 : ndarray
        Plant state at t = 0 on the closed-loop orbit.
    controller_state : ndarray
        Controller state at t = 0 (before the sample at t = 0 for a
        discrete controller).
    mode0 : int
        Plant mode at t = 0.
    monodromy : ndarray, shape (n + n_c, n + n_c)
        Jacobian of the closed-loop period map at ``[x0, controller_state]``,
        saltation matrices of the hybrid events included (for a kinked
        map, the one-sided Jacobian with the largest spectral radius).
    multipliers : ndarray
        Its eigenvalues, sorted by decreasing magnitude.  For continuous
        controllers they come from the product form of the period map
        (accurate relative to their own size, see `PeriodicOrbit`).
    dominant_multiplier : float
        Largest multiplier magnitude (the worst side of a kinked map).
    is_stable : bool
        True when all multipliers lie strictly inside the unit circle (for
        a kinked map: those of every one-sided Jacobian).
    orbit : PeriodicOrbit or None
        The orbit of the loop as a hybrid plant with states ``[x, x_c]``
        (continuous controllers), for plotting and evaluation; None for a
        discrete controller.
    residual : float
        Relative fixed-point residual of the period map.
    converged : bool
        True when the orbit search converged.  False when it diverged
        because the loop is unstable: the other fields then describe the
        period map at the starting point (see `closed_loop_orbit`).
    message : str
        Outcome of the orbit search.
    one_sided_multipliers : tuple of ndarray
        Empty when the period map is smooth at the orbit.  When a plant
        event on the orbit coincides with a time discontinuity of the
        loop's field (the controller acts on ``e = y − ȳ(t)`` and ``ȳ``
        jumps at the orbit's events, or its gain switches there), the map
        has a kink: a perturbed event before or after the nominal instant
        gives different Jacobians.  Then this holds the multipliers of each
        one-sided Jacobian (every combination of sides, early before late,
        in the order of `kink_times`), and a warning is issued.  The
        spectral radii of the sides bound the local behaviour only
        loosely: a piecewise-linear map may be unstable with every side
        stable; verify with `closed_loop_response`.
    kink_times : ndarray
        Times of the kinked events (empty for a smooth map).

    Examples
    --------
    Proportional feedback doubles the decay rate of ``ẋ = −x + cos t + u``:

    >>> sys = ct.nlsys(lambda t, x, u, p: -x + np.cos(t) + u, None, states=1, inputs=1)
    >>> orbit = ltp.periodic_orbit(sys, 2 * np.pi, [0.0])
    >>> cl = ltp.closed_loop_orbit(sys, ct.ss([], [], [], [[-1.0]]), orbit)
    >>> bool(np.isclose(cl.dominant_multiplier, np.exp(-4 * np.pi)))
    True
    """

    period: float
    x0: np.ndarray
    controller_state: np.ndarray
    mode0: int
    monodromy: np.ndarray
    multipliers: np.ndarray
    dominant_multiplier: float
    is_stable: bool
    orbit: Optional[PeriodicOrbit]
    residual: float
    converged: bool = True
    message: str = "the closed-loop orbit converged"
    one_sided_multipliers: tuple = ()
    kink_times: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __repr__(self):
        diverged = "" if self.converged else ", diverges"
        return (f"<ClosedLoopOrbit period={self.period:g}, dominant |multiplier|="
                f"{self.dominant_multiplier:.4g}, stable={self.is_stable}{diverged}>")


def _multipliers(monodromy):
    """Eigenvalues by decreasing magnitude (all infinite if the matrix overflowed)."""
    if not np.all(np.isfinite(monodromy)):
        return np.full(len(monodromy), np.inf + 0j)
    mult = np.linalg.eigvals(monodromy)
    return mult[np.argsort(-np.abs(mult), kind='stable')]


def _result(period, z0, n, mode0, monodromy, orbit, residual, multipliers=None,
            stable=None, **outcome):
    """`ClosedLoopOrbit` with the multipliers sorted by decreasing magnitude."""
    mult = _multipliers(monodromy) if multipliers is None else multipliers
    dominant = float(np.abs(mult[0]))
    stable = bool(dominant < 1) if stable is None else stable
    return ClosedLoopOrbit(period, np.array(z0[:n]), np.array(z0[n:]), mode0, monodromy, mult,
                           dominant, stable, orbit, residual, **outcome)


def _loop_multipliers(loop, lp, flow):
    """Multipliers of the continuous loop's period map from a variational `Flow`.

    Returns the keywords of `_result`: multipliers and monodromy (the worst
    side of a kinked map), stability and the one-sided multipliers.
    """
    breaks = [loop.orbit.switching_times]
    if loop.linear:
        breaks += [M.breakpoints for M in (loop.ctrl.A, loop.ctrl.B, loop.ctrl.C, loop.ctrl.D)]
    kinks = one_sided_saltations(lp, flow, np.concatenate(breaks), loop.T, np.zeros(loop.p))
    if not all(np.all(np.isfinite(F)) for F in flow.factors):
        return dict(monodromy=flow.phi)
    if not kinks:
        return dict(monodromy=flow.phi, multipliers=flow_multipliers(flow).values)
    sides = side_factor_lists(flow.factors, kinks)
    mults = [product_multipliers(fac, rtol=flow.rtol, restart=_RESTART).values
             for _, fac in sides]
    radii = [float(np.abs(m[0])) for m in mults]
    worst = int(np.argmax(radii))
    times = np.array([k[3] for k in kinks])
    summary = ", ".join(f"{'/'.join(sd)}: {r:.4g}" for (sd, _), r in zip(sides, radii))
    warnings.warn(f"closed_loop_orbit: the period map has a kink (events at t = "
                  f"{np.array2string(times, precision=6)} coincide with jumps of the loop's "
                  f"field in t, e.g. of the reference ȳ(t)): its one-sided Jacobians differ, "
                  f"spectral radii {summary}; the worst is reported.  Stability of a kinked "
                  "map is not decided by these radii alone: verify with closed_loop_response",
                  UserWarning, stacklevel=3)
    monodromy = np.eye(len(flow.phi))
    for F in sides[worst][1]:
        monodromy = F @ monodromy
    return dict(monodromy=monodromy, multipliers=mults[worst],
                stable=bool(max(radii) < 1), one_sided_multipliers=tuple(mults),
                kink_times=times)


def _initial(loop, initial_state, controller_state, mode0, t0):
    if initial_state is None:
        x0 = loop.orbit(np.mod(t0, loop.T))
        if mode0 is None:
            mode0 = int(loop.orbit._flow.evaluate([np.mod(t0, loop.T)])[1][0])
    else:
        x0 = real_array(initial_state, 'initial_state', ndim=(0, 1)).reshape(-1)
        if x0.size != loop.n:
            raise ControlDimension(f"initial_state must have {loop.n} entries, got {x0.size}")
    mode0 = loop.orbit.mode0 if mode0 is None else loop.plant.mode_index(mode0, 'mode0')
    xc0 = real_array(controller_state, 'controller_state', ndim=(0, 1)).reshape(-1)
    if xc0.size == 1 and loop.nc != 1:
        xc0 = np.full(loop.nc, xc0[0])
    if xc0.size != loop.nc:
        raise ControlDimension(f"controller_state must have {loop.nc} entries, got {xc0.size}")
    return np.concatenate([x0, xc0]), mode0


def closed_loop_response(plant, controller, orbit, timepts, initial_state=None,
                         controller_state=0.0, *, mode0=None, noise=None, saturation=None,
                         progress=False, max_deviation=1e3, rtol=1e-10, atol=1e-12,
                         method='DOP853', max_events=10000):
    """Simulate a hybrid plant with a controller in the loop.

    The controller sees the measured output deviation ``e = y + v − ȳ(t)``
    from the orbit's output and its output ``w`` drives the plant through
    ``u = sat(u0 + w)`` (no sign flip: an estimator-based controller outputs
    ``w = −K x̂``).  The controller runs on the plant's clock: its ``t = 0``
    is the orbit's ``t = 0`` (see the module notes); a discrete controller
    samples at ``t = k dt`` and holds its output in between.

    Parameters
    ----------
    plant : HybridPlant or control.NonlinearIOSystem
        The plant (a continuous-time smooth system acts as one mode).
    controller : LTPStateSpace, control.StateSpace, control.TransferFunction or control.NonlinearIOSystem
        Continuous or discrete controller from the plant's outputs to its
        inputs; an LTP controller's period must divide the orbit's period.
    orbit : PeriodicOrbit
        Nominal orbit of `plant` (from `periodic_orbit`); it supplies the
        period, ``ȳ(t)``, the nominal input ``u0`` and the parameters.
    timepts : array_like
        Increasing time points on the plant's clock; the simulation runs
        from ``timepts[0]`` to ``timepts[-1]`` (for a discrete controller
        ``timepts[0]`` must be a sampling instant ``k dt``).
    initial_state : array_like, optional
        Plant state at ``timepts[0]`` (default: the orbit's state there).
    controller_state : array_like, optional
        Controller state at ``timepts[0]`` (default 0).
    mode0 : int or str, optional
        Plant mode at ``timepts[0]`` (default: the orbit's mode there, or
        the orbit's mode at t = 0 when `initial_state` is given).
    noise : array_like or callable, optional
        Measurement noise ``v``: an array of shape ``(noutputs,
        len(timepts))`` (linearly interpolated) or a callable ``v(t)``.
    saturation : (lower, upper), optional
        Bounds of the plant input ``u`` (scalars or one per input).
    progress : bool, optional
        Show a progress bar over the periods simulated (default False).
    max_deviation : float, optional
        Divergence bound (default 1e3): the simulation stops when the plant
        state exceeds ``max_deviation · (1 + max_t ‖x̄(t)‖∞)`` in the
        infinity norm (checked at every sample of a discrete controller and
        every period boundary of a continuous one).
    rtol, atol, method, max_events : optional
        Integration settings, as in `simulate_hybrid` (defaults 1e-10,
        1e-12, 'DOP853', 10000).

    Returns
    -------
    resp : control.TimeResponseData
        ``outputs`` are the plant outputs (without noise), ``states`` the
        plant states followed by the controller states, ``inputs`` the plant
        inputs ``u`` after saturation.  Extra attributes: ``modes``,
        ``event_times``, ``noise`` (v on `timepts`) and ``diverged_at``:
        None, or the time at which a diverging loop was stopped (see
        Warns); outputs, states and inputs are NaN and modes -1 after it.

    Warns
    -----
    UserWarning
        When the loop diverges: the state exceeds the `max_deviation`
        bound or can no longer be integrated (it overflows, or the events
        exceed `max_events`).  The simulation then stops, so that a
        destabilising controller costs a bounded run time.

    Examples
    --------
    A forced oscillator hitting a wall at ``x = 0`` (restitution 0.7), its
    hopping orbit, and a proportional controller recovering from a push:

    >>> def free(t, x, u, p):
    ...     return [x[1], -40 * (x[0] - 0.1) - x[1] + 5 * np.cos(2 * np.pi * t) + u[0]]
    >>> mode = ltp.HybridMode(free, guard=lambda t, x, u, p: x[0],
    ...                       reset=lambda t, x, u, p: [x[0], -0.7 * x[1]], target=0)
    >>> wall = ltp.HybridPlant([mode], lambda t, x, u, p: [x[0]], states=2,
    ...                        inputs=1, outputs=1)
    >>> orbit = ltp.periodic_orbit(wall, 1.0, [0.2, 0.0], warmup=30)
    >>> K = ct.ss([], [], [], [[-5.0]])
    >>> resp = ltp.closed_loop_response(wall, K, orbit, np.linspace(0, 3, 31),
    ...                                 orbit.x0 + [0.0, 0.5], saturation=(-2, 2))
    >>> resp.states.shape, bool(np.abs(resp.inputs).max() <= 2)
    ((2, 31), True)
    """
    opts = solver_settings('closed_loop_response', rtol, atol, method, max_events)
    loop = FeedbackLoop(plant, controller, orbit, saturation)
    plant = loop.plant
    timepts = real_array(timepts, 'timepts', ndim=1)
    if timepts.size < 2 or np.any(np.diff(timepts) <= 0):
        raise ValueError("timepts must be strictly increasing with at least 2 points")
    z0, mode = _initial(loop, initial_state, controller_state, mode0, timepts[0])
    # the noise has one entry per plant output
    vfun = input_function(SimpleNamespace(ninputs=loop.p), 0.0 if noise is None else noise,
                           timepts)
    if isinstance(max_deviation, bool) or not isinstance(max_deviation, numbers.Real) \
            or not max_deviation > 0:
        raise ValueError(f"max_deviation must be a positive number, got {max_deviation!r}")
    bound = max_deviation * (1 + np.max(np.abs(orbit.states)))
    bar = _progress(progress, timepts)
    run = _run_sampled if loop.dt else _run_continuous
    rec = _Record(loop, timepts)
    try:
        run(loop, opts, rec, z0, mode, vfun, bar, bound)
    except (IntegrationError, _Diverged) as err:
        rec.stop(err)
        warnings.warn(f"closed_loop_response: the closed loop diverges: {err}; the response "
                      f"is NaN after t={rec.diverged_at:.6g}", UserWarning, stacklevel=2)
    bar.close()
    n, states, modes, events, u = loop.n, rec.states, rec.modes, rec.events, rec.inputs
    v = np.array([vfun(t) for t in timepts]).reshape(len(timepts), loop.p).T
    y = np.column_stack([plant.output(t, states[:n, k], loop.u0, loop.params)
                         if modes[k] >= 0 else np.full(loop.p, np.nan)
                         for k, t in enumerate(timepts)])
    resp = ct.TimeResponseData(
        timepts, y, states, u, issiso=loop.m == 1 and loop.p == 1,
        output_labels=plant.output_labels, input_labels=plant.input_labels,
        state_labels=plant.state_labels + loop.ctrl.state_labels,
        sysname=f'{plant.name}+{loop.ctrl.name}', return_x=True, plot_inputs=True,
        title=f"Closed-loop response of {plant.name} with {loop.ctrl.name}")
    resp.modes, resp.event_times, resp.noise = modes, np.array(events), v
    resp.diverged_at = rec.diverged_at
    return resp


class _Diverged(Exception):
    """The loop's state left the divergence bound."""


class _Record:
    """States, modes, inputs and events of a closed-loop run on `timepts`.

    Filled up to the time reached; `stop` marks the rest NaN (mode -1).
    """

    def __init__(self, loop, timepts):
        self.timepts, self.reached, self.diverged_at, self.events = timepts, timepts[0], None, []
        self.states = np.full((loop.n + loop.nc, timepts.size), np.nan)
        self.inputs = np.full((loop.m, timepts.size), np.nan)
        self.modes = np.full(timepts.size, -1)

    def stop(self, err):
        self.diverged_at = float(getattr(err, 'time', self.reached))
        after = self.timepts >= self.reached
        self.states[:, after], self.inputs[:, after], self.modes[after] = np.nan, np.nan, -1


def _check_bound(x, t, bound):
    if not np.max(np.abs(x)) <= bound:
        err = _Diverged(f"the plant state reaches {np.max(np.abs(x)):.3g} at t={t:.6g}, beyond "
                        f"max_deviation's bound {bound:.3g}")
        err.time = t
        raise err


def _progress(progress, timepts):
    if not isinstance(progress, (bool, np.bool_)):
        raise ControlArgument(f"progress must be True or False, got {progress!r}")
    return tqdm(total=float(timepts[-1] - timepts[0]), desc='closed loop', unit='s',
                disable=not progress, leave=False,
                bar_format='{l_bar}{bar}| {n:.3g}/{total:.3g} s')


def _chunks(timepts, T):
    """Breakpoints at the period boundaries between the first and last time."""
    inner = np.arange(np.floor(timepts[0] / T) + 1, np.ceil(timepts[-1] / T)) * T
    return np.concatenate([[timepts[0]], inner[inner > timepts[0]], [timepts[-1]]])


def _run_sampled(loop, opts, rec, z, mode, vfun, bar, bound):
    timepts = rec.timepts
    k0 = timepts[0] / loop.dt
    if abs(k0 - round(k0)) > 1e-9 * max(1.0, abs(k0)):
        raise ValueError(f"timepts[0]={timepts[0]:g} is not a sampling instant of the "
                         f"discrete controller (dt={loop.dt:g})")
    sampled = SampledLoop(loop, opts)
    n, states, u, modes = loop.n, rec.states, rec.inputs, rec.modes
    k, t = int(round(k0)), timepts[0]
    while t < timepts[-1]:
        t1 = min((k + 1) * loop.dt, timepts[-1])
        z1, mode1, flow, held = sampled.step(k, z, mode, vfun(k * loop.dt), t_end=t1)
        inside = (timepts >= t) & (timepts < t1)
        xs, modes[inside] = flow.evaluate(timepts[inside])
        # x_c[k] and u[k] hold on [k dt, (k+1) dt)
        states[:n, inside], states[n:, inside], u[:, inside] = xs[:n], z[n:, None], held[:, None]
        rec.events += [e[0] for e in flow.events]
        bar.update(t1 - t)
        z, mode, t, k = z1, mode1, t1, k + 1
        rec.reached = t
        _check_bound(z[:n], t, bound)
    states[:, -1], modes[-1] = z, mode
    u[:, -1] = sampled.sample(k, z, vfun(k * loop.dt))[n + loop.nc:]


def _run_continuous(loop, opts, rec, z, mode, vfun, bar, bound):
    lp, timepts = loop.hybrid_plant(), rec.timepts
    edges = _chunks(timepts, loop.T)
    for a, b in zip(edges[:-1], edges[1:]):
        flow = Flow(lp, a, b, z, mode, vfun, loop.params, **opts)
        inside = (timepts >= a) & (timepts < b)
        rec.states[:, inside], rec.modes[inside] = flow.evaluate(timepts[inside])
        rec.inputs[:, inside] = np.reshape(
            [lp.output(t, rec.states[:, j], vfun(t), loop.params)[loop.p:]
             for j, t in zip(np.flatnonzero(inside), timepts[inside])], (-1, loop.m)).T
        rec.events += [e[0] for e in flow.events]
        z, mode = flow.x_final, flow.mode_final
        bar.update(b - a)
        rec.reached = b
        _check_bound(z[:loop.n], b, bound)
    rec.states[:, -1], rec.modes[-1] = z, mode
    rec.inputs[:, -1] = lp.output(timepts[-1], z, vfun(timepts[-1]), loop.params)[loop.p:]


def closed_loop_orbit(plant, controller, orbit, *, saturation=None, controller_state=None,
                      tol=1e-10, max_iter=20, max_periods=20, rtol=None, atol=None,
                      method='DOP853', max_events=10000):
    """Periodic orbit of the closed hybrid loop and its Floquet multipliers.

    The loop of `closed_loop_response` (noise-free) is T-periodic; its
    period map acts on the plant state and the controller state at
    ``t = 0``.  The orbit is found by Newton's method on that map starting
    from the plant orbit and `controller_state` (for a linear controller
    and an inactive saturation the plant orbit with zero controller state is
    already the closed-loop orbit), with the exact Jacobian: variational
    equations, saltation matrices of the plant's events and, for a
    discrete controller, the Jacobians of the samples.  Its eigenvalues
    are the closed-loop Floquet multipliers, which verify a design on the
    nonlinear hybrid plant.

    Parameters
    ----------
    plant, controller, orbit, saturation
        As in `closed_loop_response`.
    controller_state : array_like, optional
        Guess of the controller state at t = 0 (default 0).
    tol, max_iter, max_periods : optional
        As in `periodic_orbit` (defaults 1e-10, 20, 20; continuous
        controllers); discrete
        controllers use `tol` and `max_iter` for Newton and fall back to
        `max_periods` periods of simulation.
    rtol, atol : float, optional
        `solve_ivp` tolerances; by default ``rtol = min(1e-10, tol/100)``
        and ``atol = rtol/100`` (below the Newton tolerance).
    method, max_events : optional
        Integration settings, as in `simulate_hybrid` (defaults 'DOP853',
        10000).

    Returns
    -------
    ClosedLoopOrbit
        With ``is_stable`` False when the controller destabilises the loop.
        When Newton's method does not converge from the starting point and
        the period map's Jacobian there has a multiplier of magnitude 1 or
        more, the loop diverges from its orbit and no search can converge
        (forward simulation only finds attracting orbits): the result then
        has ``converged=False``, ``is_stable=False``, the multipliers of
        that Jacobian (infinite if it overflows) and a `message`, and a
        warning is issued.  For a linear controller with an inactive
        saturation the starting point is the closed-loop orbit itself, so
        these multipliers are the loop's.

    Raises
    ------
    RuntimeError
        If no closed-loop orbit is found although the loop linearised at
        the starting point is stable (for example, a nonlinear controller
        whose orbit lies far from the guess).

    Warns
    -----
    UserWarning
        When the loop diverges (``converged=False``, see Returns).

    Examples
    --------
    Output feedback on ``ẋ = −x + cos t + u``: negative feedback speeds up
    the return to the orbit, positive feedback beyond 1 destabilises it:

    >>> sys = ct.nlsys(lambda t, x, u, p: -x + np.cos(t) + u, None, states=1, inputs=1)
    >>> orbit = ltp.periodic_orbit(sys, 2 * np.pi, [0.0])
    >>> ltp.closed_loop_orbit(sys, ct.ss([], [], [], [[-2.0]]), orbit).is_stable
    True
    >>> cl = ltp.closed_loop_orbit(sys, ct.ss([], [], [], [[3.0]]), orbit)
    >>> cl.is_stable, bool(np.isclose(cl.dominant_multiplier, np.exp(4 * np.pi)))
    (False, True)
    """
    opts = newton_solver_settings('closed_loop_orbit', tol, rtol, atol, method, max_events)
    loop = FeedbackLoop(plant, controller, orbit, saturation)
    z0, mode0 = _initial(loop, orbit.x0, 0.0 if controller_state is None else controller_state,
                         orbit.mode0, 0.0)
    if loop.dt:
        sampled = SampledLoop(loop, opts)
        start = _at_start(lambda: sampled.period_map(z0, mode0, jacobian=True), z0)

        def search(iterations, periods):
            return _sampled_orbit(sampled, z0, mode0, tol, iterations, periods, first=start)
    else:
        lp = loop.hybrid_plant()
        start = _at_start(lambda: _flow_map(lp, loop, z0, mode0, opts), z0)

        def search(iterations, periods):
            cl = periodic_orbit(lp, loop.T, z0, mode0, tol=tol, max_iter=iterations,
                                max_periods=periods, **opts)
            return _result(loop.T, cl.x0, loop.n, cl.mode0, orbit=cl, residual=cl.residual,
                           **_loop_multipliers(loop, lp, cl._flow))
    mult = _multipliers(start[2])
    if np.abs(mult[0]) < 1:
        return search(max_iter, max_periods)
    # unstable at the start: forward simulation runs away from the orbit, and
    # Newton converges within a few steps or not at all (not at all when one
    # period moves the state by more than its size)
    why = start[4] or f"one period moves the state by {start[3]:.3g} relative"
    if start[3] < 1:
        try:
            return search(min(max_iter, _UNSTABLE_NEWTON), 0)
        except RuntimeError as err:
            why = str(err)
    message = (f"the closed loop diverges: the period map at the starting point (the plant "
               f"orbit, controller state {'zero' if not np.any(z0[loop.n:]) else 'given'}) has "
               f"the multiplier |mu| = {np.abs(mult[0]):.4g} >= 1, so no orbit search "
               f"converges; the multipliers are those of the loop linearised there "
               f"(orbit search: {why})")
    warnings.warn(f"closed_loop_orbit: {message}", UserWarning, stacklevel=2)
    if loop.dt or start[5] is None:
        return _result(loop.T, z0, loop.n, mode0, start[2], None, start[3], converged=False,
                       message=message)
    found = _loop_multipliers(loop, lp, start[5])
    found['stable'] = False
    return _result(loop.T, z0, loop.n, mode0, orbit=None, residual=start[3], converged=False,
                   message=message, **found)


#: Newton iterations from a starting point where the loop is unstable.
_UNSTABLE_NEWTON = 5


def _flow_map(lp, loop, z0, mode0, opts):
    """Period map, final mode, Jacobian and flow of the continuous loop from ``z0``."""
    flow = Flow(lp, 0.0, loop.T, z0, mode0, lambda t: np.zeros(loop.p), loop.params,
                variational=True, **opts)
    return flow.x_final, flow.mode_final, flow.phi, flow


def _at_start(period_map, z0):
    """``(z_T, mode_T, Jacobian, residual, failure, flow)`` of the period map at the start.

    A loop that cannot be integrated over one period gets an infinite
    Jacobian and the integrator's message; `flow` is None unless the
    period map gives it (continuous loops).
    """
    try:
        zT, modeT, J, *flow = period_map()
    except IntegrationError as err:
        return None, None, np.full((len(z0), len(z0)), np.inf), np.inf, str(err), None
    return (zT, modeT, J, float(np.max(np.abs(zT - z0)) / (1 + np.max(np.abs(z0)))), '',
            flow[0] if flow else None)


def _sampled_orbit(sampled, z, mode, tol, max_iter, max_periods, first=None):
    """Newton's method on the sampled-data period map, with simulation fallback.

    `first` is the `_at_start` evaluation at `z` (reused by the first iteration).
    """
    if not isinstance(tol, numbers.Real) or not 0 < tol < 1:
        raise ValueError(f"tol must be a number in (0, 1), got {tol!r}")
    max_iter = check_positive_int(max_iter, 'max_iter')
    max_periods = check_positive_int(max_periods, 'max_periods', minimum=0)
    loop, periods, why = sampled.loop, 0, "no convergence"
    while True:
        for _ in range(max_iter + 1):
            if first is not None:
                (zT, modeT, J, _, why, _), first = first, None
                if zT is None:
                    break
            else:
                try:
                    zT, modeT, J = sampled.period_map(z, mode, jacobian=True)
                except IntegrationError as err:
                    why = str(err)
                    break
            res = np.max(np.abs(zT - z)) / (1 + np.max(np.abs(z)))
            if modeT == mode and res <= tol:
                return _result(loop.T, z, loop.n, mode, J, None, res)
            if modeT != mode or not (np.all(np.isfinite(zT)) and np.all(np.isfinite(J))):
                why = "the period changes mode or the state is no longer finite"
                break
            step = np.linalg.lstsq(J - np.eye(len(z)), z - zT, rcond=None)[0]
            if np.max(np.abs(step)) > 10 * (1 + np.max(np.abs(z))):
                why = f"Newton step of size {np.max(np.abs(step)):.3g} rejected (divergence)"
                break
            z = z + step
        if periods >= max_periods:
            raise RuntimeError(f"closed_loop_orbit: no T-periodic orbit of the sampled-data "
                               f"loop found (tol={tol:g}) after {periods} simulated periods "
                               f"({why})")
        try:
            for _ in range(min(10, max_periods - periods)):
                z, mode, _ = sampled.period_map(z, mode)
                periods += 1
        except IntegrationError as err:
            raise RuntimeError(f"closed_loop_orbit: the simulated sampled-data loop "
                               f"diverges after {periods} periods: {err}") from err
