"""Periodic orbits of clock-driven plants and their LTP linearisation.

A plant forced with period T (a continuous-time `control.NonlinearIOSystem`
whose update function depends periodically on t, or a `HybridPlant`) has a
T-periodic steady state ``x̄(t)``: a fixed point of the period map
``P: x(0) -> x(T)``.  `periodic_orbit` finds it by Newton's method on
``P(x) − x = 0`` (shooting), with the exact Jacobian of ``P`` from the
variational equations and saltation matrices at the events, falling back to
forward simulation when Newton does not converge.  `linearize_orbit` turns
the orbit into the LTP model of thesis eqs. (3.2)-(3.4), or for hybrid
plants the time-switching approximation of eqs. (3.6)-(3.9).
"""

import numbers
import warnings

import numpy as np
from control import NonlinearIOSystem
from control.exception import ControlArgument, ControlDimension

from .hybrid import (constant_input, Flow, IntegrationError, plant_params, solver_settings,
                     _RESTART)
from .hybrid_plant import HybridMode, HybridPlant, central_jacobian
from .settings import inexact_options, newton_solver_settings
from .multipliers import product_multipliers
from .tabulate import tabulate
from .._core.ltpsys import ltpss
from .._core.periodic_matrix import PeriodicMatrix
from .._core.validation import check_period, check_positive_int, real_array

__all__ = ['PeriodicOrbit', 'periodic_orbit', 'period_map', 'linearize_orbit']


