"""The feedback loop of a hybrid plant and a controller about a periodic orbit.

`FeedbackLoop` validates the plant, controller, orbit and saturation and
evaluates the loop's signals (see `ltpcontrol._orbits.closed_loop` for the
equations and the phase lock)::

    e(t) = y(t) + v(t) − ȳ(t),      u(t) = sat(u0 + w(t))

A continuous controller makes the loop a `HybridPlant` with states
``[x, x_c]`` (`FeedbackLoop.hybrid_plant`).  A discrete controller gives a
`SampledLoop`: samples at ``t = k dt`` and flows of the plant with its held
input appended to the state (``u̇ = 0``) between them; its period map is the
composition of both, with the Jacobian composed alike.
"""

import bisect

import numpy as np
import control as ct
from control.exception import ControlArgument, ControlDimension

from .hybrid import Flow
from .hybrid_plant import HybridMode, HybridPlant, central_jacobian
from .._core.ltpsys import LTPStateSpace
from .orbits import as_hybrid, check_orbit_of
from .tabulate import tabulate
from .._core.validation import steps_per_period

__all__ = []


class FeedbackLoop:
    """Validated plant, controller, orbit and saturation of one feedback loop."""

    def __init__(self, plant, controller, orbit, saturation):
        plant = as_hybrid(plant, None)
        check_orbit_of(orbit, plant, "a controller cannot act on it")
        self.plant, self.orbit, self.T = plant, orbit, orbit.period
        self.params, self.u0 = orbit.params, orbit.u0
        self.n, self.m, self.p = plant.nstates, plant.ninputs, plant.noutputs
        self.ctrl = _controller(controller, self.T)
        if self.ctrl.ninputs != self.p or self.ctrl.noutputs != self.m:
            raise ControlDimension(
                f"controller must map the plant's {self.p} output(s) to its {self.m} "
                f"input(s), got {self.ctrl.ninputs} input(s) and {self.ctrl.noutputs} output(s)")
        self.nc, self.dt = self.ctrl.nstates, float(self.ctrl.dt)
        self.nsamples = steps_per_period(self.T, self.dt, 'controller.dt') if self.dt else None
        self.lower, self.upper = _saturation(saturation, self.m)
        self.linear = isinstance(self.ctrl, LTPStateSpace)
        if self.linear:
            mats = (self.ctrl.A, self.ctrl.B, self.ctrl.C, self.ctrl.D)
            self._fixed = [M(0.0) if M.is_constant else None for M in mats]
            self._varying = _FastMatrices(mats) if not self.ctrl.dt \
                and any(F is None for F in self._fixed) else None
            self._last = (None, None)
        self._ybar = _output_interpolant(plant, orbit)
        self._check_algebraic_loop()

    def _check_algebraic_loop(self):
        # y is evaluated at u0: exact unless both h and the controller pass u through
        t, x = 0.0, self.orbit.x0
        dh_du = central_jacobian(lambda u: self.plant.output(t, x, u, self.params), self.u0)
        dk_de = central_jacobian(lambda e: self.ctrl_out(t, np.zeros(self.nc), e),
                                  np.zeros(self.p))
        if np.any(dh_du != 0) and np.any(dk_de != 0):
            raise ValueError("algebraic loop: the plant output depends on its input and the "
                             "controller has direct feedthrough; make one of them strictly "
                             "proper")

    def matrices(self, t):
        """Controller matrices ``A_c, B_c, C_c, D_c`` at time t (linear controllers).

        The last evaluation is kept: the loop's field, output and Jacobian
        ask for the same t in turn, and designed gains (Riccati solutions)
        are costly to evaluate.
        """
        if t != self._last[0]:
            if self._varying is not None:
                self._last = (t, self._varying(t))
            else:
                mats = (self.ctrl.A, self.ctrl.B, self.ctrl.C, self.ctrl.D)
                self._last = (t, [F if F is not None else M._eval(np.array([t]))[0]
                                  for F, M in zip(self._fixed, mats)])
        return self._last[1]

    def ctrl_rhs(self, t, xc, e):
        if not self.linear:
            return self.ctrl._rhs(t, xc, e)
        A, B, _, _ = self.matrices(t)
        return A @ xc + B @ e

    def ctrl_out(self, t, xc, e):
        if not self.linear:
            return self.ctrl._out(t, xc, e)
        _, _, C, D = self.matrices(t)
        return C @ xc + D @ e

    def ybar(self, t):
        return self._ybar(t)

    def error(self, t, x, v):
        return self.plant.output(t, x, self.u0, self.params) + v - self.ybar(t)

    def actuate(self, w):
        return np.clip(self.u0 + w, self.lower, self.upper)

    def hybrid_plant(self):
        """`HybridPlant` of the continuous loop: input v (noise), outputs [y, u]."""
        loop = self
        plant, ctrl, n, params = loop.plant, loop.ctrl, loop.n, loop.params

        def signals(t, z, v):
            e = loop.error(t, z[:n], v)
            return e, loop.actuate(loop.ctrl_out(t, z[n:], e))

        def mode(i):
            src = plant.modes[i]

            def updfcn(t, z, v, p):
                e, u = signals(t, z, v)
                return np.concatenate([plant.dynamics(t, z[:n], u, params, mode=i),
                                       loop.ctrl_rhs(t, z[n:], e)])

            def jacobian(t, z, v, p):
                # chain rule through e = h(x) + v − ȳ and u = sat(u0 + C_c x_c + D_c e)
                e, u = signals(t, z, v)
                Ac, Bc, Cc, Dc = loop.matrices(t)
                H = central_jacobian(lambda x: plant.output(t, x, loop.u0, params), z[:n])
                active = ((u > loop.lower) & (u < loop.upper))[:, None]
                du_dz = active * np.hstack([Dc @ H, Cc])
                top = np.hstack([plant.state_jacobian(t, z[:n], u, params, mode=i),
                                 np.zeros((n, loop.nc))])
                top += plant.input_jacobian(t, z[:n], u, params, mode=i) @ du_dz
                return np.vstack([top, np.hstack([Bc @ H, Ac])])

            guard = reset = None
            if src.guard is not None:
                def guard(t, z, v, p):
                    return plant.guard(t, z[:n], signals(t, z, v)[1], params, mode=i)

                def reset(t, z, v, p):
                    u = signals(t, z, v)[1]
                    return np.concatenate([plant.reset(t, z[:n], u, params, mode=i), z[n:]])
            return HybridMode(updfcn, guard=guard, reset=reset, name=plant.mode_names[i],
                              target=plant.mode_targets[i],
                              jacobian=jacobian if loop.linear else None)

        def output(t, z, v, p):
            u = signals(t, z, v)[1]
            return np.concatenate([plant.output(t, z[:n], u, params), u])

        return HybridPlant([mode(i) for i in range(len(plant.modes))], output,
                           states=plant.state_labels + ctrl.state_labels,
                           inputs=[f'v[{k}]' for k in range(loop.p)],
                           outputs=plant.output_labels + plant.input_labels,
                           params=params, name=f'{plant.name}+{ctrl.name}')


