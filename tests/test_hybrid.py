"""Tests of hybrid plant description, event-detecting simulation and saltation matrices."""

import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

from ltpcontrol import HybridMode, HybridPlant, saltation_matrix, simulate_hybrid
from ltpcontrol import period_map

G = 9.81


def ball(e=0.5):
    """Bouncing ball: free fall, impact at h = 0 with restitution e."""
    air = HybridMode(lambda t, x, u, p: [x[1], -G],
                     guard=lambda t, x, u, p: x[0],
                     reset=lambda t, x, u, p: [x[0], -e * x[1]],
                     target='air', name='air')
    return HybridPlant([air], states=['h', 'v'])


def wall_oscillator(e=0.8, delta=0.1):
    """Forced oscillator hitting a wall that moves as ``w(t) = −0.5 + δ sin t``."""
    def wall(t):
        return -0.5 + delta * np.sin(t)

    def wall_rate(t):
        return delta * np.cos(t)

    free = HybridMode(lambda t, x, u, p: [x[1], -0.2 * x[1] - x[0] + np.cos(t) + u[0]],
                      guard=lambda t, x, u, p: x[0] - wall(t),
                      reset=lambda t, x, u, p: [x[0], wall_rate(t) - e * (x[1] - wall_rate(t))],
                      target=0, name='free')
    return HybridPlant([free], states=2, inputs=1)


def two_mode_switch():
    """Damping on while x > 0, with an extra constant force (discontinuous field)."""
    up = HybridMode(lambda t, x, u, p: [x[1], -x[0] - x[1] + 0.5 + np.cos(t) + u[0]],
                    guard=lambda t, x, u, p: x[0], target='down', name='up')
    down = HybridMode(lambda t, x, u, p: [x[1], -4 * x[0] + np.cos(t) + u[0]],
                      guard=lambda t, x, u, p: -x[0], target='up', name='down')
    return HybridPlant([up, down], states=2, inputs=1)


class TestSimulation:
    def test_bounce_times_and_reset(self):
        e, h0 = 0.5, 1.0
        t1 = np.sqrt(2 * h0 / G)
        v1 = -G * t1
        # second impact after a flight of 2 e |v1| / g
        t2 = t1 + 2 * e * abs(v1) / G
        resp = simulate_hybrid(ball(e), np.linspace(0, 1.0, 101), [h0, 0.0])
        np.testing.assert_allclose(resp.event_times[:2], [t1, t2], rtol=0, atol=1e-10)
        assert resp.event_modes[:2] == [(0, 0), (0, 0)]
        # state right after the bounce: analytic free flight from (0, −e v1)
        k = np.searchsorted(resp.time, t1)
        tau = resp.time[k] - t1
        np.testing.assert_allclose(resp.states[:, k], [-e * v1 * tau - G * tau ** 2 / 2,
                                                       -e * v1 - G * tau], atol=1e-9)
        assert resp.states.shape == (2, 101) and resp.modes.shape == (101,)
        assert resp.mode_names == ['air']

    def test_mode_sequence_and_final_state(self):
        plant = two_mode_switch()
        t = np.linspace(0, 10, 1001)
        resp = simulate_hybrid(plant, t, [0.3, 0.0], 'up')
        # recorded mode agrees with the sign of x away from the events
        away = np.abs(resp.states[0]) > 1e-6
        assert np.all((resp.modes[away] == 0) == (resp.states[0, away] > 0))
        assert len(resp.event_times) >= 3
        assert resp.final_mode == resp.modes[-1]
        np.testing.assert_array_equal(resp.final_state, resp.states[:, -1])
        # event times are zero crossings of x
        for te in resp.event_times:
            k = np.searchsorted(t, te)
            assert np.sign(resp.states[0, k - 1]) != np.sign(resp.states[0, k])

    def test_inputs_array_and_callable_agree(self):
        plant = wall_oscillator()
        t = np.linspace(0, 3, 61)
        u = 0.1 * np.sin(3 * t)
        r1 = simulate_hybrid(plant, t, [0.0, 0.0], inputs=u[np.newaxis], rtol=1e-8)
        r2 = simulate_hybrid(plant, t, [0.0, 0.0], inputs=lambda s: [0.1 * np.sin(3 * s)])
        # linear interpolation of the samples: error ~ 0.1·9·dt²/8
        np.testing.assert_allclose(r1.states, r2.states, atol=5e-4)
        np.testing.assert_allclose(r1.u[0], u)
        r0 = simulate_hybrid(plant, t, [0.0, 0.0])
        assert np.abs(r0.states - r2.states).max() > 1e-2

    def test_zeno_stops(self):
        with pytest.raises(RuntimeError, match="max_events"):
            simulate_hybrid(ball(0.5), np.linspace(0, 3, 31), [1.0, 0.0], max_events=20)

    def test_bad_inputs(self):
        plant = ball()
        with pytest.raises(ValueError, match="timepts"):
            simulate_hybrid(plant, [0, 1, 0.5], [1.0, 0.0])
        with pytest.raises(ControlDimension, match="initial_state"):
            simulate_hybrid(plant, [0, 1], [1.0])
        with pytest.raises(ValueError, match="mode0"):
            simulate_hybrid(plant, [0, 1], [1.0, 0.0], mode0='ground')
        with pytest.raises(TypeError, match="bogus"):
            simulate_hybrid(plant, [0, 1], [1.0, 0.0], bogus=1)
        with pytest.raises(ControlArgument, match="plant"):
            simulate_hybrid("ball", [0, 1], [1.0, 0.0])
        with pytest.raises(ControlDimension, match="inputs"):
            simulate_hybrid(wall_oscillator(), [0, 1, 2], [0.0, 0.0], inputs=[[1.0, 2.0]])
        with pytest.raises(ValueError, match="rtol"):
            simulate_hybrid(plant, [0, 1], [1.0, 0.0], rtol=-1)


