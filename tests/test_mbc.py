"""Multi-blade coordinates: algebra, varying rotor speed, inverse transform."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.integrate import solve_ivp

import ltpcontrol as ltp


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 9), st.floats(-10, 10))
def test_coleman_matrix_inverse_and_derivatives(N, psi):
    T = ltp.coleman_matrix(psi, N)
    w = np.full(N, 2.0 / N)
    w[0] = 1.0 / N
    if N % 2 == 0:
        w[-1] = 1.0 / N
    assert np.allclose(np.diag(w) @ T.T @ T, np.eye(N), atol=1e-12)
    h = 1e-5
    d1 = (ltp.coleman_matrix(psi + h, N) - ltp.coleman_matrix(psi - h, N)) / (2 * h)
    d2 = (ltp.coleman_matrix(psi + h, N) - 2 * T + ltp.coleman_matrix(psi - h, N)) / h ** 2
    assert np.allclose(ltp.coleman_matrix(psi, N, 1), d1, atol=1e-8)
    assert np.allclose(ltp.coleman_matrix(psi, N, 2), d2, atol=1e-4)


OM0, DEPTH = 2.0, 0.3
T_REV = 2 * np.pi / OM0


def speed(t):
    """Rotor speed Ω(t) = Ω0 (1 + 0.3 cos Ω0 t): one revolution per period."""
    return OM0 * (1 + DEPTH * np.cos(OM0 * t))


def azimuth(t):
    return OM0 * t + DEPTH * np.sin(OM0 * t)


def rotating_blades():
    """Three blades with a lag spring and a hub coupling through cos ψ_b (states q, q')."""
    def A(t):
        psi = azimuth(t) + 2 * np.pi * np.arange(3) / 3
        K = 4 * np.eye(3) + 0.5 * np.outer(np.cos(psi), np.cos(psi))
        return np.block([[np.zeros((3, 3)), np.eye(3)], [-K, -0.2 * np.eye(3)]])
    return ltp.ltpss(A, np.zeros((6, 1)) + [[0], [0], [0], [1], [0], [0]],
                     np.eye(6)[:1], 0, period=T_REV)


def test_mbc_with_varying_rotor_speed_maps_solutions():
    sys = rotating_blades()
    Om = ltp.PeriodicMatrix.from_function(lambda t: np.array([[speed(t)]]), T_REV)
    nr, P = ltp.mbc(sys, [[0, 1, 2]], 3, rates=[[3, 4, 5]], rotor_speed=Om)
    x0 = np.array([0.1, -0.2, 0.05, 0.3, 0.0, -0.1])

    def state_map(t):
        """x = 𝒯(t) z written out from ψ(t), Ω(t)."""
        T0 = ltp.coleman_matrix(azimuth(t), 3)
        T1 = ltp.coleman_matrix(azimuth(t), 3, 1)
        return np.block([[T0, np.zeros((3, 3))], [speed(t) * T1, T0]])
    times = np.linspace(0, T_REV, 5)
    xs = solve_ivp(lambda t, x: sys.A(t) @ x, (0, times[-1]), x0, t_eval=times,
                   rtol=1e-11, atol=1e-12).y
    z0 = np.linalg.solve(state_map(0.0), x0)
    zs = solve_ivp(lambda t, z: nr.A(t) @ z, (0, times[-1]), z0, t_eval=times,
                   rtol=1e-11, atol=1e-12).y
    for k, t in enumerate(times):
        assert np.allclose(state_map(t) @ zs[:, k], xs[:, k], atol=1e-8)
        assert np.allclose(P(t), state_map(t), atol=1e-10)


def test_inverse_mbc_returns_the_rotating_model():
    sys = rotating_blades()
    Om = ltp.PeriodicMatrix.from_function(lambda t: np.array([[speed(t)]]), T_REV)
    nr, P = ltp.mbc(sys, [[0, 1, 2]], 3, rates=[[3, 4, 5]], rotor_speed=Om)
    back, Pinv = ltp.mbc(nr, [[0, 1, 2]], 3, rates=[[3, 4, 5]], rotor_speed=Om, inverse=True)
    for t in (0.1, 1.7, 2.9):
        assert np.allclose(back.A(t), sys.A(t), atol=1e-10)
        assert np.allclose(back.B(t), sys.B(t)) and np.allclose(back.C(t), sys.C(t))
        assert np.allclose(Pinv(t) @ P(t), np.eye(6), atol=1e-12)
    assert back.frame == 'rotating' and nr.frame == 'multiblade'


def test_blade_inputs_and_outputs_transform():
    # three first-order blades driven by their own pitch inputs, measured per blade
    sys = ltp.ltpss(-np.eye(3), np.eye(3), np.eye(3), 0, period=2 * np.pi)
    nr, _ = ltp.mbc(sys, [[0, 1, 2]], 3, rotating_inputs=[[0, 1, 2]],
                    rotating_outputs=[[0, 1, 2]])
    # collective, cyclic: B and C map coordinates to coordinates
    assert np.allclose(nr.B(0.4), np.eye(3)) and np.allclose(nr.C(0.4), np.eye(3))
    with pytest.raises(ValueError, match="positive"):
        ltp.mbc(sys, [[0, 1, 2]], 3, rotor_speed=-1.0)
