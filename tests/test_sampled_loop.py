"""Sampled-data loops: ZOH + discrete controller + computation delay around a
continuous periodic plant.

Truths: the closed loop's multipliers from an independent hybrid simulation
over one period (solve_ivp between samples, the controller and the delay
line stepped by hand), and python-control on LTI loops written as periodic.
"""

import control as ct
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

T = 1.0
WP = 2 * np.pi / T


def mathieu_plant():
    """x'' + 0.4 x' + (4 + 3 cos ω_p t) x = u, y = x (period 1)."""
    def A(t):
        return np.array([[0.0, 1.0], [-(4.0 + 3.0 * np.cos(WP * t)), -0.4]])
    Ap = ltp.PeriodicMatrix(np.array([[[0, 0], [-1.5, 0]], [[0, 1], [-4, -0.4]],
                                      [[0, 0], [-1.5, 0]]], complex), T)
    return ltp.ltpss(Ap, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=T), A


def hybrid_multipliers(A, B, C, Kd, Ts, N, delay):
    """Monodromy of the hybrid closed loop u[j] = -v[j - k] over N steps, by hand."""
    n, m = B.shape
    Ac, Bc, Cc, Dc = (np.atleast_2d(np.asarray(M, float)) for M in (Kd.A, Kd.B, Kd.C, Kd.D))
    nc = Ac.shape[0] if Ac.size else 0
    dim = n + nc + delay * m

    def step(j):
        # x(t_{j+1}) = Φ x(t_j) + Γ u_j, integrated independently
        def rhs(t, z):
            Z = z.reshape(n, n + m)
            return np.hstack([A(t) @ Z[:, :n], A(t) @ Z[:, n:] + B]).ravel()
        z0 = np.hstack([np.eye(n), np.zeros((n, m))]).ravel()
        sol = solve_ivp(rhs, (j * Ts, (j + 1) * Ts), z0, method='DOP853', rtol=1e-12,
                        atol=1e-14)
        Z = sol.y[:, -1].reshape(n, n + m)
        return Z[:, :n], Z[:, n:]

    M = np.eye(dim)
    for j in range(N):
        Phi, Gam = step(j)
        # state [x; xc; v_{j-1}, ..., v_{j-k}] -> next step
        S = np.zeros((dim, dim))
        ix, ic, iq = slice(0, n), slice(n, n + nc), slice(n + nc, dim)
        Cy = np.zeros((C.shape[0], dim))
        Cy[:, ix] = C
        v = np.zeros((m, dim))                       # v_j = Cc xc + Dc y_j
        v[:, ic] = Cc if nc else 0
        v += Dc @ Cy
        u = -(v if delay == 0 else np.eye(dim)[n + nc + (delay - 1) * m:
                                                n + nc + delay * m])
        S[ix] = Phi @ np.eye(dim)[ix] + Gam @ u
        if nc:
            S[ic] = Ac @ np.eye(dim)[ic] + Bc @ Cy
        if delay:
            S[n + nc:n + nc + m] = v                 # newest register: v_j
            for r in range(1, delay):
                S[n + nc + r * m:n + nc + (r + 1) * m] = np.eye(dim)[n + nc + (r - 1) * m:
                                                                      n + nc + r * m]
        M = S @ M
    return np.linalg.eigvals(M)


def test_sampled_loop_verdict_and_multipliers_equal_a_hybrid_simulation():
    plant, A = mathieu_plant()
    verdicts = set()
    # even and odd steps per period, delays 0..2, stable and unstable loops
    for N, delay, gain in ((6, 1, 2.0), (5, 2, 5.0), (6, 0, 30.0)):
        Ts = T / N
        Kd = ct.ss(ct.tf([gain * 1.5, -gain * 1.0], [1.0, -0.3], Ts))
        resp = ltp.lifted_nyquist(ltp.sampled_loop(plant, Kd, Ts, delay=delay))
        truth = hybrid_multipliers(A, np.array([[0.0], [1.0]]), np.array([[1.0, 0.0]]),
                                   Kd, Ts, N, delay)
        rho = np.abs(truth).max()
        assert resp.stable == (rho < 1)
        assert np.isclose(np.abs(resp.multipliers).max(), rho, rtol=1e-8)
        assert np.allclose(np.sort_complex(resp.multipliers), np.sort_complex(truth),
                           atol=1e-8)
        assert resp.closed_loop_unstable == int(np.sum(np.abs(truth) > 1))
        verdicts.add(resp.stable)
    assert verdicts == {True, False}


