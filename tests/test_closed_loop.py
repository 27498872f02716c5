"""Closed hybrid loops: simulation and return map against independent solve_ivp loops."""

import warnings

import numpy as np
import control as ct
import pytest
from control.exception import ControlArgument, ControlDimension
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

T = 1.0
P = dict(k=40.0, c=1.0, a=5.0, x0=0.1, e=0.7)
TIGHT = dict(rtol=1e-12, atol=1e-13, method='DOP853')


def field(t, x, u):
    return np.array([x[1], -P['k'] * (x[0] - P['x0']) - P['c'] * x[1]
                     + P['a'] * np.cos(2 * np.pi * t) + u])


def impact(x):
    return np.array([x[0], -P['e'] * x[1]])


@pytest.fixture(scope='module')
def plant():
    """Forced oscillator hitting a wall at x = 0 with restitution e (one impact a period)."""
    mode = ltp.HybridMode(lambda t, x, u, p: field(t, x, u[0]),
                          guard=lambda t, x, u, p: x[0],
                          reset=lambda t, x, u, p: impact(x), target=0, name='free')
    return ltp.HybridPlant([mode], lambda t, x, u, p: [x[0]], states=['x', 'v'],
                           inputs=['u'], outputs=['y'], name='wall')


@pytest.fixture(scope='module')
def orbit(plant):
    return ltp.periodic_orbit(plant, T, [0.2, 0.0], warmup=30, rtol=1e-12, atol=1e-13)


def ltp_controller():
    """Dynamic output feedback with a periodic input gain (phase matters)."""
    Bc = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[1.0 + 0.5 * np.cos(2 * np.pi * t)]]), T)
    return ltp.ltpss([[-3.0]], Bc, [[-20.0]], [[-5.0]], T, name='K')


def bc(t):
    return 1.0 + 0.5 * np.cos(2 * np.pi * t)


def reference_loop(orbit, t0, tf, z0, noise=lambda t: 0.0, sat=np.inf, samples=None):
    """Independent loop: plant [x, v] and controller x_c in one solve_ivp with events.

    Continuous controller of `ltp_controller`; with `samples` = dt its exact
    zero-order-hold discretisation is sampled at k dt instead.
    """
    def ybar(t):
        return orbit(np.mod(t, T))[0]

    def e_of(t, x):
        return x[0] + noise(t) - ybar(t)

    def run(a, b, x, rhs):
        # integrate [a, b], resetting at every downward crossing of x = 0
        def hit(t, z):
            return z[0]
        hit.terminal, hit.direction = True, -1
        while True:
            sol = solve_ivp(rhs, (a, b), x, events=hit, **TIGHT)
            x = sol.y[:, -1]
            if sol.status != 1:
                return x
            a, x = sol.t[-1], np.concatenate([impact(x[:2]), x[2:]])

    if samples is None:
        def rhs(t, z):
            e = e_of(t, z)
            u = np.clip(-20.0 * z[2] - 5.0 * e, -sat, sat)
            return np.concatenate([field(t, z[:2], u), [-3.0 * z[2] + bc(t) * e]])
        return run(t0, tf, np.array(z0, float), rhs)
    # discrete: x_c[k+1] = Ad x_c + Bd_k e_k, u_k = -20 x_c[k] - 5 e_k, Bd_k = ∫ e^{-3s} ds bc
    ad, bd = np.exp(-3.0 * samples), (1 - np.exp(-3.0 * samples)) / 3.0
    z = np.array(z0, float)
    for k in range(int(round(t0 / samples)), int(round(tf / samples))):
        t = k * samples
        e = e_of(t, z)
        u = np.clip(-20.0 * z[2] - 5.0 * e, -sat, sat)
        xc = ad * z[2] + bd * bc(t + samples / 2) * e
        x = run(t, t + samples, z[:2], lambda s, w: field(s, w, u))
        z = np.concatenate([x, [xc]])
    return z