class PeriodicOrbit:
    """T-periodic steady state of a forced (hybrid) plant.

    Returned by `periodic_orbit` (and, for autonomous plants, by
    `limit_cycle`); not meant to be built directly.  Calling
    the object, ``orbit(t)``, evaluates ``x̄(t mod T)`` from the solver's
    dense output (shape ``(n,)`` for scalar t, ``(n, len(t))`` otherwise).

    Attributes
    ----------
    period : float
        The period T.
    x0 : ndarray
        Orbit state at t = 0.
    mode0 : int
        Mode active at t = 0.
    time : ndarray, shape (npoints,)
        Uniform grid ``k T / npoints`` over one period.
    states : ndarray, shape (n, npoints)
        Orbit states on `time`.
    modes : ndarray of int, shape (npoints,)
        Active mode on `time`.
    switching_times : ndarray
        Event times in ``(0, T)`` along the orbit.
    mode_sequence : list of int
        Modes active on ``[0, t_1), [t_1, t_2), ..., [t_M, T)``.
    saltation_matrices : list of ndarray
        Saltation matrix of each event.
    monodromy : ndarray, shape (n, n)
        Jacobian of the period map at ``x0``: the exact linearised return
        map, including the saltation matrices of hybrid events, formed as
        one matrix (its small eigenvalues are not accurate; see
        `multipliers`).
    multipliers : ndarray
        Floquet multipliers (eigenvalues of the period map's Jacobian),
        sorted by decreasing modulus.  They are computed from the product
        form of the Jacobian — transition matrices of short intervals and
        saltation matrices, combined by QR sweeps — so that each one is
        accurate relative to its own size (a multiplier of 1e-38 of a stiff
        orbit included); moduli below 1e-308 underflow to 0 (see
        `log_multipliers`).
    log_multipliers : ndarray
        ``log|μ|`` of `multipliers`, finite far below the float range.
    multiplier_error : float
        Estimated relative error of every multiplier: the mismatch of
        Liouville's formula ``Σ log|μ_i| = ∮ tr ∂f/∂x dt + Σ log|det S_j|``
        (trace integrated with the variational equations), plus ``rtol``
        times the trace integral, plus the error estimate of the QR sweeps;
        for an autonomous orbit also the effect of the period's
        uncertainty (residual over the speed ``|f(x0)|``) through
        ``tr ∂f/∂x(x0)``.  Errors of central-difference Jacobians (about
        1e-10 relative) and, for forced orbits, of the orbit's location
        (the residual `tol`) are not included.
    is_stable : bool
        True when all `stability_multipliers` lie strictly inside the unit
        circle.
    autonomous : bool
        True for an orbit of an autonomous plant (`limit_cycle`), whose
        period is an unknown and whose monodromy has the multiplier 1 along
        the flow.
    phase_multiplier : float or None
        Autonomous orbits: the multiplier of the phase direction (1 up to
        the residual); None otherwise.
    stability_multipliers : ndarray
        The multipliers that decide (orbital) stability: all of them for a
        forced plant, all but the phase multiplier for an autonomous one.
    section : callable or None
        Autonomous orbits: the Poincaré section ``section(x) = 0`` used as
        phase condition (``x0`` lies on it); None otherwise.
    poincare_jacobian : ndarray or None
        Autonomous orbits: Jacobian ``(I − f ∇sᵀ / (∇s·f)) Φ`` of the
        return map to the section at ``x0``; its eigenvalues are the
        stability multipliers and 0 (along the flow).  None otherwise.
    residual : float
        Final relative residual ``‖P(x0) − x0‖∞ / (1 + ‖x0‖∞)``.
    iterations : int
        Newton iterations of the successful attempt.
    periods_simulated : int
        Periods of forward simulation (returns to the section for an
        autonomous orbit) used before convergence.
    plant : HybridPlant
        The plant as a hybrid plant (a smooth system becomes one mode).
    params : dict
        Parameters used.
    u0 : ndarray
        Constant input along the orbit.

    Examples
    --------
    The steady state of ``dx/dt = -x + cos t`` is ``x̄(t) = (cos t + sin t)/2``
    with the single Floquet multiplier ``e^{-2π}``:

    >>> sys = ct.nlsys(lambda t, x, u, p: -x + np.cos(t), None, states=1, inputs=0)
    >>> orbit = ltp.periodic_orbit(sys, 2 * np.pi, [0.0], npoints=8)
    >>> orbit.states.shape, orbit.is_stable
    ((1, 8), True)
    >>> bool(np.allclose(orbit(np.pi / 2), [0.5], atol=1e-8))
    True
    >>> bool(np.isclose(orbit.multipliers[0].real, np.exp(-2 * np.pi)))
    True
    """

    def __init__(self, plant, period, flow, x0, mode0, npoints, params, u0,
                 residual, iterations, periods, phase_direction=None):
        self.plant, self.period, self._flow = plant, period, flow
        self.x0, self.mode0, self.params, self.u0 = np.array(x0), mode0, params, u0
        self.time = np.arange(npoints) * period / npoints
        self.states, self.modes = flow.evaluate(self.time)
        self.switching_times = np.array([e[0] for e in flow.events])
        self.mode_sequence = [mode0] + [e[2] for e in flow.events]
        self.saltation_matrices = list(flow.saltations)
        self.monodromy = flow.phi
        mult = flow_multipliers(flow, phase_direction)
        self.multipliers, self.log_multipliers = mult.values, mult.log_moduli
        self.multiplier_error = mult.error
        self.autonomous = phase_direction is not None
        self.phase_multiplier, self.stability_multipliers = None, mult.stability
        self.section = self.poincare_jacobian = None
        if self.autonomous:
            self.phase_multiplier = float(np.real(mult.values[mult.phase]))
        self.is_stable = bool(np.all(mult.stability_log_moduli < 0))
        self.residual, self.iterations, self.periods_simulated = residual, iterations, periods

    def __call__(self, t):
        tarr = real_array(t, 't', ndim=(0, 1))
        states, _ = self._flow.evaluate(np.mod(np.atleast_1d(tarr), self.period))
        return states[:, 0] if tarr.ndim == 0 else states

    def __repr__(self):
        mags = ', '.join(f'{abs(m):.4g}' for m in self.multipliers)
        kind = "autonomous, " if self.autonomous else ""
        return (f"<PeriodicOrbit {kind}period={self.period:g}, {len(self.switching_times)} events, "
                f"|multipliers|=[{mags}], stable={self.is_stable}>")


def flow_multipliers(flow, phase_direction=None):
    """`OrbitMultipliers` of a variational `Flow` over one period (product form).

    Examples
    --------
    >>> from ltpcontrol._orbits.orbits import flow_multipliers
    >>> sys = ct.nlsys(lambda t, x, u, p: -x + np.cos(t), None, states=1, inputs=0)
    >>> orbit = ltp.periodic_orbit(sys, 2 * np.pi, [0.0], npoints=8)
    >>> mult = flow_multipliers(orbit._flow)
    >>> bool(np.isclose(mult.values[0].real, np.exp(-2 * np.pi)))
    True
    >>> bool(np.isclose(mult.log_moduli[0], -2 * np.pi))
    True
    """
    return product_multipliers(
        flow.factors or [flow.phi], rtol=flow.rtol, restart=_RESTART,
        trace_integral=flow.trace_integral if flow.factored else None,
        saltations=flow.saltations, phase_direction=phase_direction, monodromy=flow.phi)