class _FastMatrices:
    """``[A_c(t), B_c(t), C_c(t), D_c(t)]`` of a continuous LTP controller, tabulated.

    Closed-loop integrations evaluate the controller's matrices at every
    right-hand side evaluation, one time at a time; a designed gain (a
    Riccati solution times B(t)) costs far more than the integration
    itself.  Between consecutive breakpoints of the matrices (switching
    instants, interpolant knots) they are smooth, and `tabulate` samples
    them once (vectorised) into verified Chebyshev interpolants (1e-9
    relative accuracy; exact values where that cannot be verified).  The
    matrices are right-continuous at the breakpoints, as `PeriodicMatrix`.
    """

    def __init__(self, mats):
        self.period = mats[0].period
        self.shapes = [M.shape for M in mats]
        self.sizes = np.cumsum([0] + [int(np.prod(sh)) for sh in self.shapes])
        breaks = np.unique(np.concatenate([[0.0]] + [M.breakpoints for M in mats]))
        breaks = breaks[breaks < self.period * (1 - 1e-12)]
        ends = np.append(breaks[1:], self.period)
        total = (int(self.sizes[-1]),)

        def stacked(t):
            return np.concatenate([M._eval(np.atleast_1d(t)).reshape(len(np.atleast_1d(t)), -1)
                                   for M in mats], axis=1)
        self.starts = list(breaks)
        self.pieces = [tabulate(stacked, a, b, total) for a, b in zip(breaks, ends)]

    def __call__(self, t):
        # right-continuous at the breakpoints, within rounding of t mod T
        tau = t % self.period
        k = max(bisect.bisect_right(self.starts, tau + 1e-12 * self.period) - 1, 0)
        flat = self.pieces[k](np.array([tau])).reshape(-1)
        return [flat[a:b].reshape(shape) for a, b, shape in
                zip(self.sizes[:-1], self.sizes[1:], self.shapes)]


