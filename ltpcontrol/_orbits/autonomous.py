"""Periodic orbits of autonomous (clock-free) plants, whose period is unknown.

An autonomous plant ``ẋ = f_i(x)`` — smooth, or hybrid with guards and
resets that do not depend on t — has orbits ``x̄(t + T) = x̄(t)`` whose
period T is an unknown.  `limit_cycle` solves the single-shooting problem

    F(x, T) = [φ_T(x) − x;  s(x)] = 0

for ``(x, T)`` by Newton's method, where ``φ_T`` is the flow over time T
and ``s(x) = 0`` a Poincaré section (the phase condition that removes the
freedom to slide along the orbit).  Its Jacobian is the bordered matrix

    [[Φ − I, f(φ_T(x))], [∇s, 0]],

``Φ = ∂φ_T/∂x`` from the variational equations and the saltation matrices
of the events.  ``Φ f(x̄(0)) = f(x̄(T)) = f(x̄(0))``: one Floquet multiplier
is 1 (the phase direction) and the others decide orbital stability.  They
are the eigenvalues of the Jacobian of the Poincaré (return) map,
``(I − f ∇sᵀ / (∇s·f)) Φ``, apart from its zero eigenvalue along ``f``.
"""

import numbers
import time

import numpy as np
from control.exception import ControlArgument, ControlDimension
from scipy.optimize import brentq

from .hybrid import constant_input, Flow, plant_params, solver_settings
from .hybrid_plant import central_jacobian
from .settings import inexact_options, newton_solver_settings
from .orbits import PeriodicOrbit, as_hybrid, time_mismatch, _floor_hint
from .._core.validation import check_period, check_positive, check_positive_int, real_array

__all__ = ['limit_cycle', 'poincare_map']


class _Section:
    """Poincaré section ``s(x) = 0`` crossed in `direction` while in `mode`.

    `user` is the callable the user gave (None for the default hyperplane).
    """

    def __init__(self, func, direction, mode, user):
        self.func, self.direction, self.mode, self.user = func, direction, mode, user

    def __call__(self, x):
        value = np.asarray(self.func(x), float)
        if value.size != 1:
            raise ControlArgument(f"section must return a real scalar, got shape {value.shape}")
        return float(value.reshape(()))

    def gradient(self, x):
        return central_jacobian(self, x)[0]


def _section(hp, section, direction, mode, anchor, u0, params):
    """The user's section, or the hyperplane through `anchor` normal to the flow there."""
    if direction not in (1, -1):
        raise ValueError(f"direction must be 1 or -1, got {direction!r}")
    if section is None:
        normal = hp.dynamics(0.0, anchor, u0, params, mode=mode)
        if not np.linalg.norm(normal) > 0:
            raise ValueError("x0 is an equilibrium of the plant (f(x0) = 0): it lies on no "
                             "periodic orbit and defines no section; start elsewhere")
        normal = normal / np.linalg.norm(normal)
        return _Section(lambda x: normal @ (np.asarray(x) - anchor), 1, mode, None)
    if not callable(section):
        raise ControlArgument(f"section must be callable, got {type(section).__name__}")
    return _Section(section, direction, mode, section)


def _check_autonomous(hp, x0, u0, params):
    """Raise when a vector field or guard depends explicitly on t."""
    bad = time_mismatch(hp, x0, u0, params, [(0.0, t) for t in (0.7312, 3.1416, 17.123)])
    if bad is not None:
        label, mode, _, t, _ = bad
        raise ValueError(f"plant is not autonomous: {label} of mode {mode!r} depends on t "
                         f"(at t=0 and t={t}); for a clock-driven plant use periodic_orbit "
                         "with the forcing period")


