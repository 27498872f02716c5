"""Tests of periodic orbits, period-map Jacobians and LTP linearisation about orbits."""

import control as ct
import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

from ltpcontrol import HybridMode, HybridPlant
from ltpcontrol import LTPStateSpace
from ltpcontrol import PeriodicOrbit, linearize_orbit, period_map, periodic_orbit
from systems import fd_period_map_jacobian

T = 2 * np.pi
K_S, C_D, BETA = 2.0, 0.5, 0.5


def duffing(t, x, u, p):
    """ẍ + c ẋ + k x + β x³ = F(t) + u with F chosen so that x̄(t) = cos t."""
    forcing = (K_S - 1) * np.cos(t) - C_D * np.sin(t) + BETA * np.cos(t) ** 3
    return [x[1], -C_D * x[1] - K_S * x[0] - BETA * x[0] ** 3 + forcing + u[0]]


def duffing_jacobian(t, x, u, p):
    return np.array([[0.0, 1.0], [-K_S - 3 * BETA * x[0] ** 2, -C_D]])


@pytest.fixture(scope='module')
def duffing_sys():
    return ct.nlsys(duffing, lambda t, x, u, p: x[:1], states=['x', 'v'], inputs=['u'],
                    outputs=['y'], name='duffing')


@pytest.fixture(scope='module')
def duffing_orbit(duffing_sys):
    return periodic_orbit(duffing_sys, T, [0.0, 0.0], npoints=64)


class TestSmoothOrbit:
    def test_orbit_matches_closed_form(self, duffing_orbit):
        orbit = duffing_orbit
        t = orbit.time
        np.testing.assert_allclose(orbit.x0, [1.0, 0.0], atol=1e-9)
        np.testing.assert_allclose(orbit.states, [np.cos(t), -np.sin(t)], atol=1e-9)
        np.testing.assert_allclose(orbit(7.3), [np.cos(7.3), -np.sin(7.3)], atol=1e-9)
        assert orbit.residual <= 1e-10 and orbit.switching_times.size == 0
        assert orbit.mode_sequence == [0] and isinstance(orbit, PeriodicOrbit)

    def test_monodromy_matches_finite_differences(self, duffing_sys, duffing_orbit):
        fd = fd_period_map_jacobian(duffing_sys, T, duffing_orbit.x0)
        np.testing.assert_allclose(duffing_orbit.monodromy, fd, atol=1e-7)
        assert duffing_orbit.is_stable == bool(np.all(np.abs(duffing_orbit.multipliers) < 1))
        # Liouville: det Φ(T) = exp(∫ tr A) = exp(−c T)
        assert np.isclose(np.linalg.det(duffing_orbit.monodromy), np.exp(-C_D * T), rtol=1e-8)

    def test_linearization_matches_analytic_jacobians(self, duffing_sys, duffing_orbit):
        lin = linearize_orbit(duffing_sys, duffing_orbit)
        assert isinstance(lin, LTPStateSpace) and lin.period == T
        assert lin.state_labels == ['x', 'v'] and lin.output_labels == ['y']
        for t in [0.0, 0.7, 2.9, 5.5]:
            np.testing.assert_allclose(lin.A(t), duffing_jacobian(t, [np.cos(t)], None, None),
                                       atol=1e-7)
            np.testing.assert_allclose(lin.B(t), [[0.0], [1.0]], atol=1e-8)
            np.testing.assert_allclose(lin.C(t), [[1.0, 0.0]], atol=1e-8)
            np.testing.assert_allclose(lin.D(t), [[0.0]], atol=1e-8)

    def test_floquet_multipliers_match_period_map(self, duffing_sys, duffing_orbit):
        lin = linearize_orbit(duffing_sys, duffing_orbit)
        fd = fd_period_map_jacobian(duffing_sys, T, duffing_orbit.x0)
        expected = np.sort_complex(np.linalg.eigvals(fd))
        np.testing.assert_allclose(np.sort_complex(lin.floquet_multipliers()), expected,
                                   atol=1e-6)

    def test_analytic_jacobian_option(self, duffing_sys, duffing_orbit):
        orbit = periodic_orbit(duffing_sys, T, [0.5, 0.5], jacobian=duffing_jacobian)
        np.testing.assert_allclose(orbit.x0, [1.0, 0.0], atol=1e-9)
        np.testing.assert_allclose(orbit.monodromy, duffing_orbit.monodromy, atol=1e-8)

    def test_unstable_orbit_is_found_and_flagged(self):
        # ẋ = x + cos t has the single (repelling) periodic solution (sin t − cos t)/2
        sys = ct.nlsys(lambda t, x, u, p: x + np.cos(t), None, states=1, inputs=0)
        orbit = periodic_orbit(sys, T, [0.3])
        np.testing.assert_allclose(orbit.x0, [-0.5], atol=1e-10)
        assert not orbit.is_stable
        np.testing.assert_allclose(orbit.multipliers, [np.exp(T)], rtol=1e-8)

    def test_constant_input_u0(self):
        # ẋ = −x + cos t + u0: the orbit shifts by u0
        sys = ct.nlsys(lambda t, x, u, p: -x + np.cos(t) + u[0], None, states=1, inputs=1)
        orbit = periodic_orbit(sys, T, [0.0], u0=[2.0])
        np.testing.assert_allclose(orbit.x0, [2.5], atol=1e-9)


