"""Vertical hopper (VHOP) of thesis §3.7 (eqs. 3.51-3.55, Table 3.2).

State ``x = [h, h_t, ḣ, ḣ_t]`` (body and toe heights and velocities).
Flight (3.52):

``M ḧ = −M g + F``,  ``m ḧ_t = −m g − F``,
``F = −d (ḣ − ḣ_t) + k (ℓ0 − (h − h_t)) + u(t)``;

stance (3.53-3.54): the toe rests on the ground, ``M ḧ = −M g − d ḣ +
k (ℓ0 − h) + u(t)``, ``ḧ_t = 0``.  The actuator force is ``u(t) = a cos(ω_p
t) + u_c(t)`` with the identification input ``u_c``.

Touchdown happens when ``h_t`` reaches 0 and resets ``h_t = ḣ_t = 0``
(plastic impact).  Liftoff happens when the ground reaction force on the toe,
``F + m g``, reaches zero.  Eq. (3.55) states the liftoff condition as
``F = 0``, leaving out the toe weight ``m g = 0.49 N``; with that condition
the toe would accelerate into the ground at the instant of liftoff and
touch down again immediately, so the toe weight is kept here.

Two stable T-periodic motions coexist for these parameters: the hopping
limit cycle of Fig. 3.12 (reached, for example, when the robot is released
from rest 0.3 m high with an unloaded leg) and a motion that never leaves the
ground (reached from rest in static equilibrium on the ground).
"""

import math

import numpy as np

import ltpcontrol as ltp

#: Table 3.2 parameters (a = 75 N, ω_p = 2π/0.33 rad/s).
VHOP_PARAMS = {'M': 2.7, 'm': 0.05, 'k': 6500.0, 'd': 12.0, 'a': 75.0,
               'omega_p': 2 * np.pi / 0.33, 'g': 9.81, 'l0': 0.2}

#: Pumping period in seconds.
PERIOD = 0.33


def _floats(v):
    # plain floats: the solver calls the vector fields a dozen times per step, and
    # scalar arithmetic on floats is several times faster than on numpy scalars
    return v.tolist() if isinstance(v, np.ndarray) else [float(a) for a in v]


def _actuator(t, u, p):
    # u(t) = a cos(ω_p t) + u_c(t)
    return p['a'] * math.cos(p['omega_p'] * t) + float(u[0])


def _leg_force(t, x, u, p):
    # F = −d (ḣ − ḣ_t) + k (ℓ0 − (h − h_t)) + u(t)
    h, h_t, hdot, hdot_t = _floats(x)
    return -p['d'] * (hdot - hdot_t) + p['k'] * (p['l0'] - (h - h_t)) + _actuator(t, u, p)


def _flight(t, x, u, p):
    force = _leg_force(t, x, u, p)
    return [float(x[2]), float(x[3]), -p['g'] + force / p['M'], -p['g'] - force / p['m']]


def _stance(t, x, u, p):
    h, _, hdot, _ = _floats(x)
    force = -p['d'] * hdot + p['k'] * (p['l0'] - h) + _actuator(t, u, p)
    return [hdot, 0.0, -p['g'] + force / p['M'], 0.0]


def _flight_jacobian(t, x, u, p):
    kM, dM, km, dm = p['k'] / p['M'], p['d'] / p['M'], p['k'] / p['m'], p['d'] / p['m']
    return np.array([[0, 0, 1, 0], [0, 0, 0, 1],
                     [-kM, kM, -dM, dM], [km, -km, dm, -dm]], float)


def _stance_jacobian(t, x, u, p):
    return np.array([[0, 0, 1, 0], [0, 0, 0, 0],
                     [-p['k'] / p['M'], 0, -p['d'] / p['M'], 0], [0, 0, 0, 0]], float)


def _flight_input(t, x, u, p):
    return np.array([[0.0], [0.0], [1 / p['M']], [-1 / p['m']]])


def _stance_input(t, x, u, p):
    return np.array([[0.0], [0.0], [1 / p['M']], [0.0]])


def _ground_reaction(t, x, u, p):
    # toe at rest on the ground: N = F + m g (liftoff when N = 0)
    return _leg_force(t, x, u, p) + p['m'] * p['g']


def _touchdown(t, x, u, p):
    return [x[0], 0.0, x[2], 0.0]


def vhop_plant(**params):
    """VHOP hybrid plant with modes ``'stance'`` and ``'flight'``.

    Parameters
    ----------
    **params : float
        Overrides of `VHOP_PARAMS`.

    Returns
    -------
    ltpcontrol.HybridPlant
        States ``['h', 'h_t', 'hdot', 'hdot_t']``, input ``'u_c'``, output
        ``'h'``.
    """
    unknown = set(params) - set(VHOP_PARAMS)
    if unknown:
        raise TypeError(f"vhop_plant: unrecognized keyword(s): {sorted(unknown)}")
    modes = [
        ltp.HybridMode(_stance, guard=_ground_reaction, target='flight', name='stance',
                       jacobian=_stance_jacobian, input_jacobian=_stance_input),
        ltp.HybridMode(_flight, guard=lambda t, x, u, p: x[1], reset=_touchdown,
                       target='stance', name='flight', jacobian=_flight_jacobian,
                       input_jacobian=_flight_input),
    ]
    plant = ltp.HybridPlant(modes, lambda t, x, u, p: [x[0]],
                            states=['h', 'h_t', 'hdot', 'hdot_t'], inputs=['u_c'],
                            outputs=['h'], params={**VHOP_PARAMS, **params}, name='vhop')
    plant._vhop_params = tuple(sorted(plant.params.items()))
    return plant


def release_state(height=0.3, params=VHOP_PARAMS):
    """State at rest in the air at body height `height`, leg unloaded.

    The leg length is the rest length shortened by the toe weight,
    ``ℓ0 − m g / k``; the initial mode is ``'flight'``.
    """
    leg = params['l0'] - params['m'] * params['g'] / params['k']
    return np.array([height, height - leg, 0.0, 0.0])


#: Orbits already computed in this process, by plant parameters and arguments.
_ORBITS = {}


def vhop_orbit(plant=None, height=0.3, warmup=20, **kwargs):
    """Hopping limit cycle reached after releasing the robot at `height`.

    Simulates `warmup` periods from `release_state` and then refines the
    orbit by shooting (keywords go to `ltpcontrol.periodic_orbit`).  The
    orbit of a plant made by `vhop_plant` is computed once per process for
    the same parameters and arguments (the examples that use it run in one
    documentation build); the same orbit object is returned again, so
    callers must not modify it.
    """
    plant = vhop_plant() if plant is None else plant
    key = getattr(plant, '_vhop_params', None)
    if key is not None and plant.params == dict(key):
        key = (key, height, warmup, tuple(sorted(kwargs.items())))
        try:
            hash(key)
        except TypeError:           # unhashable keywords: no reuse
            key = None
    else:
        key = None
    if key is not None and key in _ORBITS:
        return _ORBITS[key]
    orbit = ltp.periodic_orbit(plant, PERIOD, release_state(height, plant.params), 'flight',
                               warmup=warmup, **kwargs)
    if key is not None:
        _ORBITS[key] = orbit
    return orbit


if __name__ == '__main__':
    orbit = vhop_orbit()
    print(orbit)
    print('event times (liftoff, touchdown):', orbit.switching_times)
    print('mode sequence:', [orbit.plant.mode_names[i] for i in orbit.mode_sequence])