class _Problem:
    """Plant, input, parameters and solver options of one autonomous orbit problem."""

    def __init__(self, hp, u0, params, opts, deadline):
        self.hp, self.u0, self.params, self.opts = hp, u0, params, opts
        self.deadline = deadline

    def flow(self, x, mode, duration, variational=False, options=None, factored=False):
        if self.deadline is not None and time.monotonic() > self.deadline:
            raise TimeoutError("the time limit (timeout) was reached")
        u0 = self.u0
        return Flow(self.hp, 0.0, duration, x, mode, lambda t: u0, self.params,
                     variational=variational, factored=factored, **(options or self.opts))

    def f(self, mode, x):
        return self.hp.dynamics(0.0, x, self.u0, self.params, mode=mode)

    def first_crossing(self, x, mode, section, max_time, chunk=None, skip=0.0):
        """Time of the first crossing of `section` after `skip`, or None before `max_time`.

        Integrates in chunks of length `chunk` (growing from the flow's time
        scale when None) and checks the sign of the section at the solver's
        steps, as `solve_ivp` does for events.
        """
        growing = chunk is None
        t0 = 0.0
        scale = 1e3 * (1 + np.max(np.abs(x)))
        if chunk is None:
            # time scale |x| / |f(x)|, doubled after each chunk without a crossing
            chunk = (1 + np.max(np.abs(x))) / max(np.max(np.abs(self.f(mode, x))), 1e-300)
        while t0 < max_time:
            duration = min(chunk, max_time - t0)
            chunk = 2 * chunk if growing else chunk
            try:
                fl = self.flow(x, mode, duration)
            except RuntimeError as err:
                raise RuntimeError(f"the trajectory diverges or cannot be integrated before it "
                                   f"crosses the section ({err})") from None
            for start, end, seg_mode, sol in fl.segments:
                if seg_mode != section.mode or end <= start:
                    continue
                ts = np.unique(np.concatenate([np.linspace(start, end, 9),
                                               sol.ts[(sol.ts > start) & (sol.ts < end)]]))
                vals = section.direction * np.array(
                    [section(sol(t)[:self.hp.nstates]) for t in ts])
                for k in np.flatnonzero((vals[:-1] < 0) & (vals[1:] >= 0)):
                    if t0 == 0 and ts[k] == 0 and abs(vals[0]) <= 1e-12 * scale:
                        continue  # leaving the section from a start on it
                    root = brentq(lambda t: section.direction * section(sol(t)[:self.hp.nstates]),
                                  ts[k], ts[k + 1], xtol=1e-14, rtol=4 * np.finfo(float).eps)
                    if t0 + root > skip:
                        return t0 + root
            x, mode = fl.x_final, fl.mode_final
            if not np.all(np.isfinite(x)) or np.max(np.abs(x)) > scale:
                raise RuntimeError(f"the trajectory diverges (|x| = {np.max(np.abs(x)):.3g} "
                                   f"at t = {t0 + duration:.4g}) before it crosses the section")
            t0 += duration
        return None


def poincare_map(plant, x0, section=None, mode0=0, *, direction=1, max_time=None, u0=None,
                 params=None, jacobian=False, rtol=1e-10, atol=1e-12, method='DOP853',
                 max_events=10000):
    """Poincaré (return) map of an autonomous (hybrid) plant.

    Integrates from `x0` until the trajectory next crosses the section
    ``section(x) = 0`` in `direction` while in mode `mode0`, and returns
    the crossing state and time.  With ``jacobian=True`` it also returns
    the Jacobian of the map ``x0 -> x(t*)``,

    ``(I − f ∇sᵀ / (∇s·f)) Φ(t*)``,

    with ``Φ`` from the variational equations and saltation matrices and
    the projection accounting for the state dependence of the crossing
    time ``t*``.  Restricted to the section, it is the linearised return
    map (e.g. a legged robot's apex-to-apex stride map).

    Parameters
    ----------
    plant : control.NonlinearIOSystem or HybridPlant
        Autonomous continuous-time plant (vector fields and guards
        independent of t).
    x0 : array_like
        Initial state.
    section : callable, optional
        ``section(x) -> float``.  Default: the hyperplane through `x0`
        normal to the vector field there, crossed in the flow direction.
    mode0 : int or str, optional
        Mode of `x0`; crossings count only in this mode (hybrid plants).
    direction : {1, -1}, optional
        Count crossings where ``section`` increases (1, default) or
        decreases (-1).  Ignored for the default section.
    max_time : float, optional
        Integration limit; `ValueError` when no crossing occurs before it.
        Default: 1000 time units.
    u0 : array_like, optional
        Constant input (zero by default).
    params : dict, optional
        Parameters overriding the plant's defaults.
    jacobian : bool, optional
        Also return the Jacobian of the map.
    rtol, atol, method, max_events : optional
        Integration settings, as in `simulate_hybrid`.

    Returns
    -------
    x_next : ndarray
        State at the crossing.
    t_return : float
        Crossing time.
    jac : ndarray, shape (n, n)
        Jacobian of the map (only with ``jacobian=True``).

    Examples
    --------
    The harmonic oscillator returns to the half-line ``y = 0, x > 0`` after
    2π, and its return map is the identity on that line:

    >>> sys = ct.nlsys(lambda t, x, u, p: [x[1], -x[0]], None, states=2, inputs=0)
    >>> x1, t1, J = ltp.poincare_map(sys, [1.0, 0.0], lambda x: x[1], direction=-1,
    ...                              jacobian=True)
    >>> bool(np.isclose(t1, 2 * np.pi)), bool(np.allclose(J, [[1, 0], [0, 0]], atol=1e-6))
    (True, True)
    """
    opts = solver_settings('poincare_map', rtol, atol, method, max_events)
    if not isinstance(jacobian, (bool, np.bool_)):
        raise ControlArgument(f"jacobian must be True or False, got {jacobian!r}")
    hp, x0, mode0, u0, params = _prepare(plant, x0, mode0, u0, params, None)
    max_time = 1000.0 if max_time is None else check_positive(max_time, 'max_time')
    sec = _section(hp, section, direction, mode0, x0, u0, params)
    prob = _Problem(hp, u0, params, opts, None)
    t_cross = prob.first_crossing(x0, mode0, sec, max_time)
    if t_cross is None:
        raise ValueError(f"the trajectory from x0 does not cross the section within "
                         f"max_time={max_time:g}")
    fl = prob.flow(x0, mode0, t_cross, variational=bool(jacobian))
    if not jacobian:
        return fl.x_final, float(t_cross)
    return fl.x_final, float(t_cross), _projected(prob, sec, fl)