def as_hybrid(plant, jacobian):
    """A `HybridPlant` view of `plant` (a smooth system becomes one mode).

    Examples
    --------
    >>> from ltpcontrol._orbits.orbits import as_hybrid
    >>> sys = ct.nlsys(lambda t, x, u, p: -x + np.cos(t), None, states=1, inputs=0, name='P')
    >>> plant = as_hybrid(sys, None)
    >>> type(plant).__name__, plant.mode_names, as_hybrid(plant, None) is plant
    ('HybridPlant', ['P'], True)
    >>> plant.dynamics(0.0, np.array([1.0]), [])
    array([0.])
    """
    if jacobian is not None and not callable(jacobian):
        raise ControlArgument(f"jacobian must be callable, got {type(jacobian).__name__}")
    if isinstance(plant, HybridPlant):
        if jacobian is not None:
            raise ValueError("jacobian applies to NonlinearIOSystem plants; give each "
                             "HybridMode its own jacobian")
        return plant
    if not isinstance(plant, NonlinearIOSystem):
        raise ControlArgument("plant must be a control.NonlinearIOSystem or a HybridPlant, "
                              f"got {type(plant).__name__}")
    if plant.dt != 0:
        raise ValueError(f"plant must be a continuous-time system, got dt={plant.dt}")
    if plant.outfcn is None and plant.noutputs != plant.nstates:
        raise ControlDimension("plant has no output function but its outputs are not the states")
    mode = HybridMode(plant.updfcn, name=plant.name, jacobian=jacobian)
    return HybridPlant([mode], plant.outfcn, states=plant.state_labels,
                       inputs=plant.input_labels, outputs=plant.output_labels,
                       params=plant.params, name=plant.name)


def time_mismatch(plant, x0, u0, params, pairs):
    """First vector field or guard that differs between the times of a pair.

    Compares at `x0` and a perturbed state; returns ``(label, mode name,
    t_a, t_b, largest difference)`` or None.

    Examples
    --------
    ``ẋ = -x + cos t`` is 2π-periodic, not 1-periodic:

    >>> from ltpcontrol._orbits.orbits import as_hybrid, time_mismatch
    >>> sys = ct.nlsys(lambda t, x, u, p: -x + np.cos(t), None, states=1, inputs=0, name='P')
    >>> plant, x0, u0 = as_hybrid(sys, None), np.zeros(1), np.zeros(0)
    >>> time_mismatch(plant, x0, u0, {}, [(0.3, 0.3 + 2 * np.pi)]) is None
    True
    >>> label, mode, ta, tb, diff = time_mismatch(plant, x0, u0, {}, [(0.3, 1.3)])
    >>> label, mode, bool(np.isclose(diff, np.cos(0.3) - np.cos(1.3)))
    ('updfcn', 'P', True)
    """
    bumps = np.linspace(-1.0, 1.0, plant.nstates) * 0.1 * (1 + np.abs(x0))
    for i, mode in enumerate(plant.modes):
        checks = [('updfcn', lambda t, x: plant.dynamics(t, x, u0, params, mode=i))]
        if mode.guard is not None:
            checks.append(('guard', lambda t, x: plant.guard(t, x, u0, params, mode=i)))
        for label, func in checks:
            for ta, tb in pairs:
                for x in (x0, x0 + bumps):
                    a, b = np.asarray(func(ta, x)), np.asarray(func(tb, x))
                    if not np.allclose(a, b, rtol=1e-8, atol=1e-10 * (1 + np.abs(a).max())):
                        return label, plant.mode_names[i], ta, tb, np.abs(a - b).max()
    return None


def _check_periodicity(plant, period, x0, u0, params):
    """Raise when a vector field or guard is not T-periodic in t."""
    probes = period * np.array([0.1234567, 0.5, 0.8765432])
    bad = time_mismatch(plant, x0, u0, params, [(t, t + period) for t in probes])
    if bad is not None:
        label, mode, t, _, diff = bad
        raise ValueError(f"plant is not periodic with period={period:g}: {label} of mode "
                         f"{mode!r} differs between t={t:.6g} and t+T (max difference "
                         f"{diff:.3g})")


