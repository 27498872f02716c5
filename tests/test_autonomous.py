"""Orbits of autonomous plants: unknown period, return maps, continuation, bad input.

Every figure is checked against an independent truth: long `solve_ivp`
runs with event location, finite differences of independently coded
return maps, Liouville's formula, and closed-form bifurcation points.
"""

import control as ct
import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

from examples.clockfree_hopper import apex_map, clockfree_hopper, hopping_gait
from examples.slip_model import SLIPParams, neutral_touchdown_angle, predict_stride
from examples.slip_running import apex_return_map, slip_plant


# ----------------------------------------------------------------- van der Pol

def vdp_rhs(mu):
    return lambda t, x: [x[1], mu * (1 - x[0] ** 2) * x[1] - x[0]]


def vdp_sys(mu, inputs=0):
    def f(t, x, u, p):
        return [x[1], p['mu'] * (1 - x[0] ** 2) * x[1] - x[0] + (u[0] if inputs else 0)]
    return ct.nlsys(f, None, states=2, inputs=inputs, params={'mu': mu}, name='vdp')


def vdp_jac(t, x, u, p):
    mu = p['mu']
    return np.array([[0.0, 1.0], [-2 * mu * x[0] * x[1] - 1, mu * (1 - x[0] ** 2)]])


def down_crossings(mu, x0, t_end):
    """Times and states where y = 0 is crossed downwards (x > 0), plain solve_ivp."""
    def event(t, x):
        return x[1]
    event.direction = -1
    sol = solve_ivp(vdp_rhs(mu), (0, t_end), x0, method='DOP853', rtol=1e-12, atol=1e-13,
                    events=event, dense_output=True)
    keep = sol.t_events[0] > 1e-6
    return sol.t_events[0][keep], sol.y_events[0][keep], sol


def vdp_return(mu, a, T):
    """Return map x -> x' on the half-line y = 0, x > 0 (independent of the library)."""
    times, states, _ = down_crossings(mu, [a, 0.0], 1.5 * T)
    return states[0, 0]


@pytest.fixture(scope='module', params=[0.5, 1.0, 5.0])
def vdp(request):
    mu = request.param
    orbit = ltp.limit_cycle(vdp_sys(mu), None, [2.0, 0.0], section=lambda x: x[1],
                            direction=-1, jacobian=vdp_jac)
    return mu, orbit


class TestVanDerPol:
    def test_period_against_long_simulation(self, vdp):
        mu, orbit = vdp
        # from a point off the cycle; drop the transient (multiplier^8 < 1e-11)
        nper = 20 if mu < 2 else 10
        times, _, _ = down_crossings(mu, [0.5, 0.5], (nper + 1) * orbit.period)
        assert len(times) >= nper
        assert abs(np.mean(np.diff(times[8 if mu < 2 else 2:])) - orbit.period) < 1e-8

    def test_multipliers(self, vdp):
        mu, orbit = vdp
        assert abs(orbit.phase_multiplier - 1) < 1e-8
        (lam,) = orbit.stability_multipliers
        # fourth-order central differences of the independent return map
        a, T, h = orbit.x0[0], orbit.period, 1e-3
        P = [vdp_return(mu, a + k * h, T) for k in (-2, -1, 1, 2)]
        fd = (P[0] - 8 * P[1] + 8 * P[2] - P[3]) / (12 * h)
        assert abs(lam - fd) < 1e-8
        # Liouville: the product of the multipliers is exp(∫ div f dt)
        t = np.linspace(0, T, 4001)
        x = orbit(t)
        div = mu * (1 - x[0] ** 2)
        liouville = np.exp(np.sum((div[1:] + div[:-1]) / 2 * np.diff(t)))
        assert abs(lam - liouville) < 1e-8
        assert orbit.is_stable and orbit.autonomous
        # the return-map Jacobian carries the same multiplier and 0 along the flow
        ev = np.sort(np.abs(np.linalg.eigvals(orbit.poincare_jacobian)))
        assert ev[0] < 1e-8 and abs(ev[1] - abs(lam)) < 1e-8

    def test_orbit_lies_on_the_cycle(self, vdp):
        mu, orbit = vdp
        assert abs(orbit.x0[1]) < 1e-10
        _, states, _ = down_crossings(mu, orbit.x0, 1.2 * orbit.period)
        assert abs(states[0, 0] - orbit.x0[0]) < 1e-8