class TestHybridOrbit:
    @staticmethod
    def plant():
        """Forced oscillator with a lossy and a stiffer lossless mode (discontinuous field)."""
        up = HybridMode(lambda t, x, u, p: [x[1], -x[0] - x[1] + 0.5 + np.cos(t) + u[0]],
                        guard=lambda t, x, u, p: x[0], target='down', name='up')
        down = HybridMode(lambda t, x, u, p: [x[1], -4 * x[0] + np.cos(t) + u[0]],
                          guard=lambda t, x, u, p: -x[0], target='up', name='down')
        return HybridPlant([up, down], states=2, inputs=1, name='switcher')

    def test_saltation_jacobian_matches_finite_differences(self):
        plant = self.plant()
        orbit = periodic_orbit(plant, T, [0.3, 0.0], 'up')
        assert len(orbit.switching_times) == 2
        assert [plant.mode_names[i] for i in orbit.mode_sequence][:2] in (['up', 'down'],
                                                                          ['down', 'up'])
        fd = fd_period_map_jacobian(plant, T, orbit.x0, orbit.mode0)
        np.testing.assert_allclose(orbit.monodromy, fd, atol=1e-5)
        # the force jump at x = 0 makes the saltation matrices non-trivial
        assert all(np.abs(S - np.eye(2)).max() > 1e-2 for S in orbit.saltation_matrices)
        # the orbit is periodic: simulating it once returns to x0
        np.testing.assert_allclose(period_map(plant, T, orbit.x0, orbit.mode0)[0], orbit.x0,
                                   atol=1e-9)

    def test_time_switching_linearization(self):
        plant = self.plant()
        orbit = periodic_orbit(plant, T, [0.3, 0.0], 'up')
        with pytest.warns(UserWarning, match="freezes the orbit's 2 events"):
            lin = linearize_orbit(plant, orbit)
        t_up = [t for t in np.linspace(0, T, 50, endpoint=False)
                if orbit(t)[0] > 1e-3]
        t_down = [t for t in np.linspace(0, T, 50, endpoint=False) if orbit(t)[0] < -1e-3]
        for t in t_up[:3]:
            np.testing.assert_allclose(lin.A(t), [[0, 1], [-1, -1]], atol=1e-7)
        for t in t_down[:3]:
            np.testing.assert_allclose(lin.A(t), [[0, 1], [-4, 0]], atol=1e-7)
        np.testing.assert_allclose(lin.A.breakpoints, np.sort(np.append(orbit.switching_times,
                                                                       0.0)))
        # the time-switching model ignores the saltation: its monodromy differs
        assert np.abs(lin.monodromy() - orbit.monodromy).max() > 1e-2
        with pytest.warns(UserWarning, match="multipliers"):
            avg = linearize_orbit(plant, orbit, piecewise_constant=True)
        np.testing.assert_allclose(avg.monodromy(), lin.monodromy(), atol=1e-8)


