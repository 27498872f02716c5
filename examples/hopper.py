"""Simplified vertical hopper of thesis §3.4 (eqs. 3.36-3.40, 3.43).

A mass on a spring whose damper acts only while the mass moves up
(``ẋ > 0``, the lossy "stance" chart) and is off otherwise (lossless
"flight" chart), driven by the actuator force ``f0(t) + u(t)`` with
``f0(t) = cos 2πt``:

``m ẍ = −m g − c s ẋ − k (x − x0) + f0(t) + u``,  ``s = 1`` if ``ẋ > 0``.

The functions below build the hybrid plant, its 1 s limit cycle, the
analytic LTP model (3.39) with the square-wave damping flag ``s(t)`` frozen
at the orbit's switching times, and the piecewise-LTI return map (3.43).
"""

import numpy as np
from scipy.linalg import expm

import ltpcontrol as ltp

#: Parameters of the thesis (§3.4.1).
HOPPER_PARAMS = {'g': 9.81, 'k': 200.0, 'c': 2.0, 'm': 1.0, 'x0': 0.2}

#: Forcing period in seconds (``f0(t) = cos 2πt``).
PERIOD = 1.0

#: Simulated experiments already at hand in this process, by their arguments (see
#: `cached_experiment`).
_EXPERIMENTS = {}


def cached_experiment(key, simulate):
    """``simulate()``, computed once per process for the same hashable `key`
    (every time when `key` is None).

    The examples that simulate the same experiment (the undelayed chirps of
    the delay study and of the HTF identification) run in one documentation
    build; the same result objects are returned again, so callers must not
    modify them.
    """
    if key is None:
        return simulate()
    if key not in _EXPERIMENTS:
        _EXPERIMENTS[key] = simulate()
    return _EXPERIMENTS[key]


def _vector_field(damped):
    def updfcn(t, x, u, p):
        # m ẍ = −m g − c s ẋ − k (x − x0) + cos 2πt + u
        damping = p['c'] * x[1] if damped else 0.0
        force = -p['m'] * p['g'] - damping - p['k'] * (x[0] - p['x0']) \
            + np.cos(2 * np.pi * t / PERIOD) + u[0]
        return [x[1], force / p['m']]
    return updfcn


def _state_matrix(damped):
    def jacobian(t, x, u, p):
        return np.array([[0.0, 1.0], [-p['k'] / p['m'], -p['c'] * damped / p['m']]])
    return jacobian


def _input_matrix(t, x, u, p):
    return np.array([[0.0], [1.0 / p['m']]])


def hopper_plant(**params):
    """Hybrid plant of eq. (3.36) with modes ``'lossy'`` and ``'lossless'``.

    Parameters
    ----------
    **params : float
        Overrides of `HOPPER_PARAMS` (``g``, ``k``, ``c``, ``m``, ``x0``).

    Returns
    -------
    ltpcontrol.HybridPlant
        States ``['x', 'v']``, input ``'u'`` (actuator perturbation),
        output ``'x'``.
    """
    unknown = set(params) - set(HOPPER_PARAMS)
    if unknown:
        raise TypeError(f"hopper_plant: unrecognized keyword(s): {sorted(unknown)}")
    modes = [
        ltp.HybridMode(_vector_field(True), guard=lambda t, x, u, p: x[1],
                       target='lossless', name='lossy', jacobian=_state_matrix(True),
                       input_jacobian=_input_matrix),
        ltp.HybridMode(_vector_field(False), guard=lambda t, x, u, p: -x[1],
                       target='lossy', name='lossless', jacobian=_state_matrix(False),
                       input_jacobian=_input_matrix),
    ]
    plant = ltp.HybridPlant(modes, lambda t, x, u, p: [x[0]], states=['x', 'v'],
                            inputs=['u'], outputs=['x'], params={**HOPPER_PARAMS, **params},
                            name='hopper')
    plant._hopper_params = tuple(sorted(plant.params.items()))
    return plant


def plant_key(plant):
    """Hashable parameters of a plant made by `hopper_plant` (None for other plants)."""
    key = getattr(plant, '_hopper_params', None)
    return key if key is not None and plant.params == dict(key) else None


def hopper_orbit(plant=None, x0=(0.15, 0.0), mode0='lossy', **kwargs):
    """The hopper's 1 s limit cycle (keywords go to `ltpcontrol.periodic_orbit`)."""
    plant = hopper_plant() if plant is None else plant
    return ltp.periodic_orbit(plant, PERIOD, x0, mode0, **kwargs)


def _mode_matrices(orbit, k, c, m):
    """``A_i = [[0, 1], [−k/m, −c s_i/m]]`` for each interval of the orbit."""
    lossy = orbit.plant.mode_index('lossy')
    return [np.array([[0.0, 1.0], [-k / m, -c * (mode == lossy) / m]])
            for mode in orbit.mode_sequence]


def hopper_ltp(orbit, k=HOPPER_PARAMS['k'], c=HOPPER_PARAMS['c'], m=HOPPER_PARAMS['m']):
    """Analytic LTP model (3.39) about the orbit, output ``y = ξ1``.

    ``A(t) = [[0, 1], [−k/m, −c s(t)/m]]``, ``B = [0, 1/m]ᵀ``, ``C = [1, 0]``
    where the damping flag ``s(t)`` is the square wave equal to 1 on the
    orbit's lossy intervals (a switching `PeriodicMatrix`).
    """
    times = np.concatenate([[0.0], orbit.switching_times])
    A = ltp.PeriodicMatrix.switching(_mode_matrices(orbit, k, c, m), times, orbit.period)
    return ltp.ltpss(A, [[0.0], [1.0 / m]], [[1.0, 0.0]], 0, orbit.period, name='hopper_ltp',
                     inputs=['u'], outputs=['x'], states=['x', 'v'])


def piecewise_lti_return_map(orbit, k=HOPPER_PARAMS['k'], c=HOPPER_PARAMS['c'],
                             m=HOPPER_PARAMS['m']):
    """Linearised return map of eq. (3.43), ``DP = Π e^{A_i Δt_i}``.

    The product runs over the orbit's mode intervals in time order (for the
    two-interval case ``e^{A_1 (T − t̂)} e^{A_0 t̂}``), so it is the period
    map Jacobian of the time-switching model at t = 0 and has the same
    eigenvalues as (3.43) on the Poincaré section.
    """
    times = np.concatenate([[0.0], orbit.switching_times, [orbit.period]])
    DP = np.eye(2)
    for A, dt in zip(_mode_matrices(orbit, k, c, m), np.diff(times)):
        DP = expm(A * dt) @ DP
    return DP


if __name__ == '__main__':
    orbit = hopper_orbit()
    print(orbit)
    print('switching times:', orbit.switching_times, 'modes:', orbit.mode_sequence)
    print('exact return-map eigenvalues:', orbit.multipliers)
    print('(3.43) eigenvalues:          ', np.linalg.eigvals(piecewise_lti_return_map(orbit)))