def _prepare(plant, period, x0, mode0, u0, params, jacobian):
    hp = as_hybrid(plant, jacobian)
    period = check_period(period)
    x0 = real_array(x0, 'x0', ndim=(0, 1)).reshape(-1)
    if x0.size != hp.nstates:
        raise ControlDimension(f"x0 must have {hp.nstates} entries, got {x0.size}")
    mode0 = hp.mode_index(mode0, 'mode0')
    u0 = constant_input(hp, u0, 'u0')
    return hp, period, x0, mode0, u0, plant_params(hp, params)


def period_map(plant, period, x0, mode0=0, *, u0=None, params=None, jacobian=False,
               rtol=1e-10, atol=1e-12, method='DOP853', max_events=10000):
    """Stroboscopic period map ``x(0) -> x(T)`` of a forced (hybrid) plant.

    Parameters
    ----------
    plant : control.NonlinearIOSystem or HybridPlant
        Continuous-time plant.
    period : float
        Period T.
    x0 : array_like
        State at t = 0.
    mode0 : int or str, optional
        Mode at t = 0 (hybrid plants).
    u0 : array_like, optional
        Constant input (zero by default).
    params : dict, optional
        Parameters overriding the plant's defaults.
    jacobian : bool, optional
        Also return the Jacobian of the map from the variational equations
        and saltation matrices.
    rtol, atol, method, max_events : optional
        Integration settings, as in `simulate_hybrid`.

    Returns
    -------
    x_T : ndarray
        State at t = T.
    mode_T : int
        Mode at t = T.
    jac : ndarray, shape (n, n)
        Jacobian ``∂x(T)/∂x(0)`` (only with ``jacobian=True``).

    Examples
    --------
    For ``dx/dt = -x + cos t`` the period map over 2π is affine with slope
    ``e^{-2π}``:

    >>> sys = ct.nlsys(lambda t, x, u, p: -x + np.cos(t), None, states=1, inputs=0)
    >>> xT, mode, J = ltp.period_map(sys, 2 * np.pi, [0.0], jacobian=True)
    >>> bool(np.isclose(J[0, 0], np.exp(-2 * np.pi)))
    True
    """
    opts = solver_settings('period_map', rtol, atol, method, max_events)
    if not isinstance(jacobian, (bool, np.bool_)):
        raise ControlArgument(f"jacobian must be True or False, got {jacobian!r}")
    hp, period, x0, mode0, u0, params = _prepare(plant, period, x0, mode0, u0, params, None)
    flow = Flow(hp, 0.0, period, x0, mode0, lambda t: u0, params,
                 variational=bool(jacobian), **opts)
    if jacobian:
        return flow.x_final, flow.mode_final, flow.phi
    return flow.x_final, flow.mode_final