def fd_jacobian(func, z, h=2e-5):
    """Central differences, Richardson-extrapolated.

    The loop's period map is C¹ but not C² (``e = y − ȳ(t)`` has a kink where
    ȳ has one, at the nominal impact), so central differences err by O(h);
    ``2 D(h/2) − D(h)`` removes that term.
    """
    def central(step):
        cols = []
        for j in range(len(z)):
            dz = np.zeros(len(z))
            dz[j] = step
            cols.append((func(z + dz) - func(z - dz)) / (2 * step))
        return np.column_stack(cols)
    return 2 * central(h / 2) - central(h)


def discrete_controller(dt):
    """The sampled `ltp_controller`: exact ZOH of A_c, B_c held at mid-step values."""
    N = int(round(T / dt))
    ad, bd = np.exp(-3.0 * dt), (1 - np.exp(-3.0 * dt)) / 3.0
    Bd = np.array([[[bd * bc((k + 0.5) * dt)]] for k in range(N)])
    return ltp.ltpss(np.full((N, 1, 1), ad), Bd, [[-20.0]], [[-5.0]], T, dt=dt, name='Kd')


class TestSimulation:
    def test_continuous_matches_independent_loop(self, plant, orbit):
        # start off the orbit at a phase t0 ≠ 0: the controller reads the plant clock
        t = np.linspace(0.3, 3.3, 61)
        x0, xc0 = orbit(0.3) + [0.05, -0.2], 0.1
        noise = lambda t: 0.01 * np.sin(7 * t)    # noqa: E731
        resp = ltp.closed_loop_response(plant, ltp_controller(), orbit, t, x0, xc0,
                                        noise=noise, saturation=(-1.5, 1.5))
        ref = reference_loop(orbit, 0.3, 3.3, np.r_[x0, xc0], noise, sat=1.5)
        np.testing.assert_allclose(resp.states[:, -1], ref, atol=1e-6)
        assert np.max(np.abs(resp.inputs)) <= 1.5 + 1e-12
        assert np.max(np.abs(resp.inputs)) == pytest.approx(1.5)     # saturation was active
        assert resp.states.shape == (3, 61) and len(resp.event_times) >= 3
        np.testing.assert_allclose(resp.noise[0], noise(t))

    def test_discrete_matches_independent_loop(self, plant, orbit):
        dt = 0.05
        t = np.arange(0, 121) * dt / 2
        x0 = orbit.x0 + [0.05, -0.2]
        resp = ltp.closed_loop_response(plant, discrete_controller(dt), orbit, t, x0, 0.1)
        ref = reference_loop(orbit, 0.0, 3.0, np.r_[x0, 0.1], samples=dt)
        np.testing.assert_allclose(resp.states[:, -1], ref, atol=1e-6)
        # input and controller state are held between samples
        np.testing.assert_array_equal(resp.inputs[0:-1:2], resp.inputs[1::2])
        np.testing.assert_array_equal(resp.states[2, 0:-1:2], resp.states[2, 1::2])
        assert np.all(np.diff(resp.inputs[0::2]) != 0)

    def test_lti_controller_equals_its_ltp_form(self, plant, orbit):
        K = ct.ss([[-3.0]], [[1.0]], [[-20.0]], [[-5.0]])
        t = np.linspace(0, 2, 21)
        x0 = orbit.x0 + [0.05, 0.0]
        r1 = ltp.closed_loop_response(plant, K, orbit, t, x0)
        r2 = ltp.closed_loop_response(plant, ltp.ltpss(K, period=T / 2), orbit, t, x0)
        np.testing.assert_allclose(r1.states, r2.states, atol=1e-9)

    def test_nonlinear_controller(self, plant, orbit):
        lin = ct.ss([[-3.0]], [[1.0]], [[-20.0]], [[-5.0]])
        nl = ct.nlsys(lambda t, x, e, p: -3.0 * x + e, lambda t, x, e, p: -20.0 * x - 5.0 * e,
                      states=1, inputs=1, outputs=1, name='nl')
        t = np.linspace(0, 2, 21)
        x0 = orbit.x0 + [0.05, 0.0]
        np.testing.assert_allclose(
            ltp.closed_loop_response(plant, nl, orbit, t, x0).states,
            ltp.closed_loop_response(plant, lin, orbit, t, x0).states, atol=1e-8)

    def test_on_orbit_stays_on_orbit(self, plant, orbit):
        t = np.linspace(0, 2, 41)
        resp = ltp.closed_loop_response(plant, ltp_controller(), orbit, t)
        np.testing.assert_allclose(resp.states[:2], orbit(np.mod(t, T)), atol=1e-7)
        np.testing.assert_allclose(resp.states[2], 0, atol=1e-7)

    def test_progress_bar_is_silenceable(self, plant, orbit, capsys):
        ltp.closed_loop_response(plant, ltp_controller(), orbit, [0.0, 0.5])
        assert capsys.readouterr().err == ''