def _projected(prob, sec, fl):
    """``(I − f ∇sᵀ / (∇s·f)) Φ``: Jacobian of the flow stopped on the section."""
    f = prob.f(fl.mode_final, fl.x_final)
    grad = sec.gradient(fl.x_final)
    rate = grad @ f
    if rate == 0:
        raise ValueError("the flow is tangent to the section at the crossing")
    return fl.phi - np.outer(f, grad @ fl.phi) / rate


def _prepare(plant, x0, mode0, u0, params, jacobian):
    hp = as_hybrid(plant, jacobian)
    x0 = real_array(x0, 'x0', ndim=(0, 1)).reshape(-1)
    if x0.size != hp.nstates:
        raise ControlDimension(f"x0 must have {hp.nstates} entries, got {x0.size}")
    mode0 = hp.mode_index(mode0, 'mode0')
    u0 = constant_input(hp, u0, 'u0')
    params = plant_params(hp, params)
    _check_autonomous(hp, x0, u0, params)
    return hp, x0, mode0, u0, params


def limit_cycle(plant, period, x0, mode0=0, *, section=None, direction=1, u0=None,
                params=None, jacobian=None, tol=1e-10, max_iter=20, max_periods=200,
                timeout=None, npoints=200, rtol=None, atol=None, method='DOP853',
                max_events=10000):
    """Periodic orbit of an autonomous plant, with its period as an unknown.

    Single shooting with a Poincaré-section phase condition: Newton's
    method on ``φ_T(x) − x = 0, s(x) = 0`` for the state ``x`` on the
    section and the period ``T`` (see the module notes), with the exact
    Jacobian from variational equations and saltation matrices.  When
    Newton fails the return map is iterated (forward simulation towards an
    attracting orbit) in blocks of 10 returns and Newton is retried, up to
    `max_periods` returns.  Newton converges to the orbit nearest the
    guess, stable or not.

    Parameters
    ----------
    plant : control.NonlinearIOSystem or HybridPlant
        Autonomous continuous-time plant: vector fields and guards must not
        depend on t (checked at sample points).
    period : float or None
        Guess of the period.  The first return time to the section replaces
        it when within a third of it (None: always).
    x0 : array_like
        Initial guess of a state on (or near) the orbit.  When it is off
        a user-given section, the trajectory from it is first followed to
        the section (for at most 20 period guesses).
    mode0 : int or str, optional
        Mode of `x0` and of the section (hybrid plants).
    section : callable, optional
        ``section(x) -> float``, the Poincaré section ``section(x) = 0``
        crossed once per period in `direction` while in `mode0` (e.g. the
        apex ``v_z = 0`` of a hopping gait).  Default: the hyperplane
        through `x0` normal to the vector field there.
    direction : {1, -1}, optional
        Crossing direction of a user-given section (default 1: increasing).
    u0 : array_like, optional
        Constant input held along the orbit (zero by default).
    params : dict, optional
        Parameters overriding the plant's defaults.
    jacobian : callable, optional
        ``jacobian(t, x, u, params) -> ∂f/∂x`` for a `NonlinearIOSystem`
        plant (central differences otherwise).  Hybrid plants carry it in
        each `HybridMode`.
    tol : float, optional
        Convergence threshold on the relative residual
        ``max(‖φ_T(x) − x‖∞ / (1 + ‖x‖∞), |s(x)|)`` (default 1e-10).
    max_iter : int, optional
        Newton iterations per attempt (20).
    max_periods : int, optional
        Budget of returns to the section simulated after failed Newton
        attempts (200); also bounds every search for a crossing to
        `max_periods` period guesses.
    timeout : float, optional
        Wall-clock limit in seconds (none by default).
    npoints : int, optional
        Number of grid points of the stored orbit (200).
    rtol, atol : float, optional
        `solve_ivp` tolerances; by default ``rtol = min(1e-10, tol/100)``
        and ``atol = rtol/100``, so that the integration error of the
        period map stays below the Newton tolerance.
    method, max_events : optional
        Integration settings, as in `simulate_hybrid`.

    Returns
    -------
    PeriodicOrbit
        With ``autonomous=True``: the multiplier of the phase direction is
        reported as `phase_multiplier` (1 up to the residual), the others
        as `stability_multipliers`, and `is_stable` is decided by the
        latter.  `poincare_jacobian` is the Jacobian of the return map.

    Raises
    ------
    ValueError
        If the plant depends on t, `x0` is an equilibrium, or the
        trajectory from `x0` does not reach the section.
    RuntimeError
        If Newton and forward simulation do not converge, the trajectory
        approaches an equilibrium or diverges; the message lists what was
        tried.
    TimeoutError
        If `timeout` seconds pass.

    See Also
    --------
    periodic_orbit : orbits of clock-driven plants (known period).
    orbit_continuation : follow the orbit as a parameter changes.

    Examples
    --------
    The van der Pol oscillator with μ = 1 has a limit cycle of period
    6.6633; its phase multiplier is 1 and the other one is small:

    >>> def vdp(t, x, u, p):
    ...     return [x[1], p['mu'] * (1 - x[0] ** 2) * x[1] - x[0]]
    >>> sys = ct.nlsys(vdp, None, states=2, inputs=0, params={'mu': 1.0})
    >>> orbit = ltp.limit_cycle(sys, 6.0, [2.0, 0.0], section=lambda x: x[1],
    ...                         direction=-1)
    >>> round(orbit.period, 4), orbit.is_stable
    (6.6633, True)
    >>> bool(abs(orbit.phase_multiplier - 1) < 1e-8), bool(orbit.stability_multipliers[0] < 1e-3)
    (True, True)
    """
    opts = newton_solver_settings('limit_cycle', tol, rtol, atol, method, max_events)
    hp, x0, mode0, u0, params = _prepare(plant, x0, mode0, u0, params, jacobian)
    if period is not None:
        period = check_period(period)
    if isinstance(tol, bool) or not isinstance(tol, numbers.Real) or not 0 < tol < 1:
        raise ValueError(f"tol must be a number in (0, 1), got {tol!r}")
    max_iter = check_positive_int(max_iter, 'max_iter')
    max_periods = check_positive_int(max_periods, 'max_periods', minimum=0)
    npoints = check_positive_int(npoints, 'npoints', minimum=2)
    if timeout is not None:
        timeout = check_positive(timeout, 'timeout')
    deadline = None if timeout is None else time.monotonic() + timeout
    sec = _section(hp, section, direction, mode0, x0, u0, params)
    prob = _Problem(hp, u0, params, opts, deadline)
    # forward simulation only supplies starting guesses: moderate tolerances
    loose = dict(opts, rtol=max(opts['rtol'], 1e-8), atol=max(opts['atol'], 1e-10))
    search = _Problem(hp, u0, params, loose, deadline)
    x, period = _start_on_section(search, sec, x0, mode0, period)
    return _shoot(prob, search, sec, x, period, tol, max_iter, max_periods, npoints)