def periodic_orbit(plant, period, x0, mode0=0, *, u0=None, params=None, jacobian=None,
                   warmup=0, tol=1e-10, max_iter=20, max_periods=200, npoints=200,
                   rtol=None, atol=None, method='DOP853', max_events=10000):
    """T-periodic steady state (limit cycle) of a periodically forced plant.

    Solves ``P(x) = x`` for the period map ``P`` by Newton's method
    (shooting) with the exact Jacobian: variational equations
    ``dΦ/dt = ∂f/∂x Φ`` within each mode and saltation matrices at events.
    When Newton fails (divergence, a change of the mode sequence, no
    progress) the plant is simulated forward in blocks of 10 periods
    and Newton is retried from the new state, up to `max_periods` periods.
    Newton converges to the orbit nearest the guess, stable or not; to land
    on the attracting orbit reached from a given initial condition, first
    simulate `warmup` periods.  Forward simulation only supplies starting
    guesses and uses tolerances of at most 1e-8 (relative) and 1e-10
    (absolute); the final orbit is computed with the given ones.

    Parameters
    ----------
    plant : control.NonlinearIOSystem or HybridPlant
        Continuous-time plant whose vector fields (and guards) are
        T-periodic in t; checked at sample points.
    period : float
        Forcing period T.
    x0 : array_like
        Initial guess of the orbit state at t = 0.
    mode0 : int or str, optional
        Mode of `x0` (hybrid plants).
    u0 : array_like, optional
        Constant input held along the orbit (zero by default).
    params : dict, optional
        Parameters overriding the plant's defaults.
    jacobian : callable, optional
        ``jacobian(t, x, u, params) -> ∂f/∂x`` for a `NonlinearIOSystem`
        plant (central differences otherwise).  Hybrid plants carry it in
        each `HybridMode`.
    warmup : int, optional
        Periods simulated forward before shooting starts (default 0).
    tol : float, optional
        Convergence threshold on ``‖P(x) − x‖∞ / (1 + ‖x‖∞)`` (1e-10).
    max_iter : int, optional
        Newton iterations per attempt (20).
    max_periods : int, optional
        Budget of forward-simulated periods after a failed Newton attempt
        (200).
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

    Raises
    ------
    ValueError
        If the plant is not T-periodic.
    RuntimeError
        If neither Newton nor forward simulation converges; the message
        lists what was tried.

    Warns
    -----
    UserWarning
        If a hybrid plant with guards never leaves its mode on the orbit.

    Examples
    --------
    Forced linear oscillator ``ẍ + ẋ + x = cos t`` with the steady state
    ``x̄ = sin t``:

    >>> def f(t, x, u, p):
    ...     return [x[1], -x[0] - x[1] + np.cos(t)]
    >>> sys = ct.nlsys(f, None, states=2, inputs=0)
    >>> orbit = ltp.periodic_orbit(sys, 2 * np.pi, [0.0, 0.0])
    >>> bool(np.allclose(orbit.x0, [0.0, 1.0], atol=1e-9)), orbit.is_stable
    (True, True)
    """
    opts = newton_solver_settings('periodic_orbit', tol, rtol, atol, method, max_events)
    hp, period, x0, mode0, u0, params = _prepare(plant, period, x0, mode0, u0, params, jacobian)
    tol, max_iter, max_periods, warmup, npoints = _shooting_options(
        tol, max_iter, max_periods, warmup, npoints)
    _check_periodicity(hp, period, x0, u0, params)
    shooter = _PeriodShooter(hp, period, u0, params, opts)
    tried = []
    x, mode, periods = x0.copy(), mode0, warmup
    if warmup:
        x, mode, res = shooter.simulate(x, mode, warmup)
        tried.append(f"warm-up simulation to t={warmup}T: residual {res:.3g}")
    sim_x, sim_mode = x, mode
    while True:
        found = shooter.newton(x, mode, tol, max_iter, f"Newton from t={periods}T", tried)
        if found is not None:
            fl, x, res, iterations = found
            # the multipliers from the product form of the period map
            if not fl.factored:
                fl = shooter.flow(x, mode, True, factored=True)
            return _finish(hp, period, fl, x, mode, npoints, params, u0, res, iterations,
                           periods)
        if periods >= warmup + max_periods:
            break
        # fall back to forward simulation towards an attracting orbit
        nper = min(10, warmup + max_periods - periods)
        try:
            sim_x, sim_mode, res = shooter.simulate(sim_x, sim_mode, nper)
        except IntegrationError as err:
            tried.append(f"forward simulation from t={periods}T: {err}")
            break
        x, mode, periods = sim_x, sim_mode, periods + nper
        tried.append(f"forward simulation to t={periods}T: residual {res:.3g}")
    raise RuntimeError("periodic_orbit did not converge to a T-periodic orbit "
                       f"(tol={tol:g}); tried: " + "; ".join(tried) +
                       ". The response may be unbounded, quasi-periodic, chaotic or periodic "
                       "with a multiple of the period; try another x0, a warm-up or a larger "
                       "max_periods.")


def _shooting_options(tol, max_iter, max_periods, warmup, npoints):
    """Validated Newton tolerance and iteration, period and grid counts."""
    if isinstance(tol, bool) or not isinstance(tol, numbers.Real) or not 0 < tol < 1:
        raise ValueError(f"tol must be a number in (0, 1), got {tol!r}")
    return (tol, check_positive_int(max_iter, 'max_iter'),
            check_positive_int(max_periods, 'max_periods', minimum=0),
            check_positive_int(warmup, 'warmup', minimum=0),
            check_positive_int(npoints, 'npoints', minimum=2))


def _relres(x, xT):
    """Relative residual ``‖x(T) − x‖∞ / (1 + ‖x‖∞)``."""
    return np.max(np.abs(xT - x)) / (1 + np.max(np.abs(x)))