def test_periodic_controller_is_delayed_after_it_acts():
    # a gain alternating between steps: u[j] = -K[j - k] y[j - k], which is not
    # K[j] y[j - k]; the hybrid simulation steps the gain by hand
    plant, A = mathieu_plant()
    N, Ts, delay = 6, 1.0 / 6, 1
    gains = np.array([3.0, 0.5])
    Kp = ltp.ltpss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)),
                   gains.reshape(2, 1, 1), period=2 * Ts, dt=Ts)
    resp = ltp.lifted_nyquist(ltp.sampled_loop(plant, Kp, Ts, delay=delay))
    n, dim = 2, 3
    M = np.eye(dim)
    for j in range(N):
        def rhs(t, z):
            Z = z.reshape(2, 3)
            return np.hstack([A(t) @ Z[:, :2], A(t) @ Z[:, 2:] + [[0.0], [1.0]]]).ravel()
        sol = solve_ivp(rhs, (j * Ts, (j + 1) * Ts), np.hstack([np.eye(2), np.zeros((2, 1))]
                                                               ).ravel(),
                        method='DOP853', rtol=1e-12, atol=1e-14)
        Z = sol.y[:, -1].reshape(2, 3)
        S = np.zeros((dim, dim))
        S[:n, :n], S[:n, n] = Z[:, :2], -Z[:, 2]          # u_j = -v_{j-1}
        S[n, 0] = gains[j % 2]                            # v_j = K[j] y_j
        M = S @ M
    truth = np.linalg.eigvals(M)
    assert np.allclose(np.sort_complex(resp.multipliers), np.sort_complex(truth), atol=1e-8)
    assert resp.stable == (np.abs(truth).max() < 1)


@pytest.mark.parametrize('P, K, delay', [
    (ct.tf([1], [0.1, 1]), ct.tf([2, -1.8], [1, -1], 0.01), 1),           # PI, stable
    (ct.tf([1], [1, -1]), ct.tf([30.0], [1], 0.01), 2),                 # unstable plant
    (ct.tf([4], [1, 1.2, 4]), ct.tf([0.5, 0.2], [1, -0.5], 0.01), 0),
])
def test_lti_sampled_loops_equal_python_control(P, K, delay):
    Ts = 0.01
    L = ltp.sampled_loop(ltp.ltpss(P, period=3 * Ts), K, Ts, delay=delay)
    ref_loop = ct.c2d(P, Ts) * K * ct.tf([1], [1] + [0] * delay, Ts)
    resp = ltp.lifted_nyquist(L)
    want = ct.nyquist_response(ref_loop)
    cl = np.abs(ct.poles(ct.feedback(ref_loop, 1))).max()
    assert resp.stable == (cl < 1)
    # the lifted multipliers are the cubes of the base-rate ones: same P and Z;
    # a pole on the circle (the integrator) is outside our contour (not in P)
    # and inside python-control's (counted in its P)
    poles = np.abs(ct.poles(ref_loop))
    assert resp.open_loop_unstable == int(np.sum(poles > 1 + 1e-9))
    assert resp.closed_loop_unstable == int(np.sum(poles > 1 - 1e-9)) + want.count
    # the margins of such a loop are python-control's: sampled_loop's example


def test_sampled_loop_refuses_bad_input():
    plant, _ = mathieu_plant()
    with pytest.raises(ValueError, match='dt = Ts'):
        ltp.sampled_loop(plant, ct.tf([1.0], [1, 0.5], 0.05), 0.1)
    with pytest.raises(ValueError, match='Ts'):
        ltp.sampled_loop(plant, 2.0, 0.3)                   # 0.3 does not divide 1
    with pytest.raises(ValueError, match='delay'):
        ltp.sampled_loop(plant, 2.0, 0.1, delay=-1)
    with pytest.raises(ct.ControlDimension):
        ltp.sampled_loop(plant, np.ones((2, 1)), 0.1)
    with pytest.raises(ValueError, match='continuous'):
        ltp.sampled_loop(plant.sample(0.1), 2.0, 0.1)
    with pytest.raises(ValueError, match='discrete'):
        ltp.lifted_nyquist(plant)
