"""Kinked closed-loop return maps: a ball on a vibrating table under continuous state feedback."""

import warnings

import numpy as np
import control as ct
import pytest
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

G, E, T, AMP = 9.81, 0.5, 0.5, 0.1
W = 2 * np.pi / T
TIGHT = dict(method='DOP853', rtol=1e-12, atol=1e-13)


def table(t):
    return AMP * np.sin(W * t)


def table_speed(t):
    return AMP * W * np.cos(W * t)


def ball_plant(analytic):
    extra = dict(jacobian=lambda t, x, u, p: [[0.0, 1.0], [0.0, 0.0]],
                 input_jacobian=lambda t, x, u, p: [[0.0], [1.0]]) if analytic else {}
    air = ltp.HybridMode(lambda t, x, u, p: [x[1], -G + u[0]],
                         guard=lambda t, x, u, p: x[0] - table(t),
                         reset=lambda t, x, u, p: [x[0], table_speed(t) - E * (x[1]
                                                                              - table_speed(t))],
                         target='air', name='air', **extra)
    return ltp.HybridPlant([air], states=['y', 'v'], inputs=1)


# the unstable period-1 orbit in closed form: impacts where the table moves at
# w = gT(1 - e)/(2(1 + e)) upwards; the ball leaves at v⁺ = gT/2 and flies for T
IMPACT = np.arccos(G * T * (1 - E) / (2 * (1 + E)) / (AMP * W)) / W
V_PLUS = G * T / 2


def nominal(t):
    """x̄(t), right-continuous at the impact."""
    tau = np.mod(t - IMPACT, T)
    return np.array([table(IMPACT) + V_PLUS * tau - G * tau ** 2 / 2, V_PLUS - G * tau])


def reference_period_map(x0, K):
    """x(0) -> x(T) of the loop u = −K (x − x̄(t)), by solve_ivp with impact events."""
    def rhs(t, x):
        u = -K @ (x - nominal(t))
        return [x[1], -G + u[0]]

    def hit(t, x):
        return x[0] - table(t)
    hit.terminal, hit.direction = True, -1
    x = np.array(x0, float)
    # x̄ jumps at the nominal impact: integrate up to it and from it separately
    for a, b in ((0.0, IMPACT), (IMPACT, T)):
        while True:
            sol = solve_ivp(rhs, (a, b), x, events=hit, **TIGHT)
            x = sol.y[:, -1]
            if sol.status != 1:
                break
            a = sol.t[-1]
            x = np.array([x[0], table_speed(a) - E * (x[1] - table_speed(a))])
    return x


def reference_one_sided(K, h=1e-4):
    """One-sided Jacobians of the reference map: impacts before / after the nominal one."""
    x0 = nominal(0.0)

    def impact_time(x):
        def hit(t, z):
            return z[0] - table(t)
        hit.terminal, hit.direction = True, -1
        sol = solve_ivp(lambda t, z: [z[1], -G - (K @ (z - nominal(t)))[0]], (0, IMPACT + 0.1),
                        x, events=hit, **TIGHT)
        return sol.t_events[0][0]
    # gradient of the (smooth) first impact time
    grad = np.array([(impact_time(x0 + 1e-6 * e) - impact_time(x0 - 1e-6 * e)) / 2e-6
                     for e in np.eye(2)])
    u = grad / np.linalg.norm(grad)
    w = np.array([-u[1], u[0]])
    P0 = reference_period_map(x0, K)
    out = {}
    for side, sign in (('early', -1.0), ('late', 1.0)):
        D = np.column_stack([sign * u, sign * u + w])      # both strictly on one side
        cols = []
        for d in D.T:
            P1, P2 = (reference_period_map(x0 + m * h * d, K) for m in (1, 2))
            cols.append((-3 * P0 + 4 * P1 - P2) / (2 * h))
        out[side] = np.column_stack(cols) @ np.linalg.inv(D)
    return out


@pytest.fixture(scope='module')
def design():
    plant = ball_plant(analytic=False)
    orbit = ltp.periodic_orbit(plant, T, nominal(0.0))
    assert np.allclose(orbit.x0, nominal(0.0), atol=1e-8) and not orbit.is_stable
    with pytest.warns(UserWarning, match="freezes the orbit's"):
        lin = ltp.linearize_orbit(plant, orbit)
    K, _, _ = ltp.lqr(lin, np.eye(2), [[1.0]])
    return orbit, K


@pytest.mark.parametrize('analytic', [False, True])
def test_kink_both_sides_reported(design, analytic):
    orbit, K = design
    plant = ball_plant(analytic)
    ctrl = ltp.ltpss(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((1, 0)), -K, period=T)
    with pytest.warns(UserWarning, match='kink'):
        cl = ltp.closed_loop_orbit(plant, ctrl, orbit)
    # independent: python-control's LQR gain of the double integrator (the
    # time-switching model about the orbit), the closed-form orbit, events
    Kref = ct.lqr(np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]]),
                  np.eye(2), [[1.0]])[0]
    assert np.allclose(K(0.123), Kref, atol=1e-8)
    ref = reference_one_sided(Kref)
    radii = {side: np.abs(np.linalg.eigvals(J)).max() for side, J in ref.items()}
    assert abs(radii['late'] - radii['early']) > 0.1            # a genuine kink
    assert len(cl.one_sided_multipliers) == 2
    got = [np.abs(m).max() for m in cl.one_sided_multipliers]   # early, late
    assert abs(got[0] - radii['early']) < 1e-5
    assert abs(got[1] - radii['late']) < 1e-5
    assert cl.dominant_multiplier == pytest.approx(max(got))
    assert cl.is_stable == (max(got) < 1)
    assert np.allclose(cl.kink_times, IMPACT, atol=1e-8)


def test_smooth_loop_has_no_kink():
    # output = position, continuous at the impacts: no spike, no kink
    plant = ball_plant(analytic=True)
    plant_y = ltp.HybridPlant(plant.modes, lambda t, x, u, p: [x[0]], states=2, inputs=1,
                              outputs=1)
    orbit = ltp.periodic_orbit(plant_y, T, nominal(0.0))
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        cl = ltp.closed_loop_orbit(plant_y, ct.ss([], [], [], [[-0.5]]), orbit)
    assert cl.one_sided_multipliers == () and cl.kink_times.size == 0