def test_default_section_and_period_guess():
    orbit = ltp.limit_cycle(vdp_sys(1.0), 6.0, [1.0, 1.0], jacobian=vdp_jac)
    assert abs(orbit.period - 6.663286859) < 1e-8
    # the default section passes through x0 normal to the flow
    np.testing.assert_allclose(orbit.section([1.0, 1.0]), 0, atol=1e-15)


def test_linearization_keeps_the_phase_multiplier():
    sys_u = vdp_sys(1.0, inputs=1)
    orbit = ltp.limit_cycle(sys_u, None, [2.0, 0.0], section=lambda x: x[1], direction=-1,
                            jacobian=vdp_jac)
    lin = ltp.linearize_orbit(sys_u, orbit, jacobian=vdp_jac)
    assert lin.period == orbit.period
    mu = np.sort(np.abs(ltp.floquet_multipliers(lin)))
    np.testing.assert_allclose(mu, np.sort(np.abs(orbit.multipliers)), atol=1e-7)
    assert not ltp.is_stable(lin)
    assert ltp.is_stable(lin, autonomous=True)


# ------------------------------------------------------------ clock-free hopper

@pytest.fixture(scope='module')
def gait():
    return hopping_gait()


class TestClockFreeHopper:
    def test_saltation_matrices_are_not_identity(self, gait):
        assert len(gait.saltation_matrices) == 3
        for S in gait.saltation_matrices:
            assert np.max(np.abs(S - np.eye(2))) > 0.1

    def test_multiplier_against_independent_return_map(self, gait):
        h, h_step = gait.x0[0], 1e-4
        height, time = apex_map(h)
        assert abs(height - h) < 1e-9 and abs(time - gait.period) < 1e-9
        fd = (apex_map(h + h_step)[0] - apex_map(h - h_step)[0]) / (2 * h_step)
        assert abs(gait.stability_multipliers[0] - fd) < 1e-5
        assert abs(gait.phase_multiplier - 1) < 1e-8

    def test_stability_verdict_agrees_with_simulation(self, gait):
        assert gait.is_stable
        lam = gait.stability_multipliers[0].real
        for h in (0.8 * gait.x0[0], 1.3 * gait.x0[0]):
            errors = []
            for _ in range(40):
                h = apex_map(h, rtol=1e-9, atol=1e-11)[0]
                errors.append(abs(h - gait.x0[0]))
            assert errors[-1] < 1e-6
            # close to the gait the error contracts by the multiplier per hop
            assert abs(errors[15] / errors[14] - abs(lam)) < 1e-2


# ------------------------------------------------------------------------ SLIP