class TestDescription:
    def test_mode_validation(self):
        f = lambda t, x, u, p: -x  # noqa: E731
        with pytest.raises(ValueError, match="target"):
            HybridMode(f, guard=lambda t, x, u, p: x[0])
        with pytest.raises(ValueError, match="guard"):
            HybridMode(f, target=0)
        with pytest.raises(ControlArgument, match="reset"):
            HybridMode(f, guard=f, reset=3, target=0)
        with pytest.raises(ControlArgument, match="updfcn"):
            HybridMode(None)

    def test_plant_validation(self):
        f = lambda t, x, u, p: -x  # noqa: E731
        with pytest.raises(ValueError, match="target"):
            HybridPlant([HybridMode(f, guard=f, target='nowhere')], states=1)
        with pytest.raises(ValueError, match="unique"):
            HybridPlant([HybridMode(f, name='a'), HybridMode(f, name='a')], states=1)
        with pytest.raises(ControlArgument, match="modes"):
            HybridPlant([f], states=1)
        with pytest.raises(ValueError, match="outputs"):
            HybridPlant([HybridMode(f)], lambda t, x, u, p: x, states=1)
        with pytest.raises(ControlDimension, match="outputs"):
            HybridPlant([HybridMode(f)], states=2, outputs=1)
        plant = HybridPlant([HybridMode(f)], states=['a', 'b'], inputs=2, name='p')
        assert plant.input_labels == ['u[0]', 'u[1]'] and plant.mode_names == ['mode[0]']
        assert 'p' in repr(plant)

    def test_chart_evaluation(self):
        # the public evaluation methods against the mode functions themselves
        plant, x, u = two_mode_switch(), np.array([0.3, -0.2]), np.array([0.4])
        for i, name in enumerate(plant.mode_names):
            mode = plant.modes[i]
            np.testing.assert_array_equal(plant.dynamics(0.7, x, u, mode=name),
                                          mode.updfcn(0.7, x, u, {}))
            assert plant.guard(0.7, x, u, mode=i) == mode.guard(0.7, x, u, {})
            np.testing.assert_array_equal(plant.reset(0.7, x, u, mode=i), x)
            # central differences against the exact Jacobians of the affine fields
            A = plant.state_jacobian(0.7, x, u, mode=i)
            np.testing.assert_allclose(A @ [1.0, 2.0], plant.dynamics(0.7, x + [1.0, 2.0], u,
                                                                      mode=i)
                                       - plant.dynamics(0.7, x, u, mode=i), atol=1e-8)
            np.testing.assert_allclose(plant.input_jacobian(0.7, x, u, mode=i), [[0.0], [1.0]],
                                       atol=1e-8)
        assert plant.mode_targets == [1, 0]
        np.testing.assert_array_equal(plant.output(0.0, x, u), x)
        b = ball(0.5)
        np.testing.assert_array_equal(b.reset(0.0, [0.0, -2.0], []), [0.0, 1.0])
        with pytest.raises(ValueError, match="no guard"):
            HybridPlant([HybridMode(lambda t, x, u, p: -x)], states=1).guard(0.0, [1.0], [])
        with pytest.raises(ValueError, match="not one of the modes"):
            plant.dynamics(0.0, x, u, mode='sideways')
        with pytest.raises(ControlDimension, match="outfcn"):
            HybridPlant([HybridMode(lambda t, x, u, p: -x)], lambda t, x, u, p: [1.0, 2.0],
                        states=1, outputs=1).output(0.0, [1.0], [])

    def test_wrong_vector_field_size(self):
        plant = HybridPlant([HybridMode(lambda t, x, u, p: [0.0])], states=2)
        with pytest.raises(ControlDimension, match="updfcn"):
            simulate_hybrid(plant, [0, 1], [0.0, 0.0])