class TestReturnMap:
    @pytest.mark.slow
    def test_continuous_multipliers_match_finite_differences(self, plant, orbit):
        cl = ltp.closed_loop_orbit(plant, ltp_controller(), orbit, saturation=(-8, 8))
        z0 = np.r_[cl.x0, cl.controller_state]
        np.testing.assert_allclose(reference_loop(orbit, 0, T, z0), z0, atol=1e-8)
        fd = fd_jacobian(lambda z: reference_loop(orbit, 0, T, z), z0)
        np.testing.assert_allclose(cl.monodromy, fd, atol=1e-5)
        np.testing.assert_allclose(np.sort_complex(cl.multipliers),
                                   np.sort_complex(np.linalg.eigvals(fd)), atol=1e-5)
        assert cl.is_stable and cl.dominant_multiplier == pytest.approx(
            np.abs(cl.multipliers).max())

    def test_discrete_multipliers_match_finite_differences(self, plant, orbit):
        dt = 0.1
        cl = ltp.closed_loop_orbit(plant, discrete_controller(dt), orbit)
        z0 = np.r_[cl.x0, cl.controller_state]
        fd = fd_jacobian(lambda z: reference_loop(orbit, 0, T, z, samples=dt), z0)
        np.testing.assert_allclose(cl.monodromy, fd, atol=1e-5)
        assert cl.orbit is None and cl.is_stable

    def test_zero_controller_keeps_open_loop_multipliers(self, plant, orbit):
        # block triangular loop: plant multipliers and e^{A_c T}
        K = ct.ss([[-2.0]], [[1.0]], [[0.0]], [[0.0]])
        cl = ltp.closed_loop_orbit(plant, K, orbit)
        expected = np.r_[orbit.multipliers, np.exp(-2.0 * T)]
        np.testing.assert_allclose(np.sort_complex(cl.multipliers),
                                   np.sort_complex(expected), atol=1e-8)
        np.testing.assert_allclose(cl.x0, orbit.x0, atol=1e-9)

    def test_saturated_orbit_moves(self, plant, orbit):
        # a constant input bias clipped by the saturation shifts the orbit (Newton path)
        K = ct.nlsys(lambda t, x, e, p: np.zeros(0), lambda t, x, e, p: [0.3 - 2.0 * e[0]],
                     inputs=1, outputs=1,
                     states=0, name='bias')
        cl = ltp.closed_loop_orbit(plant, K, orbit, saturation=(-0.2, 0.2))
        resp = ltp.closed_loop_response(plant, K, orbit, [0.0, T], cl.x0,
                                        saturation=(-0.2, 0.2))
        np.testing.assert_allclose(resp.states[:, -1], cl.x0, atol=1e-8)
        assert np.max(np.abs(cl.x0 - orbit.x0)) > 1e-3

    def test_destabilizing_controller_is_reported(self, plant, orbit):
        K = ct.ss([], [], [], [[60.0]])       # positive position feedback: k_eff < 0
        cl = ltp.closed_loop_orbit(plant, K, orbit)
        assert not cl.is_stable and cl.dominant_multiplier > 1
        assert 'stable=False' in repr(cl)
        # the simulation of the unstable loop ends: it leaves the orbit, saturated and
        # bounded, or settles against the wall in infinitely many impacts (Zeno), which
        # is reported and ends the response with NaN (the loop has one impact a period:
        # 500 events a period tell Zeno apart as surely as the default 10000, and stop
        # this response at the same instant, t = 1.659, at a twentieth of the cost)
        t = np.linspace(0, 3, 31)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter('always')
            resp = ltp.closed_loop_response(plant, K, orbit, t, orbit.x0 + [0.01, 0.0],
                                            saturation=(-20, 20), max_events=500)
        x = resp.states[0]
        finite = np.isfinite(x)
        assert finite[:6].all() and np.all(np.abs(x[finite]) < 10)
        if not finite.all():
            assert any('diverges' in str(w.message) for w in caught)
            assert not finite[np.argmin(finite):].any()      # NaN from the event on
        assert np.max(np.abs(x[finite] - orbit(t[finite])[0])) > 0.02