class _PeriodShooter:
    """Period map of a forced plant, its Newton iteration and forward simulation."""

    def __init__(self, hp, period, u0, params, opts):
        self.hp, self.period, self.u0, self.params, self.opts = hp, period, u0, params, opts
        # forward simulation only supplies starting guesses: moderate tolerances
        self.loose = dict(opts, rtol=max(opts['rtol'], 1e-8), atol=max(opts['atol'], 1e-10))

    def flow(self, x, mode, variational, options=None, factored=False):
        u0 = self.u0
        return Flow(self.hp, 0.0, self.period, x, mode, lambda t: u0, self.params,
                     variational=variational, factored=factored, **(options or self.opts))

    def simulate(self, x, mode, nper):
        """State, mode and last-period residual after `nper` simulated periods."""
        res = np.inf
        for _ in range(nper):
            fl = self.flow(x, mode, False, self.loose)
            res = _relres(x, fl.x_final) if fl.mode_final == mode else np.inf
            x, mode = fl.x_final, fl.mode_final
        return x, mode, res

    def newton(self, x, mode, tol, max_iter, where, tried):
        """Newton on ``P(x) − x = 0``: (flow, x, residual, iterations) or None."""
        names, n = self.hp.mode_names, self.hp.nstates
        # `best`: the point whose residual is `last`
        last, stalled, tight, best = np.inf, 0, False, x
        for it in range(max_iter + 1):
            # inexact Newton: loose integration while the residual is large,
            # the requested accuracy once it is small or a loose step misled;
            # the iterations need Φ only to first order: no product form
            # (the caller takes the multipliers from one flow at the solution)
            options = self.opts if tight else inexact_options(self.opts, last)
            exact = options['rtol'] == self.opts['rtol']
            try:
                fl = self.flow(x, mode, True, options)
            except IntegrationError as err:
                tried.append(f"{where}: {err}")
                return None
            if fl.mode_final != mode:
                tried.append(f"{where}: the period ends in mode {names[fl.mode_final]!r}, "
                             f"not {names[mode]!r}")
                return None
            res = _relres(x, fl.x_final)
            if res <= tol and exact:
                return fl, x, res, it
            if not exact and res > 0.9 * last:
                # no progress with loose integration: on at full accuracy from
                # the best point so far
                tight, x, last, stalled = True, best, np.inf, 0
                continue
            stalled = stalled + 1 if res > 0.9 * last else 0
            if res > 1e3 * last or stalled >= 3 or it == max_iter:
                tried.append(f"{where}: residual {res:.3g} after {it} iterations"
                             + (" (no progress)" if stalled >= 3 else "")
                             + _floor_hint(res, self.opts['rtol']))
                return None
            last, best = res, x
            # (∂P/∂x − I) δ = −(P(x) − x); least squares handles neutral
            # directions (multipliers equal to 1)
            step, _, rank, _ = np.linalg.lstsq(fl.phi - np.eye(n), x - fl.x_final, rcond=None)
            if rank == 0:
                tried.append(f"{where}: the period map is the identity to first order "
                             "(all multipliers 1)")
                return None
            if np.max(np.abs(step)) > 10 * (1 + np.max(np.abs(x))):
                if not exact:
                    # a loose Jacobian misled: again from here at full accuracy
                    tight, last, stalled = True, np.inf, 0
                    continue
                tried.append(f"{where}: step of size {np.max(np.abs(step)):.3g} rejected "
                             "(divergence)")
                return None
            x = x + step
        return None  # pragma: no cover - the loop always returns


def _floor_hint(res, rtol):
    """Hint when a stalled residual is at the integration error's level."""
    if res <= 1e4 * rtol:
        return (f" (at the level of the integration tolerance rtol={rtol:g}: lower rtol or "
                "raise tol)")
    return ""


def _finish(hp, period, fl, x, mode, npoints, params, u0, res, iterations, periods):
    has_guards = any(m.guard is not None for m in hp.modes)
    if has_guards and not fl.events:
        warnings.warn(f"no guard is crossed on the periodic orbit: it stays in mode "
                      f"{hp.mode_names[mode]!r} for the whole period", UserWarning, stacklevel=3)
    return PeriodicOrbit(hp, period, fl, x, mode, npoints, params, u0, res, iterations, periods)