class TestSaltation:
    def test_bouncing_ball_closed_form(self):
        e, v = 0.5, -2.0
        S = saltation_matrix(ball(e), 'air', 0.3, [0.0, v])
        np.testing.assert_allclose(S, [[-e, 0], [-(1 + e) * G / v, -e]], atol=1e-8)

    def test_flow_jacobian_across_bounce_matches_finite_differences(self):
        plant, x0, horizon = ball(0.7), np.array([1.0, 0.5]), 0.9   # one bounce
        _, _, J = period_map(plant, horizon, x0, jacobian=True)
        fd = np.empty((2, 2))
        for j in range(2):
            h = np.zeros(2)
            h[j] = 1e-6
            fd[:, j] = (period_map(plant, horizon, x0 + h)[0]
                        - period_map(plant, horizon, x0 - h)[0]) / 2e-6
        np.testing.assert_allclose(J, fd, atol=1e-6)
        # without the saltation matrix the Jacobian would be that of free flight
        assert np.abs(J - [[1, horizon], [0, 1]]).max() > 0.1

    def test_moving_wall_period_map_jacobian(self):
        # time-dependent guard and reset: the ∂g/∂t and ∂r/∂t terms matter
        plant, T = wall_oscillator(), 2 * np.pi
        x0 = np.array([0.1, 0.4])
        x1, _, J = period_map(plant, T, x0, jacobian=True)
        fd = np.empty((2, 2))
        for j in range(2):
            h = np.zeros(2)
            h[j] = 1e-5
            fd[:, j] = (period_map(plant, T, x0 + h)[0] - period_map(plant, T, x0 - h)[0]) / 2e-5
        np.testing.assert_allclose(J, fd, atol=1e-7)

    def test_grazing(self):
        with pytest.raises(ValueError, match="tangent"):
            saltation_matrix(ball(), 0, 0.0, [0.0, 0.0])
        with pytest.warns(UserWarning, match="grazing"):
            saltation_matrix(ball(), 0, 0.0, [0.0, -1e-12])

    def test_bad_arguments(self):
        with pytest.raises(ControlDimension, match="x"):
            saltation_matrix(ball(), 0, 0.0, [0.0])
        plant = HybridPlant([HybridMode(lambda t, x, u, p: -x)], states=1)
        with pytest.raises(ValueError, match="no guard"):
            saltation_matrix(plant, 0, 0.0, [1.0])
        with pytest.raises(ControlArgument, match="plant"):
            saltation_matrix(None, 0, 0.0, [1.0])