def _return(search, sec, x, period, max_periods, what):
    """Next crossing of the section from `x` on it: (state, return time)."""
    t = search.first_crossing(x, sec.mode, sec, max(max_periods, 2) * period, period,
                              skip=1e-6 * period)
    if t is None:
        raise RuntimeError(f"{what}: the trajectory does not return to the section within "
                           f"{max(max_periods, 2)} period guesses ({period:.4g} each); it "
                           "may approach an equilibrium, or the period guess is far too small")
    return search.flow(x, sec.mode, t).x_final, t


def _start_on_section(search, sec, x0, mode0, period):
    """A start on the section and a period guess (the first return time if not given).

    The searches span 20 period guesses (1000 time units without a guess).
    """
    horizon = 20 * period if period is not None else 1000.0
    x = x0
    if abs(sec(x0)) > 1e-12 * (1 + np.max(np.abs(x0))):
        t = search.first_crossing(x0, mode0, sec, horizon, period)
        if t is None:
            raise ValueError(f"the trajectory from x0 does not cross the section within "
                             f"t={horizon:g}: the orbit may not cross it, or x0 is in the "
                             "basin of an equilibrium")
        x = search.flow(x0, mode0, t).x_final
    if period is None:
        t = search.first_crossing(x, mode0, sec, horizon, skip=1e-9 * horizon)
        if t is None:
            raise ValueError(f"the trajectory does not return to the section within "
                             f"t={horizon:g}: give a period guess, or x0 is not near an orbit")
        return x, t
    # the first return time refines the guess, unless the section is crossed
    # several times per period or the trajectory leaves (unstable orbits)
    try:
        t = search.first_crossing(x, mode0, sec, 1.5 * period, period / 4,
                                  skip=1e-9 * period)
    except RuntimeError:
        t = None
    return x, t if t is not None and abs(t - period) < period / 3 else period