def _output_interpolant(plant, orbit, tol=1e-11):
    """``ȳ(t)`` from Chebyshev interpolants on each mode interval of the orbit.

    The orbit's dense output is continuous only to the solver's tolerance
    at its step boundaries; fed back through a controller such ripples
    force the step-size control of the loop's integration into rejections.
    The orbit is smooth within each mode interval, so a Chebyshev
    interpolant there is smooth and accurate (degree doubled up to 256 until
    it reproduces the orbit to `tol` relative at intermediate points).
    """
    cheb = np.polynomial.chebyshev
    T, u0, params = orbit.period, orbit.u0, orbit.params
    breaks = np.concatenate([[0.0], orbit.switching_times, [T]])

    def ybar_exact(t):
        return np.column_stack([plant.output(tk, x, u0, params)
                                for tk, x in zip(t, orbit(t).T)])

    pieces = []
    for a, b in zip(breaks[:-1], breaks[1:]):
        check = a + (b - a) * (0.5 + 0.49 * np.cos(np.linspace(0.1, 3.0, 17)))
        y_check = ybar_exact(check)
        scale = 1 + np.max(np.abs(y_check))
        for deg in (16, 32, 64, 128, 256):
            nodes = cheb.chebpts1(deg + 1)   # interior points: events excluded
            coef = cheb.chebfit(nodes, ybar_exact(a + (b - a) * (nodes + 1) / 2).T, deg)
            err = np.max(np.abs(cheb.chebval(2 * (check - a) / (b - a) - 1, coef) - y_check))
            if err <= tol * scale:
                break
        pieces.append((a, b - a, coef))

    def ybar(t):
        tau = t % T
        a, w, coef = pieces[min(np.searchsorted(breaks, tau, side='right') - 1, len(pieces) - 1)]
        # Σ c_k T_k(s) with T_k(s) = cos(k arccos s)
        s = np.clip(2 * (tau - a) / w - 1, -1.0, 1.0)
        return np.cos(np.arange(len(coef)) * np.arccos(s)) @ coef
    return ybar


def _controller(controller, period):
    """The controller as a `NonlinearIOSystem` phase-locked to `period`."""
    if isinstance(controller, (ct.StateSpace, ct.TransferFunction)):
        lti = ct.ss(controller) if isinstance(controller, ct.TransferFunction) else controller
        dt = 0.0 if lti.dt in (0, None) else lti.dt
        if dt is True:
            raise ValueError("controller must have a numeric sampling time, got dt=True")
        controller = LTPStateSpace(lti.A, lti.B, lti.C, lti.D, period, dt=dt,
                                   name=lti.name, inputs=lti.input_labels,
                                   outputs=lti.output_labels, states=lti.state_labels)
    if not isinstance(controller, ct.NonlinearIOSystem):
        raise ControlArgument("controller must be an LTPStateSpace, a control.StateSpace/"
                              f"TransferFunction or a NonlinearIOSystem, got "
                              f"{type(controller).__name__}")
    if controller.dt is True or controller.dt is None:
        raise ValueError(f"controller must have a numeric sampling time, got "
                         f"dt={controller.dt}")
    if isinstance(controller, LTPStateSpace):
        ratio = period / controller.period
        if abs(ratio - round(ratio)) > 1e-9 * ratio or round(ratio) < 1:
            raise ValueError(f"controller period {controller.period:g} does not divide the "
                             f"orbit period {period:g}: the loop would not be phase-locked")
    return controller