def _along_orbit(orbit, func):
    """Callable ``t -> func(mode, t, x̄(t))`` accepting scalar or 1D array t."""
    def along(t):
        tarr = np.atleast_1d(np.asarray(t, float))
        states, modes = orbit._flow.evaluate(np.mod(tarr, orbit.period))
        values = np.array([func(modes[k], tk, states[:, k]) for k, tk in enumerate(tarr)])
        return values if np.ndim(t) else values[0]
    return along


def _segment_average(func, a, b):
    """Mean of ``func`` over ``[a, b]`` by 20-point Gauss-Legendre quadrature."""
    nodes, weights = np.polynomial.legendre.leggauss(20)
    t = 0.5 * (a + b) + 0.5 * (b - a) * nodes
    return np.einsum('k,kij->ij', weights, func(t)) / 2


def check_orbit_of(orbit, plant, why_inputs):
    """`orbit` is a `PeriodicOrbit` of `plant` (a `HybridPlant` with inputs).

    Examples
    --------
    >>> from ltpcontrol._orbits.orbits import as_hybrid, check_orbit_of
    >>> sys = ct.nlsys(lambda t, x, u, p: -x + np.cos(t), None, states=1, inputs=0)
    >>> orbit = ltp.periodic_orbit(sys, 2 * np.pi, [0.0], npoints=8)
    >>> check_orbit_of(orbit, as_hybrid(sys, None), 'there is nothing to linearise in u')
    Traceback (most recent call last):
    ...
    ValueError: plant has no inputs: there is nothing to linearise in u
    """
    if not isinstance(orbit, PeriodicOrbit):
        raise ControlArgument(f"orbit must be a PeriodicOrbit, got {type(orbit).__name__}")
    if orbit.plant.nstates != plant.nstates or orbit.plant.mode_names != plant.mode_names:
        raise ValueError("orbit was computed for a plant with different states or modes")
    if plant.ninputs == 0:
        raise ValueError(f"plant has no inputs: {why_inputs}")