def _shoot(prob, search, sec, x, period, tol, max_iter, max_periods, npoints):
    """Newton attempts alternating with blocks of return-map iterations."""
    hp, mode = prob.hp, sec.mode
    tried, returns = [], 0
    sim_x, sim_T = x, period
    while True:
        orbit = _newton(prob, sec, x, period, tol, max_iter, npoints, returns, tried)
        if orbit is not None:
            return orbit
        if returns >= max_periods:
            break
        # fall back to iterating the return map towards an attracting orbit
        nret = min(10, max_periods - returns)
        for _ in range(nret):
            sim_x, sim_T = _return(search, sec, sim_x, sim_T, max_periods,
                                   f"forward simulation after {returns} returns")
            returns += 1
        _check_not_equilibrium(prob, mode, sim_x, sim_T, f"after {returns} returns")
        x, period = sim_x, sim_T
        tried.append(f"forward simulation for {returns} returns: last return time "
                     f"{sim_T:.6g}")
    raise RuntimeError("limit_cycle did not converge to a periodic orbit "
                       f"(tol={tol:g}); tried: " + "; ".join(tried) +
                       f". In mode {hp.mode_names[mode]!r} the response may be quasi-periodic, "
                       "chaotic or periodic with several crossings of the section per period; "
                       "try another x0, section or period guess, or a larger max_periods.")


def _check_not_equilibrium(prob, mode, x, period, where):
    speed = np.max(np.abs(prob.f(mode, x))) * period
    if speed <= 1e-6 * (1 + np.max(np.abs(x))):
        raise RuntimeError(f"the trajectory approaches an equilibrium ({where}: |f(x)| T = "
                           f"{speed:.3g} at x = {np.array2string(x, precision=4)}); the plant "
                           "has no periodic orbit there")


