"""The extended SLIP of `slip_model` as an autonomous hybrid plant.

`slip_model` predicts strides by composing flight, stance and collision
maps (thesis Chapter 2).  Here the same model is written as a clock-free
`ltpcontrol.HybridPlant`, so that the library's orbit machinery — return
maps with saltation matrices, `limit_cycle`, continuation — applies to it.
State ``x = [q, z, vy, vz]``: body height ``z``, velocities, and the body's
horizontal position ``q`` relative to the last toe position (the forward
position itself is cyclic and left out, so running gaits are periodic
orbits).  Two modes:

``'flight'``
    ``q̇ = vy, ż = vz, v̇y = −d_h vy, v̇z = −g − d_v vz`` (2.4); touchdown
    when ``z`` falls to ``rho0 cos(theta_td)``, placing the toe at
    ``q = rho0 sin(theta_td)`` (the leg angle from the vertical, negative
    for forward running);
``'stance'``
    the body on a massless spring-damper leg of length ``rho = |(q, z)|``,
    ``m_b a = F (q, z)/rho − m_b g e_z`` with the leg force
    ``F = k (rho0 − rho) − d rhȯ`` (2.9)-(2.10); liftoff when F falls to 0,
    followed by the collision with the leg mass (2.21),
    ``v⁺ = m_b v⁻ / (m_b + m_l)``.

The apex is the section ``vz = 0`` crossed downwards in flight.
"""

import numpy as np

import ltpcontrol as ltp
try:                    # imported as the package ``examples`` (tests)
    from .slip_model import SLIPParams
except ImportError:     # run from this folder (gallery scripts)
    from slip_model import SLIPParams


def _flight(t, x, u, p):
    return [x[2], x[3], -p['d_h'] * x[2], -p['g'] - p['d_v'] * x[3]]


def _leg(x, p):
    """Leg length, its rate and the leg force ``k (rho0 − rho) − d rhȯ``."""
    rho = np.hypot(x[0], x[1])
    rhod = (x[0] * x[2] + x[1] * x[3]) / rho
    return rho, rhod, p['k'] * (p['rho0'] - rho) - p['d'] * rhod


def _stance(t, x, u, p):
    rho, _, force = _leg(x, p)
    a = force / (p['m_b'] * rho)
    return [x[2], x[3], a * x[0], a * x[1] - p['g']]


def _touchdown(t, x, u, p):
    return [p['rho0'] * np.sin(p['theta_td']), x[1], x[2], x[3]]


def _liftoff(t, x, u, p):
    ratio = p['m_b'] / (p['m_b'] + p['m_l'])
    return [x[0], x[1], ratio * x[2], ratio * x[3]]


def slip_plant(params=None, theta_td=-0.2):
    """Autonomous hybrid SLIP with modes ``'flight'`` and ``'stance'``.

    Parameters
    ----------
    params : SLIPParams, optional
        Model parameters (default `SLIPParams()`).
    theta_td : float, optional
        Touchdown leg angle from the vertical, rad.

    Returns
    -------
    ltpcontrol.HybridPlant
        States ``['q', 'z', 'vy', 'vz']``; the parameters (including
        ``theta_td``) are plant parameters, so they can be continued.
    """
    P = SLIPParams() if params is None else params
    values = {name: float(getattr(P, name))
              for name in ('m_b', 'm_l', 'k', 'd', 'd_h', 'd_v', 'rho0', 'g')}
    modes = [
        ltp.HybridMode(_flight, name='flight', target='stance', reset=_touchdown,
                       guard=lambda t, x, u, p: x[1] - p['rho0'] * np.cos(p['theta_td'])),
        ltp.HybridMode(_stance, name='stance', target='flight', reset=_liftoff,
                       guard=lambda t, x, u, p: _leg(x, p)[2]),
    ]
    return ltp.HybridPlant(modes, states=['q', 'z', 'vy', 'vz'],
                           params={**values, 'theta_td': float(theta_td)}, name='slip')


def apex_section(x):
    """Apex section ``vz = 0`` (crossed downwards in flight)."""
    return x[3]


def apex_state(apex):
    """Plant state at an apex ``[y, ydot, z]`` of `slip_model` (toe behind: q = 0)."""
    return np.array([0.0, apex[2], apex[1], 0.0])


def apex_return_map(plant, apex, jacobian=False, **kwargs):
    """Apex-to-apex map ``[ydot, z] -> [ydot', z']`` through `ltpcontrol.poincare_map`.

    Returns the next apex ``[ydot', z']``, the stride time and, with
    ``jacobian=True``, the 2 x 2 Jacobian of the map.
    """
    out = ltp.poincare_map(plant, apex_state(apex), apex_section, 'flight', direction=-1,
                           max_time=5.0, jacobian=jacobian, **kwargs)
    x_next, t = out[0], out[1]
    if not jacobian:
        return x_next[[2, 1]], t
    # rows and columns of [vy, z]; q does not influence the stride
    return x_next[[2, 1]], t, out[2][np.ix_([2, 1], [2, 1])]


def running_gait(plant, apex, **kwargs):
    """Periodic running gait near the apex ``[y, ydot, z]`` (keywords to `limit_cycle`)."""
    return ltp.limit_cycle(plant, None, apex_state(apex), 'flight', section=apex_section,
                           direction=-1, **kwargs)


if __name__ == '__main__':
    from slip_model import predict_stride
    apex = np.array([0.0, 1.0, 0.3])
    P = SLIPParams()
    nxt, t = apex_return_map(slip_plant(P, -0.2), apex)
    s = predict_stride(apex, -0.2, P, method='SLIPD')
    print('hybrid plant :', nxt, t)
    print('slip_model   :', [s.apex.vy, s.apex.z], s.apex.t)