def _saturation(saturation, m):
    if saturation is None:
        return np.full(m, -np.inf), np.full(m, np.inf)
    try:
        lower, upper = saturation
    except (TypeError, ValueError):
        raise ControlArgument(f"saturation must be a pair (lower, upper), got "
                              f"{saturation!r}") from None
    bounds = []
    for value, label in ((lower, 'lower'), (upper, 'upper')):
        arr = np.asarray(value, float).reshape(-1)
        if arr.size == 1:
            arr = np.full(m, arr[0])
        if arr.size != m:
            raise ControlDimension(f"saturation {label} bound must have {m} entries")
        if np.any(np.isnan(arr)):
            raise ValueError(f"saturation {label} bound contains NaN")
        bounds.append(arr)
    if np.any(bounds[0] >= bounds[1]):
        raise ValueError(f"saturation needs lower < upper, got {saturation!r}")
    return bounds


def _held_plant(loop):
    """The plant with its held input appended to the state (``u̇ = 0``)."""
    plant, n, params = loop.plant, loop.n, loop.params

    def mode(i):
        src = plant.modes[i]
        guard = reset = None
        if src.guard is not None:
            def guard(t, z, _, p):
                return plant.guard(t, z[:n], z[n:], params, mode=i)

            def reset(t, z, _, p):
                return np.concatenate([plant.reset(t, z[:n], z[n:], params, mode=i), z[n:]])

        def jacobian(t, z, _, p):
            J = np.zeros((n + loop.m, n + loop.m))
            J[:n, :n] = plant.state_jacobian(t, z[:n], z[n:], params, mode=i)
            J[:n, n:] = plant.input_jacobian(t, z[:n], z[n:], params, mode=i)
            return J

        def updfcn(t, z, _, p):
            return np.concatenate([plant.dynamics(t, z[:n], z[n:], params, mode=i),
                                   np.zeros(loop.m)])
        return HybridMode(updfcn,
                          guard=guard, reset=reset, target=plant.mode_targets[i],
                          name=plant.mode_names[i], jacobian=jacobian)

    return HybridPlant([mode(i) for i in range(len(plant.modes))],
                       states=plant.state_labels + plant.input_labels, params=params)


class SampledLoop:
    """Sampled-data loop: state ``[x, x_c]`` just before a sample."""

    def __init__(self, loop, opts):
        self.loop, self.opts, self.held = loop, opts, _held_plant(loop)

    def sample(self, k, z, v):
        """``[x, x_c⁺, u_k]`` from ``[x, x_c]`` at the sample ``t = k dt``."""
        loop, n = self.loop, self.loop.n
        t = k * loop.dt
        e = loop.error(t, z[:n], v)
        tk = self._ctrl_time(k)
        return np.concatenate([z[:n], loop.ctrl_rhs(tk, z[n:], e),
                               loop.actuate(loop.ctrl_out(tk, z[n:], e))])

    def _ctrl_time(self, k):
        # middle of the step for LTP matrices held on [k dt, (k+1) dt): immune to rounding
        loop = self.loop
        return (k + 0.5) * loop.dt if isinstance(loop.ctrl, LTPStateSpace) else k * loop.dt

    def step(self, k, z, mode, v, variational=False, t_end=None):
        """Sample at ``k dt`` and flow to ``(k+1) dt`` (or `t_end`).

        Returns the state before the next sample, its mode, the flow (or the
        step's Jacobian with `variational`) and the held input.
        """
        loop, n, nc = self.loop, self.loop.n, self.loop.nc
        s = self.sample(k, z, v)
        t1 = (k + 1) * loop.dt if t_end is None else t_end
        flow = Flow(self.held, k * loop.dt, t1, np.concatenate([s[:n], s[n + nc:]]), mode,
                     lambda t: np.zeros(0), loop.params, variational=variational, **self.opts)
        z1 = np.concatenate([flow.x_final[:n], s[n:n + nc]])
        if not variational:
            return z1, flow.mode_final, flow, s[n + nc:]
        # ds/dz by central differences (exact for linear controllers), then the
        # flow Jacobian of the plant with held input [x, u]
        S = central_jacobian(lambda w: self.sample(k, w, v), z)
        xu = flow.phi @ S[np.r_[0:n, n + nc:n + nc + loop.m]]
        return z1, flow.mode_final, np.vstack([xu[:n], S[n:n + nc]]), s[n + nc:]

    def period_map(self, z, mode, jacobian=False):
        J = np.eye(len(z))
        for k in range(self.loop.nsamples):
            z, mode, Jk, _ = self.step(k, z, mode, 0.0, jacobian)
            if jacobian:
                J = Jk @ J
        return z, mode, J