class TestSLIPReturnMap:
    def test_apex_map_matches_slip_model(self):
        P, apex = SLIPParams(), np.array([0.0, 1.0, 0.3])
        nxt, t, J = apex_return_map(slip_plant(P, -0.2), apex, jacobian=True)
        s = predict_stride(apex, -0.2, P, method='SLIPD')
        np.testing.assert_allclose(nxt, [s.apex.vy, s.apex.z], atol=1e-9)
        assert abs(t - s.apex.t) < 1e-9
        h, fd = 1e-6, np.empty((2, 2))
        for j, i in enumerate((1, 2)):
            sp, sm = (predict_stride(apex + d, -0.2, P, method='SLIPD')
                      for d in (h * np.eye(3)[i], -h * np.eye(3)[i]))
            fd[:, j] = [(sp.apex.vy - sm.apex.vy) / (2 * h), (sp.apex.z - sm.apex.z) / (2 * h)]
        np.testing.assert_allclose(J, fd, atol=1e-6)

    def test_lossless_gait_multipliers(self):
        P = SLIPParams(m_l=0.0, d=0.0, d_h=0.0, d_v=0.0)
        apex = np.array([0.0, 1.0, 0.3])
        theta = float(neutral_touchdown_angle(apex, P, method='SLIP'))
        nxt, _, J = apex_return_map(slip_plant(P, theta), apex, jacobian=True)
        np.testing.assert_allclose(nxt, apex[1:], atol=1e-6)
        # energy is conserved: one multiplier is 1, the other decides stability
        ev = np.sort(np.linalg.eigvals(J).real)
        assert abs(ev[0] - 1) < 1e-5
        s = [predict_stride(apex + d, theta, P, method='SLIP')
             for d in (1e-6 * np.eye(3)[2], -1e-6 * np.eye(3)[2])]
        dz = (s[0].apex.z - s[1].apex.z) / 2e-6
        dv = (s[0].apex.vy - s[1].apex.vy) / 2e-6
        np.testing.assert_allclose(J[:, 1], [dv, dz], atol=1e-5)


# ---------------------------------------------------------------- continuation

def bautin(t, x, u, p):
    r2 = x[0] ** 2 + x[1] ** 2
    g = p['p'] + r2 - r2 ** 2
    return [x[0] * g - x[1], x[1] * g + x[0]]


def bautin_jac(t, x, u, p):
    r2 = x[0] ** 2 + x[1] ** 2
    g, dg = p['p'] + r2 - r2 ** 2, 2 - 4 * r2
    return np.array([[g + dg * x[0] ** 2, dg * x[0] * x[1] - 1],
                     [dg * x[0] * x[1] + 1, g + dg * x[1] ** 2]])


@pytest.mark.slow
def test_fold_of_cycles_at_closed_form_value():
    """ṙ = r (p + r² − r⁴): cycles r² = (1 ± √(1 + 4p))/2 meet at p = −1/4."""
    sys_b = ct.nlsys(bautin, None, states=2, inputs=0, params={'p': 0.0})
    orbit = ltp.limit_cycle(sys_b, 6.0, [1.0, 0.0], jacobian=bautin_jac)
    branch = ltp.orbit_continuation(orbit, 'p', np.linspace(0, -0.28, 8), max_halvings=7)
    (fold,) = branch.bifurcations
    assert fold.kind == 'fold' and abs(fold.value + 0.25) < 1e-4
    # multipliers along the branch: exp(2π · 2r²(1 − 2r²)) with r² on the stable cycle
    # (the orbit is ill-conditioned at the fold: skip the last 1e-4 before it)
    away = 1 + 4 * branch.values > 4e-4
    r2 = (1 + np.sqrt(1 + 4 * branch.values[away])) / 2
    np.testing.assert_allclose(branch.multipliers[away, 0].real,
                               np.exp(2 * np.pi * 2 * r2 * (1 - 2 * r2)), atol=1e-6)
    assert 'ends' in branch.message and branch.stable.all()
    cplt = branch.plot()
    assert isinstance(cplt, ct.ControlPlot) and cplt.axes.shape == (2, 1)


def rossler(t, x, u, p):
    return [-x[1] - x[2], x[0] + p['a'] * x[1], p['b'] + x[2] * (x[0] - p['c'])]


def rossler_jac(t, x, u, p):
    return np.array([[0, -1, -1], [1, p['a'], 0], [x[2], 0, x[0] - p['c']]])


def rossler_multipliers(c, guess):
    """Return-map multipliers on x = 0 (x decreasing), all by plain solve_ivp."""
    def rhs(t, x):
        return rossler(t, x, None, {'a': 0.2, 'b': 0.2, 'c': c})

    def event(t, x):
        return x[0]
    event.direction = -1

    def ret(yz):
        sol = solve_ivp(rhs, (0, 9.0), [0.0, *yz], method='DOP853', rtol=1e-12, atol=1e-13,
                        events=event)
        times = sol.t_events[0]
        return sol.y_events[0][np.argmax(times > 1e-6), 1:]

    yz = np.array(guess, float)
    for _ in range(2):          # fixed point of the return map by Newton (FD Jacobian)
        J = np.column_stack([(ret(yz + h) - ret(yz - h)) / 2e-6 for h in 1e-6 * np.eye(2)])
        yz = yz + np.linalg.solve(np.eye(2) - J, ret(yz) - yz)
    return np.linalg.eigvals(J)