def linearize_orbit(plant, orbit, *, piecewise_constant=False, jacobian=None, name=None):
    """LTP model of a plant linearised about its periodic orbit.

    ``A(t) = ∂f/∂x``, ``B(t) = ∂f/∂u``, ``C(t) = ∂h/∂x``, ``D(t) = ∂h/∂u``
    evaluated on the orbit (thesis eqs. 3.2-3.4), analytic where the plant
    provides Jacobians and by central differences otherwise.  They are
    sampled once along the orbit and evaluated from piecewise Chebyshev
    interpolants verified to ``1e-9 (1 + max |M|)`` on every subinterval
    (fast to evaluate in transition matrices, Riccati equations and closed
    loops); where an interpolant cannot be verified, the exact values are
    used.  For a hybrid
    orbit the mode switches are frozen at the orbit's switching times, giving
    the switching LTP model of eqs. (3.6)-(3.7); with
    ``piecewise_constant=True`` each mode's matrices are replaced by their
    average over its interval (the piecewise LTI model 3.8-3.9).

    The time-switching model ignores the state dependence of the switching
    instants and the reset maps; its monodromy matrix therefore differs from
    the exact return-map Jacobian `PeriodicOrbit.monodromy` when events
    have jumps or discontinuous vector fields.  A warning then names both
    sets of multipliers (relative difference above 1e-4): e.g. an impacting
    hopper's frozen-event model can be unstable while its orbit is stable.

    Parameters
    ----------
    plant : control.NonlinearIOSystem or HybridPlant
        The plant the orbit was computed for.
    orbit : PeriodicOrbit
        Result of `periodic_orbit`.
    piecewise_constant : bool, optional
        Average the matrices over each mode interval (3.8-3.9).
    jacobian : callable, optional
        ``∂f/∂x`` of a `NonlinearIOSystem` plant, as in `periodic_orbit`.
    name : str, optional
        Name of the LTP system (default: the plant's name + ``'$lin'``).

    Returns
    -------
    LTPStateSpace
        Continuous-time LTP model with the orbit's period, in deviation
        coordinates ``x − x̄(t)``, ``u − u0``, ``y − ȳ(t)``.

    Examples
    --------
    >>> def f(t, x, u, p):
    ...     return [x[1], -(1 + 0.1 * np.cos(t)) * x[0] - x[1] + np.cos(t) + u[0]]
    >>> sys = ct.nlsys(f, None, states=2, inputs=1)
    >>> orbit = ltp.periodic_orbit(sys, 2 * np.pi, [0.0, 0.0])
    >>> lin = ltp.linearize_orbit(sys, orbit)
    >>> bool(np.allclose(np.sort(np.abs(lin.floquet_multipliers())),
    ...                  np.sort(np.abs(orbit.multipliers)), rtol=1e-6))
    True
    """
    hp = as_hybrid(plant, jacobian)
    check_orbit_of(orbit, hp, "an LTP model needs at least one input")
    if not isinstance(piecewise_constant, (bool, np.bool_)):
        raise ControlArgument(f"piecewise_constant must be True or False, "
                              f"got {piecewise_constant!r}")
    if name is not None and not isinstance(name, str):
        raise ControlArgument(f"name must be a string, got {name!r}")
    params, u0, T = orbit.params, orbit.u0, orbit.period

    def h_of(t, x, u):
        return hp.output(t, x, u, params)

    derivatives = {
        'A': lambda i, t, x: hp.state_jacobian(t, x, u0, params, mode=i),
        'B': lambda i, t, x: hp.input_jacobian(t, x, u0, params, mode=i),
        'C': lambda i, t, x: central_jacobian(lambda z: h_of(t, z, u0), x),
        'D': lambda i, t, x: central_jacobian(lambda v: h_of(t, x, v), u0),
    }
    times = np.concatenate([[0.0], orbit.switching_times])
    ends = np.append(times[1:], T)
    shapes = {'A': (hp.nstates, hp.nstates), 'B': (hp.nstates, hp.ninputs),
              'C': (hp.noutputs, hp.nstates), 'D': (hp.noutputs, hp.ninputs)}
    mats = {}
    for key, deriv in derivatives.items():
        func = _along_orbit(orbit, deriv)
        if key in 'CD' and hp.outfcn is None:
            # y = x: C = I, D = 0
            value = np.eye(hp.nstates) if key == 'C' else np.zeros((hp.nstates, hp.ninputs))
            mats[key] = PeriodicMatrix.constant(value, T)
        elif piecewise_constant:
            mats[key] = PeriodicMatrix.switching(
                [_segment_average(func, a, b) for a, b in zip(times, ends)], times, T)
        else:
            # sampled once along the orbit, evaluated from verified interpolants
            tabs = [tabulate(func, a, b, shapes[key]) for a, b in zip(times, ends)]
            if len(times) == 1:
                tab = tabs[0]
                mats[key] = PeriodicMatrix.from_function(
                    lambda t, tab=tab: tab(np.mod(t, T)), T, shapes[key], check=False)
            else:
                mats[key] = PeriodicMatrix.switching(tabs, times, T)
    lin = ltpss(mats['A'], mats['B'], mats['C'], mats['D'], T,
                name=name if name is not None else f'{hp.name}$lin',
                inputs=hp.input_labels, outputs=hp.output_labels, states=hp.state_labels)
    if len(orbit.switching_times):
        _check_frozen_events(lin, orbit)
    return lin


#: relative difference of the multipliers (sorted by modulus) above which the frozen-event
#: model of a hybrid orbit is reported
_FROZEN_RTOL = 1e-4


def _check_frozen_events(lin, orbit):
    """Warn when the multipliers of the frozen-event model `lin` differ from the
    orbit's (its events have resets or state-dependent switching)."""
    try:
        model = np.asarray(lin.floquet_multipliers())
    except (ValueError, np.linalg.LinAlgError):
        return
    exact = np.asarray(orbit.multipliers)
    a = model[np.argsort(-np.abs(model))]
    b = exact[np.argsort(-np.abs(exact))]
    if a.size != b.size:
        return
    if np.max(np.abs(a - b) / np.maximum(1.0, np.abs(b))) > _FROZEN_RTOL:
        fmt = ', '.join
        warnings.warn(
            f"the linearised model freezes the orbit's {len(orbit.switching_times)} events "
            f"at their times: its multipliers [{fmt(f'{m:.3g}' for m in a)}] differ from "
            f"the orbit's [{fmt(f'{m:.3g}' for m in b)}] (the saltation of the resets and "
            "of the state-dependent switching is not in a time-switching model); its "
            "stability and designs on it do not carry over to the plant: use the orbit's "
            "monodromy (PeriodicOrbit.monodromy) or a model with the saltations",
            UserWarning, stacklevel=3)