class TestDivergence:
    """A destabilising controller: the return map reports it, the simulation stops."""

    @pytest.fixture(scope='class')
    def smooth(self):
        sys = ct.nlsys(lambda t, x, u, p: -x + np.cos(t) + u, None, states=1, inputs=1)
        return sys, ltp.periodic_orbit(sys, 2 * np.pi, [0.0])

    def test_sampled_loop_diverges(self, smooth):
        sys, orbit = smooth
        dt = np.pi / 8
        K = ct.ss([], [], [], [[-50.0]], dt=dt)
        with pytest.warns(UserWarning, match="closed loop diverges"):
            cl = ltp.closed_loop_orbit(sys, K, orbit)
        # zero-order hold: x[k+1] - x̄ = (e^{-dt} - 50 (1 - e^{-dt})) (x[k] - x̄), 16 samples
        a = np.exp(-dt)
        assert not cl.converged and not cl.is_stable
        assert cl.dominant_multiplier == pytest.approx(abs(a - 50 * (1 - a)) ** 16, rel=1e-6)
        assert 'diverges' in repr(cl) and '|mu|' in cl.message

    def test_continuous_loop_diverges(self, smooth):
        sys, orbit = smooth
        with pytest.warns(UserWarning, match="closed loop diverges"):
            cl = ltp.closed_loop_orbit(sys, ct.ss([], [], [], [[10.0]]), orbit)
        assert not cl.converged and not cl.is_stable
        assert cl.dominant_multiplier == pytest.approx(np.exp(9 * 2 * np.pi), rel=1e-6)

    def test_converged_unstable_loop_is_not_a_divergence(self, smooth):
        sys, orbit = smooth
        cl = ltp.closed_loop_orbit(sys, ct.ss([], [], [], [[1.5]]), orbit)
        assert cl.converged and not cl.is_stable
        assert cl.dominant_multiplier == pytest.approx(np.exp(np.pi), rel=1e-8)

    @pytest.mark.parametrize('dt', [0.0, np.pi / 8])
    def test_response_stops(self, smooth, dt):
        sys, orbit = smooth
        K = ct.ss([], [], [], [[10.0 if dt == 0 else -50.0]], dt=dt)
        t = np.linspace(0, 40 * np.pi, 161)
        with pytest.warns(UserWarning, match="closed loop diverges"):
            resp = ltp.closed_loop_response(sys, K, orbit, t, orbit.x0 + 0.01)
        stop = resp.diverged_at
        assert stop is not None and stop < 2 * np.pi + 1e-9
        assert np.all(np.isnan(resp.states[:, t >= stop])) and np.all(resp.modes[t >= stop] == -1)
        assert np.all(np.isfinite(resp.states[:, t < stop]))
        if dt:      # the bound is checked at every sample (every period when continuous)
            assert np.all(np.abs(resp.states[:, t < stop])
                          <= 1e3 * (1 + np.abs(orbit.states).max()))

    def test_stable_response_does_not_stop(self, smooth):
        sys, orbit = smooth
        resp = ltp.closed_loop_response(sys, ct.ss([], [], [], [[-1.0]]), orbit,
                                        np.linspace(0, 4, 9), orbit.x0 + 0.01)
        assert resp.diverged_at is None and np.all(np.isfinite(resp.states))
        with pytest.raises(ValueError, match="max_deviation"):
            ltp.closed_loop_response(sys, ct.ss([], [], [], [[-1.0]]), orbit, [0, 1],
                                     max_deviation=0)