@pytest.mark.slow
def test_period_doubling_of_rossler_located():
    sys_r = ct.nlsys(rossler, None, states=3, inputs=0,
                     params={'a': 0.2, 'b': 0.2, 'c': 2.6})
    orbit = ltp.limit_cycle(sys_r, 5.7, [0.0, 3.0, 1.8], section=lambda x: x[0],
                            direction=-1, jacobian=rossler_jac)
    branch = ltp.orbit_continuation(orbit, 'c', [2.6, 2.9, 3.0])
    (pd,) = branch.bifurcations
    assert pd.kind == 'period-doubling' and abs(pd.multiplier + 1) < 1e-6
    assert list(branch.stable) == [True, False, False]
    # independent return maps 1e-4 either side: a multiplier crosses −1 in between
    guess = pd.orbit.x0[1:]
    below = np.min(rossler_multipliers(pd.value - 1e-4, guess).real)
    above = np.min(rossler_multipliers(pd.value + 1e-4, guess).real)
    assert below > -1 > above


def test_continuation_of_a_forced_orbit_in_the_lti_limit():
    """Forced linear oscillator: the multipliers are exp(λ_i T) of the LTI system."""
    def f(t, x, u, p):
        return [x[1], -p['k'] * x[0] - 0.3 * x[1] + np.cos(t)]
    sys_f = ct.nlsys(f, None, states=2, inputs=0, params={'k': 1.5})
    orbit = ltp.periodic_orbit(sys_f, 2 * np.pi, [0.0, 0.0])
    branch = ltp.orbit_continuation(orbit, 'k', [1.5, 2.0, 3.0])
    for k, mu in zip(branch.values, branch.multipliers):
        lti = np.linalg.eigvals(np.array([[0, 1], [-k, -0.3]]))
        np.testing.assert_allclose(np.sort_complex(mu), np.sort_complex(np.exp(lti * 2 * np.pi)),
                                   atol=1e-8)


# ------------------------------------------------------------------- bad input

def stuart_landau(a):
    """ṙ = a r (1 − r²), θ̇ = 1: cycle r = 1 with multiplier exp(−4πa)."""
    def f(t, x, u, p):
        g = a * (1 - x[0] ** 2 - x[1] ** 2)
        return [x[0] * g - x[1], x[1] * g + x[0]]
    return ct.nlsys(f, None, states=2, inputs=0)