def _newton(prob, sec, x, T, tol, max_iter, npoints, returns, tried):
    """One Newton attempt on [φ_T(x) − x; s(x)] = 0; a PeriodicOrbit or None."""
    hp, n, mode = prob.hp, prob.hp.nstates, sec.mode
    where = f"Newton after {returns} returns"
    # `best`: the point (and period) whose residual is `last`
    last, stalled, tight, best = np.inf, 0, False, (x, T)
    for it in range(max_iter + 1):
        if not 0 < T < np.inf:
            tried.append(f"{where}: the period left (0, ∞)")
            return None
        # inexact Newton: loose integration while the residual is large,
        # the requested accuracy once it is small or a loose step misled;
        # the iterations need Φ only to first order: no product form
        # (`_finish` takes the multipliers from one flow at the solution)
        options = prob.opts if tight else inexact_options(prob.opts, last)
        exact = options['rtol'] == prob.opts['rtol']
        try:
            fl = prob.flow(x, mode, T, variational=True, options=options)
        except RuntimeError as err:
            tried.append(f"{where}: {err}")
            return None
        if fl.mode_final != mode:
            tried.append(f"{where}: the period ends in mode "
                         f"{hp.mode_names[fl.mode_final]!r}, not {hp.mode_names[mode]!r}")
            return None
        scale = 1 + np.max(np.abs(x))
        gap, phase = fl.x_final - x, sec(x)
        res = max(np.max(np.abs(gap)), abs(phase)) / scale
        if res <= tol and exact:
            _check_not_equilibrium(prob, mode, x, T, "Newton")
            return _finish(prob, sec, fl, x, T, npoints, res, it, returns)
        if not exact and res > 0.9 * last:
            # no progress with loose integration: on at full accuracy from the
            # best point so far
            tight, (x, T), last, stalled = True, best, np.inf, 0
            continue
        stalled = stalled + 1 if res > 0.9 * last else 0
        if res > 1e3 * last or stalled >= 3 or it == max_iter:
            tried.append(f"{where}: residual {res:.3g} after {it} iterations"
                         + (" (no progress)" if stalled >= 3 else "")
                         + _floor_hint(res, prob.opts['rtol']))
            return None
        last, best = res, (x, T)
        # bordered system [[Φ − I, f(φ_T(x))], [∇s, 0]] [δx; δT] = −[φ_T(x) − x; s(x)]
        jac = np.zeros((n + 1, n + 1))
        jac[:n, :n] = fl.phi - np.eye(n)
        jac[:n, n] = prob.f(mode, fl.x_final)
        jac[n, :n] = sec.gradient(x)
        # least squares handles further neutral directions (e.g. conserved energy)
        step = np.linalg.lstsq(jac, -np.append(gap, phase), rcond=None)[0]
        if np.max(np.abs(step[:n])) > 10 * scale:
            if not exact:
                # a loose Jacobian misled: again from here at full accuracy
                tight, last, stalled = True, np.inf, 0
                continue
            tried.append(f"{where}: step of size {np.max(np.abs(step[:n])):.3g} "
                         "rejected (divergence)")
            return None
        # damped step: the period changes by at most half of itself
        step *= min(1.0, 0.5 * T / max(abs(step[n]), 1e-300))
        x, T = x + step[:n], T + step[n]
    return None  # pragma: no cover - the loop always returns


def _finish(prob, sec, fl, x, T, npoints, res, iterations, returns):
    grad = sec.gradient(x)
    f0 = prob.f(sec.mode, x)
    if sec.direction * (grad @ f0) <= 0:
        raise RuntimeError("limit_cycle converged to an orbit that crosses the section in the "
                           "other direction; use direction=-1 or another section")
    # the multipliers from the product form of the period map
    if not fl.factored:
        fl = prob.flow(x, sec.mode, T, variational=True, factored=True)
    orbit = PeriodicOrbit(prob.hp, float(T), fl, x, sec.mode, npoints, prob.params, prob.u0, res,
                          iterations, returns, phase_direction=f0)
    orbit.section = sec
    orbit.poincare_jacobian = fl.phi - np.outer(f0, grad @ fl.phi) / (grad @ f0)
    # the period is known to about res (1 + |x|) / |f(x)|, and Σ log|μ| =
    # ∮ tr ∂f/∂x dt changes with it at the rate tr ∂f/∂x(x)
    trace = np.trace(prob.hp.state_jacobian(0.0, x, prob.u0, prob.params, mode=sec.mode))
    dT = res * (1 + np.max(np.abs(x))) / max(np.max(np.abs(f0)), 1e-300)
    orbit.multiplier_error = float(orbit.multiplier_error + abs(trace) * dT)
    return orbit