class TestBadInput:
    def test_period_mismatch(self, plant, orbit):
        K = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, 0.7)
        with pytest.raises(ValueError, match="does not divide the orbit period"):
            ltp.closed_loop_response(plant, K, orbit, [0, 1])
        with pytest.raises(ValueError, match="does not divide the orbit period"):
            ltp.closed_loop_orbit(plant, ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, 2.0), orbit)

    def test_sampling_time_must_divide_period(self, plant, orbit):
        with pytest.raises(ValueError, match="does not divide the period"):
            ltp.closed_loop_orbit(plant, ct.ss([[0.5]], [[1]], [[1]], [[0]], 0.3), orbit)

    def test_first_time_must_be_a_sample(self, plant, orbit):
        with pytest.raises(ValueError, match="sampling instant"):
            ltp.closed_loop_response(plant, discrete_controller(0.1), orbit, [0.05, 1.0])

    def test_mismatched_dimensions(self, plant, orbit):
        with pytest.raises(ControlDimension, match="controller must map"):
            ltp.closed_loop_orbit(plant, ct.rss(2, 2, 1), orbit)
        with pytest.raises(ControlDimension, match="controller_state"):
            ltp.closed_loop_response(plant, ltp_controller(), orbit, [0, 1], None, [0, 0])
        with pytest.raises(ControlDimension, match="initial_state"):
            ltp.closed_loop_response(plant, ltp_controller(), orbit, [0, 1], [0, 0, 0])
        with pytest.raises(ControlDimension, match="inputs"):
            ltp.closed_loop_response(plant, ltp_controller(), orbit, [0, 1], noise=[[0, 0]] * 2)

    def test_wrong_types(self, plant, orbit):
        with pytest.raises(ControlArgument, match="controller"):
            ltp.closed_loop_orbit(plant, 'K', orbit)
        with pytest.raises(ControlArgument, match="plant"):
            ltp.closed_loop_orbit('wall', ltp_controller(), orbit)
        with pytest.raises(ValueError, match="different states"):
            ltp.closed_loop_orbit(ct.rss(3, 1, 1), ltp_controller(), orbit)
        with pytest.raises(ControlArgument, match="orbit"):
            ltp.closed_loop_orbit(plant, ltp_controller(), orbit.x0)
        with pytest.raises(ControlArgument, match="saturation"):
            ltp.closed_loop_orbit(plant, ltp_controller(), orbit, saturation=1.0)
        with pytest.raises(ValueError, match="lower < upper"):
            ltp.closed_loop_orbit(plant, ltp_controller(), orbit, saturation=(1.0, -1.0))
        with pytest.raises(TypeError, match="bogus"):
            ltp.closed_loop_response(plant, ltp_controller(), orbit, [0, 1], bogus=1)
        with pytest.raises(ValueError, match="strictly increasing"):
            ltp.closed_loop_response(plant, ltp_controller(), orbit, [1, 0])

    def test_algebraic_loop(self, orbit):
        mode = ltp.HybridMode(lambda t, x, u, p: field(t, x, u[0]),
                              guard=lambda t, x, u, p: x[0],
                              reset=lambda t, x, u, p: impact(x), target=0, name='free')
        through = ltp.HybridPlant([mode], lambda t, x, u, p: [x[0] + u[0]], states=['x', 'v'],
                                  inputs=['u'], outputs=['y'])
        with pytest.raises(ValueError, match="algebraic loop"):
            ltp.closed_loop_orbit(through, ct.ss([], [], [], [[1.0]]), orbit)
