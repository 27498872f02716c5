"""Kinks of a closed-loop return map: events at time discontinuities of the loop.

A controller acting on the deviation ``e = y − ȳ(t)`` from a hybrid orbit
makes the loop's vector field discontinuous in t at the orbit's switching
times (``ȳ`` jumps there, and a gain designed on the time-switching model
may switch there too).  On the closed-loop orbit the plant's own event
happens at that same instant ``d``.  A perturbed trajectory meets its event
slightly before or after ``d``; in between, ``e`` spikes (for example
``x⁻ − x̄⁺`` after the nominal impact but before the perturbed one).  The
return map is then only piecewise smooth: its Jacobian on the side where
the event comes first (``t_e < d``) has the saltation matrix of the event
evaluated with the loop's field before ``d``,

    S_early = Dr + (f_j(d⁻, x⁺) − Dr f_i(d⁻, x⁻) − ∂r/∂t) ∇g / (∇g·f_i(d⁻, x⁻) + ∂g/∂t),

and on the other side the same with the field after ``d`` (``d⁺``).  Both
are exact one-sided derivatives; a single "Jacobian" of such a map does not
exist.  ``∂g/∂t`` and ``∂r/∂t`` are one-sided (second-order) differences
that stay on their side of ``d``.
"""

import numpy as np

from .hybrid_plant import central_jacobian

__all__ = []

#: an event this close to a discontinuity of the loop (relative to T) coincides with it
COINCIDENCE = 1e-6
#: one-sided saltations differing by more than this (relative) make a kink
KINK_TOL = 1e-6
#: at most this many kinked events are combined (2**k one-sided Jacobians)
MAX_KINKS = 4


def one_sided_saltations(lp, flow, breaks, period, v0):
    """``[(factor index, S_early, S_late, t_event)]`` for the kinked events of `flow`.

    `lp` is the loop as a `HybridPlant`, `flow` a variational `Flow` of it
    over one period, `breaks` the instants (modulo `period`) where the
    loop's field may jump in t, `v0` the (zero) noise input.

    Examples
    --------
    ``ẋ = -a(t) - x`` with a = 1, then 3 from t = 0.5, meets its guard ``x = 0``
    at t = 0.5 and jumps to ``x + 2``: the saltation ``f⁺/f⁻`` is 3 with the
    field before the jump and 5/3 with the field after it.

    >>> from ltpcontrol._orbits.hybrid import Flow
    >>> from ltpcontrol._orbits.kinks import one_sided_saltations
    >>> a = lambda t: 1.0 if t % 1.0 < 0.5 else 3.0
    >>> mode = ltp.HybridMode(lambda t, x, u, p: [-a(t) - x[0]],
    ...                       guard=lambda t, x, u, p: x[0],
    ...                       reset=lambda t, x, u, p: [x[0] + 2.0], target='m', name='m')
    >>> plant = ltp.HybridPlant([mode], states=1)
    >>> flow = Flow(plant, 0.0, 1.0, [np.exp(0.5) - 1], 0, lambda t: np.zeros(0),
    ...             plant.params, 1e-10, 1e-12, 'DOP853', 10, variational=True)
    >>> [(index, early, late, t_event)] = one_sided_saltations(plant, flow, [0.5], 1.0,
    ...                                                        np.zeros(0))
    >>> index, round(float(early[0, 0]), 6), round(float(late[0, 0]), 6), round(t_event, 6)
    (1, 3.0, 1.666667, 0.5)
    """
    breaks = np.mod(np.asarray(breaks, float), period)
    kinks = []
    for S, (t_e, i, j, x_minus, _) in zip(flow.saltations, flow.events):
        if breaks.size == 0:
            break
        gap = np.abs(np.angle(np.exp(2j * np.pi * (breaks - t_e) / period))) * period / (2 * np.pi)
        k = int(np.argmin(gap))
        if gap[k] > COINCIDENCE * period:
            continue
        d = t_e + np.angle(np.exp(2j * np.pi * (breaks[k] - t_e) / period)) \
            * period / (2 * np.pi)
        eta = 1e-9 * period
        early = _saltation_side(lp, i, j, d - eta, x_minus, v0, -1, period)
        late = _saltation_side(lp, i, j, d + eta, x_minus, v0, +1, period)
        if np.max(np.abs(early - late)) > KINK_TOL * (1 + np.max(np.abs(early))):
            index = next(m for m, F in enumerate(flow.factors) if F is S)
            kinks.append((index, early, late, float(t_e)))
    return kinks


def _saltation_side(lp, i, j, t, x, v0, side, period):
    """Saltation matrix of the event i -> j at (t, x) with one-sided t-derivatives."""
    params = lp.params
    xp = lp.reset(t, x, v0, params, mode=i)
    f_minus = lp.dynamics(t, x, v0, params, mode=i)
    f_plus = lp.dynamics(t, xp, v0, params, mode=j)
    dg_dx = central_jacobian(lambda z: lp.guard(t, z, v0, params, mode=i), x)[0]
    dr_dx = central_jacobian(lambda z: lp.reset(t, z, v0, params, mode=i), x)
    h = side * 1e-6 * period
    # second-order one-sided differences: (-3 F(t) + 4 F(t + h) - F(t + 2h)) / 2h
    g = [lp.guard(t + m * h, x, v0, params, mode=i) for m in range(3)]
    r = [lp.reset(t + m * h, x, v0, params, mode=i) for m in range(3)]
    dg_dt = (-3 * g[0] + 4 * g[1] - g[2]) / (2 * h)
    dr_dt = (-3 * r[0] + 4 * r[1] - r[2]) / (2 * h)
    rate = dg_dx @ f_minus + dg_dt
    if rate == 0:
        raise ValueError("the flow of the closed loop is tangent to a guard at a "
                         f"discontinuity of the loop (t={t:.6g}): no saltation matrix exists")
    return dr_dx + np.outer(f_plus - dr_dx @ f_minus - dr_dt, dg_dx) / rate


def side_factor_lists(factors, kinks):
    """Factor lists of every combination of sides (early/late) of the kinked events.

    Returns ``[(sides, factors)]``, sides a tuple of 'early'/'late' per kink.

    Examples
    --------
    >>> from ltpcontrol._orbits.kinks import side_factor_lists
    >>> factors = [np.eye(1), np.full((1, 1), 2.0), np.eye(1)]
    >>> kink = (1, np.full((1, 1), 3.0), np.full((1, 1), 0.5), 0.5)
    >>> [(sides, float(f[1][0, 0])) for sides, f in side_factor_lists(factors, [kink])]
    [(('early',), 3.0), (('late',), 0.5)]
    """
    kinks = kinks[:MAX_KINKS]
    out = []
    for code in range(2 ** len(kinks)):
        sides, fac = [], list(factors)
        for b, (index, early, late, _) in enumerate(kinks):
            late_side = bool(code >> b & 1)
            fac[index] = late if late_side else early
            sides.append('late' if late_side else 'early')
        out.append((tuple(sides), fac))
    return out