class TestBadInput:
    def test_start_far_from_an_attracting_orbit_converges(self):
        orbit = ltp.limit_cycle(stuart_landau(1), None, [30.0, 0.0], section=lambda x: x[1])
        assert abs(orbit.period - 2 * np.pi) < 1e-8 and orbit.is_stable

    def test_unstable_orbit_found_from_nearby(self):
        orbit = ltp.limit_cycle(stuart_landau(-0.1), 6.0, [1.05, 0.0], max_periods=0)
        assert abs(orbit.period - 2 * np.pi) < 1e-8 and not orbit.is_stable
        assert abs(orbit.stability_multipliers[0] - np.exp(0.4 * np.pi)) < 1e-8
        # the verdict agrees with simulation: a perturbed state leaves the cycle
        sol = solve_ivp(lambda t, x: stuart_landau(-0.1).updfcn(t, x, [], {}),
                        (0, 10 * np.pi), [1.001, 0.0], rtol=1e-10, atol=1e-12)
        assert np.hypot(*sol.y[:, -1]) - 1 > 0.1

    def test_start_far_from_a_repelling_orbit_diverges(self):
        with pytest.raises(RuntimeError, match="diverges"):
            ltp.limit_cycle(stuart_landau(-1), None, [3.0, 0.0], section=lambda x: x[1])

    def test_plant_with_an_equilibrium(self):
        damped = ct.nlsys(lambda t, x, u, p: [x[1], -x[0] - 0.5 * x[1]], None, states=2,
                          inputs=0)
        with pytest.raises(RuntimeError, match="equilibrium"):
            ltp.limit_cycle(damped, 6.0, [1.0, 0.0], section=lambda x: x[1], direction=-1,
                            timeout=30)
        with pytest.raises(ValueError, match="equilibrium"):
            ltp.limit_cycle(damped, 6.0, [0.0, 0.0])

    def test_section_never_crossed(self):
        with pytest.raises(ValueError, match="does not cross the section"):
            ltp.limit_cycle(vdp_sys(1.0), 6.0, [2.0, 0.0], section=lambda x: x[0] - 10,
                            jacobian=vdp_jac)
        with pytest.raises(ValueError, match="does not cross the section"):
            ltp.poincare_map(vdp_sys(1.0), [2.0, 0.0], lambda x: x[0] - 10, max_time=50)

    def test_time_limit(self):
        with pytest.raises(TimeoutError):
            ltp.limit_cycle(vdp_sys(1.0), None, [0.1, 0.0], timeout=1e-6)

    def test_clock_driven_plant_rejected(self):
        forced = ct.nlsys(lambda t, x, u, p: [x[1], -x[0] + np.cos(t)], None, states=2,
                          inputs=0)
        with pytest.raises(ValueError, match="not autonomous"):
            ltp.limit_cycle(forced, 6.0, [1.0, 0.0])

    def test_arguments(self):
        sys_v = vdp_sys(1.0)
        with pytest.raises(ValueError, match="direction"):
            ltp.limit_cycle(sys_v, 6.0, [2.0, 0.0], section=lambda x: x[1], direction=0)
        with pytest.raises(ControlArgument, match="section"):
            ltp.limit_cycle(sys_v, 6.0, [2.0, 0.0], section=3.0)
        with pytest.raises(ControlDimension, match="x0"):
            ltp.limit_cycle(sys_v, 6.0, [2.0, 0.0, 1.0])
        with pytest.raises(ValueError, match="tol"):
            ltp.limit_cycle(sys_v, 6.0, [2.0, 0.0], tol=2.0)
        with pytest.raises(ValueError, match="period"):
            ltp.limit_cycle(sys_v, -1.0, [2.0, 0.0])
        with pytest.raises(ControlArgument, match="section must return a real scalar"):
            ltp.limit_cycle(sys_v, 6.0, [2.0, 0.0], section=lambda x: x)
        orbit = ltp.limit_cycle(stuart_landau(1), None, [1.0, 0.0])
        with pytest.raises(ValueError, match="param"):
            ltp.orbit_continuation(orbit, 'nope', [0.0, 1.0])
        with pytest.raises(ControlArgument, match="orbit"):
            ltp.orbit_continuation('orbit', 'a', [0.0, 1.0])


def test_kicked_ball_closed_form():
    """v⁺ = −e v⁻ + c at each bounce: period 2c/((1−e)g), multiplier e."""
    e, c, g = 0.6, 3.0, 9.81
    air = ltp.HybridMode(lambda t, x, u, p: [x[1], -g], guard=lambda t, x, u, p: x[0],
                         reset=lambda t, x, u, p: [0.0, -e * x[1] + c], target=0)
    ball = ltp.HybridPlant([air], states=['h', 'v'])
    orbit = ltp.limit_cycle(ball, None, [0.2, 0.0], section=lambda x: x[1], direction=-1)
    assert abs(orbit.period - 2 * c / ((1 - e) * g)) < 1e-10
    assert abs(orbit.x0[0] - (c / (1 - e)) ** 2 / (2 * g)) < 1e-10
    assert abs(orbit.stability_multipliers[0] - e) < 1e-8
    assert abs(orbit.phase_multiplier - 1) < 1e-8