class TestBadInput:
    def test_non_periodic_forcing(self):
        sys = ct.nlsys(lambda t, x, u, p: -x + np.cos(1.1 * t), None, states=1, inputs=0)
        with pytest.raises(ValueError, match="not periodic with period"):
            periodic_orbit(sys, T, [0.0])

    def test_non_periodic_guard(self):
        mode = HybridMode(lambda t, x, u, p: [x[1], -x[0] + np.cos(t)],
                          guard=lambda t, x, u, p: x[0] + 0.1 * t, target=0)
        with pytest.raises(ValueError, match="guard .* not periodic|guard of mode"):
            periodic_orbit(HybridPlant([mode], states=2), T, [0.0, 0.0])

    def test_guard_never_crossed(self):
        mode = HybridMode(lambda t, x, u, p: [x[1], -x[0] - x[1] + np.cos(t)],
                          guard=lambda t, x, u, p: x[0] + 100.0, target=0, name='free')
        with pytest.warns(UserWarning, match="no guard is crossed"):
            orbit = periodic_orbit(HybridPlant([mode], states=2), T, [0.0, 0.0])
        np.testing.assert_allclose(orbit.x0, [0.0, 1.0], atol=1e-9)

    def test_no_periodic_orbit(self):
        # undamped resonance: x(t) grows like t sin t, there is no periodic solution
        sys = ct.nlsys(lambda t, x, u, p: [x[1], -x[0] + np.cos(t)], None, states=2, inputs=0)
        with pytest.raises(RuntimeError, match="Newton.*forward simulation"):
            periodic_orbit(sys, T, [0.0, 0.0], max_periods=20)

    def test_argument_checks(self, duffing_sys, duffing_orbit):
        with pytest.raises(TypeError, match="bogus"):
            periodic_orbit(duffing_sys, T, [0.0, 0.0], bogus=True)
        with pytest.raises(ValueError, match="period"):
            periodic_orbit(duffing_sys, -1.0, [0.0, 0.0])
        with pytest.raises(ControlDimension, match="x0"):
            periodic_orbit(duffing_sys, T, [0.0])
        with pytest.raises(ControlArgument, match="plant"):
            periodic_orbit(np.eye(2), T, [0.0, 0.0])
        with pytest.raises(ValueError, match="tol"):
            periodic_orbit(duffing_sys, T, [0.0, 0.0], tol=2.0)
        with pytest.raises(ControlDimension, match="u0"):
            periodic_orbit(duffing_sys, T, [0.0, 0.0], u0=[1.0, 2.0])
        dsys = ct.nlsys(duffing, None, states=2, inputs=1, dt=0.1)
        with pytest.raises(ValueError, match="continuous-time"):
            periodic_orbit(dsys, T, [0.0, 0.0])
        with pytest.raises(ControlArgument, match="orbit"):
            linearize_orbit(duffing_sys, "orbit")
        with pytest.raises(TypeError, match="bogus"):
            linearize_orbit(duffing_sys, duffing_orbit, bogus=1)
        with pytest.raises(ControlArgument, match="jacobian"):
            period_map(duffing_sys, T, [0.0, 0.0], jacobian='yes')
        autonomous = ct.nlsys(lambda t, x, u, p: -x + np.cos(t), None, states=1, inputs=0)
        orbit = periodic_orbit(autonomous, T, [0.0])
        with pytest.raises(ValueError, match="no inputs"):
            linearize_orbit(autonomous, orbit)
