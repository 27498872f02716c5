"""Clock-free vertical hopper: a hopping robot whose controller reacts to events.

A body of mass ``M`` on a spring-damper leg (stiffness ``k``, damping ``d``,
rest length ``l0``) with a toe of mass ``m``.  No clock drives it; the
controller lengthens the leg's rest length by ``delta`` when the body
reaches the bottom of stance, which injects the energy that the damper and
the liftoff collision remove.  State ``x = [z, v]`` (body height and
velocity), three modes:

``'flight'``
    ``ż = v, v̇ = −g``; touchdown when ``z`` falls to ``l0``;
``'compression'``
    ``M v̇ = −M g + k (l0 − z) − d v``; bottom when ``v`` rises through 0;
``'thrust'``
    ``M v̇ = −M g + k (l0 + delta − z) − d v``; liftoff when the leg force
    ``k (l0 + delta − z) − d v`` falls to 0, followed by the plastic
    collision with the toe, ``v⁺ = M v⁻ / (M + m)``.

The vector field jumps at touchdown (the damper force ``d v``) and at the
bottom (the thrust ``k delta``), and liftoff has a reset, so every saltation
matrix differs from the identity.  The gait is an isolated limit cycle whose
period is an unknown; its apex-to-apex return map is one-dimensional.
"""

import numpy as np
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

#: Default parameters (SI units).
CLOCKFREE_PARAMS = {'M': 2.7, 'm': 0.3, 'k': 2500.0, 'd': 15.0, 'l0': 0.2, 'delta': 0.03,
                    'g': 9.81}


def _legged(rest):
    def updfcn(t, x, u, p):
        # M v̇ = −M g + k (rest − z) − d v
        return [x[1], -p['g'] + (p['k'] * (rest(p) - x[0]) - p['d'] * x[1]) / p['M']]

    def jacobian(t, x, u, p):
        return np.array([[0.0, 1.0], [-p['k'] / p['M'], -p['d'] / p['M']]])
    return updfcn, jacobian


def _leg_force(t, x, u, p):
    return p['k'] * (p['l0'] + p['delta'] - x[0]) - p['d'] * x[1]


def _liftoff(t, x, u, p):
    return [x[0], x[1] * p['M'] / (p['M'] + p['m'])]


def clockfree_hopper(**params):
    """Hybrid plant with modes ``'flight'``, ``'compression'``, ``'thrust'``.

    Parameters
    ----------
    **params : float
        Overrides of `CLOCKFREE_PARAMS`.

    Returns
    -------
    ltpcontrol.HybridPlant
        States ``['z', 'v']``, no inputs, the states as outputs.
    """
    unknown = set(params) - set(CLOCKFREE_PARAMS)
    if unknown:
        raise TypeError(f"clockfree_hopper: unrecognized keyword(s): {sorted(unknown)}")
    compress, compress_jac = _legged(lambda p: p['l0'])
    thrust, thrust_jac = _legged(lambda p: p['l0'] + p['delta'])
    modes = [
        ltp.HybridMode(lambda t, x, u, p: [x[1], -p['g']],
                       guard=lambda t, x, u, p: x[0] - p['l0'], target='compression',
                       name='flight', jacobian=lambda t, x, u, p: np.array([[0, 1], [0, 0.0]])),
        ltp.HybridMode(compress, guard=lambda t, x, u, p: -x[1], target='thrust',
                       name='compression', jacobian=compress_jac),
        ltp.HybridMode(thrust, guard=_leg_force, reset=_liftoff, target='flight',
                       name='thrust', jacobian=thrust_jac),
    ]
    return ltp.HybridPlant(modes, states=['z', 'v'], params={**CLOCKFREE_PARAMS, **params},
                           name='clockfree_hopper')


def apex_section(x):
    """Apex section ``v = 0`` (crossed downwards in flight)."""
    return x[1]


def hopping_gait(plant=None, height=0.3, **kwargs):
    """The hopping limit cycle, started from rest at apex `height`.

    Keywords go to `ltpcontrol.limit_cycle`; the section is the apex.
    """
    plant = clockfree_hopper() if plant is None else plant
    return ltp.limit_cycle(plant, None, [height, 0.0], 'flight', section=apex_section,
                           direction=-1, **kwargs)


def apex_map(height, params=None, rtol=1e-12, atol=1e-14):
    """Apex-to-apex map by plain event-located `solve_ivp` integration.

    Independent of the library: each phase is integrated with its own
    terminal event.  Returns the next apex height and the hop time.
    """
    p = {**CLOCKFREE_PARAMS, **(params or {})}
    M, k, d, l0, g = p['M'], p['k'], p['d'], p['l0'], p['g']

    def run(rhs, x0, event, direction):
        event.terminal, event.direction = True, direction
        sol = solve_ivp(rhs, (0.0, 10.0), x0, method='DOP853', rtol=rtol, atol=atol,
                        events=event)
        return sol.t_events[0][0], sol.y_events[0][0]

    def leg(rest):
        return lambda t, x: [x[1], -g + (k * (rest - x[0]) - d * x[1]) / M]

    t1, x = run(lambda t, x: [x[1], -g], [height, 0.0], lambda t, x: x[0] - l0, -1)
    t2, x = run(leg(l0), x, lambda t, x: x[1], 1)
    t3, x = run(leg(l0 + p['delta']), x,
                lambda t, x: k * (l0 + p['delta'] - x[0]) - d * x[1], -1)
    x = [x[0], x[1] * M / (M + p['m'])]
    t4, x = run(lambda t, x: [x[1], -g], x, lambda t, x: x[1], -1)
    return x[0], t1 + t2 + t3 + t4


if __name__ == '__main__':
    gait = hopping_gait()
    print(gait)
    print('apex height', gait.x0[0], 'period', gait.period)
    print('mode sequence', [gait.plant.mode_names[i] for i in gait.mode_sequence])
    print('stability multipliers', gait.stability_multipliers)
