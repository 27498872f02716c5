"""Periodic Riccati equations, LQR, Kalman filters and LQG.

Truths: python-control on LTI plants written as periodic; Lyapunov-
transformed LTI plants (closed forms); the Riccati differential equation by
finite differences; simulated closed-loop costs.
"""

import warnings

import numpy as np
import control as ct
import pytest
from control.exception import ControlArgument, ControlDimension
from hypothesis import assume, given, settings, strategies as st
import scipy.linalg as la
from scipy.integrate import simpson

import ltpcontrol as ltp

from systems import switching_mathieu


def _rand(seed, n, m, p):
    rng = np.random.default_rng(seed)
    return (rng.standard_normal((n, n)), rng.standard_normal((n, m)),
            rng.standard_normal((p, n)), rng)


def _sorted(z):
    return np.sort_complex(np.round(np.asarray(z, complex), 12))


#
# LTI embedding
#

@pytest.mark.parametrize("period", [0.3, 2.0])
def test_lqr_lqe_care_equal_python_control(period):
    A, B, C, rng = _rand(1, 4, 2, 2)
    Q, R = np.diag([1.0, 2, 3, 4]), np.array([[2.0, 0.3], [0.3, 1.0]])
    N = 0.2 * rng.standard_normal((4, 2))
    sys = ltp.ltpss(A, B, C, 0, period=period)
    K, X, E = ltp.lqr(sys, Q, R, N)
    K0, X0, _ = ct.lqr(A, B, Q, R, N)
    t = np.array([0.0, 0.17, 0.61]) * period
    assert np.abs(K(t) - K0).max() < 1e-8 * np.abs(K0).max()
    assert np.abs(X(t) - X0).max() < 1e-8 * np.abs(X0).max()
    # closed-loop eigenvalues recomputed (ct.lqr returns them in single precision)
    eig = np.linalg.eigvals(A - B @ K0)
    np.testing.assert_allclose(_sorted(np.exp(E * period)), _sorted(np.exp(eig * period)),
                               atol=1e-9)
    Xc, Lc, Gc = ltp.care(A, B, Q, R, N, period=period)
    Xc0, _, Gc0 = ct.care(A, B, Q, R, N)
    assert np.abs(Xc(t) - Xc0).max() < 1e-8 * np.abs(Xc0).max()
    assert np.abs(Gc(t) - Gc0).max() < 1e-8 * np.abs(Gc0).max()
    L, P, EL = ltp.lqe(sys, np.diag([1.0, 0.5]), np.eye(2))
    L0, P0, _ = ct.lqe(ct.ss(A, B, C, 0), np.diag([1.0, 0.5]), np.eye(2))
    assert np.abs(L(t) - L0).max() < 1e-8 * np.abs(L0).max()
    assert np.abs(P(t) - P0).max() < 1e-8 * np.abs(P0).max()
    np.testing.assert_allclose(_sorted(np.exp(EL * period)),
                               _sorted(np.exp(np.linalg.eigvals(A - L0 @ C) * period)),
                               atol=1e-9)


@pytest.mark.parametrize("nsteps", [1, 2, 5])
def test_dlqr_dlqe_dare_equal_python_control(nsteps):
    A, B, C, rng = _rand(2, 3, 2, 2)
    A *= 0.8
    Q, R = np.eye(3), np.diag([1.0, 3.0])
    N = 0.1 * rng.standard_normal((3, 2))
    sysd = ltp.ltpss(A, B, C, 0, period=0.1 * nsteps, dt=0.1)
    K, X, E = ltp.lqr(sysd, Q, R, N)        # dispatches to dlqr, as python-control
    K0, X0, _ = ct.dlqr(A, B, Q, R, N)
    assert np.abs(K.sample(nsteps) - K0).max() < 1e-10
    assert np.abs(X.sample(nsteps) - X0).max() < 1e-10 * np.abs(X0).max()
    eig = np.linalg.eigvals(A - B @ K0)
    np.testing.assert_allclose(_sorted(E ** nsteps), _sorted(eig ** nsteps), atol=1e-10)
    Xd, Ld, Gd = ltp.dare(A, B, Q, R, N)
    Xd0, _, Gd0 = ct.dare(A, B, Q, R, N)
    assert np.abs(Xd[0] - Xd0).max() < 1e-10 * np.abs(Xd0).max()
    L, P, EL = ltp.dlqe(sysd, np.eye(2), np.diag([0.5, 2.0]))
    L0, P0, _ = ct.dlqe(ct.ss(A, B, C, 0, 0.1), np.eye(2), np.diag([0.5, 2.0]))
    assert np.abs(L.sample(nsteps) - L0).max() < 1e-10
    assert np.abs(P.sample(nsteps) - P0).max() < 1e-10 * np.abs(P0).max()
    np.testing.assert_allclose(_sorted(EL ** nsteps),
                               _sorted(np.linalg.eigvals(A - L0 @ C) ** nsteps), atol=1e-10)


#
# Lyapunov-transformed LTI plants: x_p = P(t) x with a rotation P
#

def _rotation(theta, n):
    out = np.broadcast_to(np.eye(n), np.shape(theta) + (n, n)).copy()
    c, s = np.cos(theta), np.sin(theta)
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    return out


def test_lyapunov_transformed_continuous_plant():
    n, m, p = 3, 2, 1
    A0, B0, C0, _ = _rand(3, n, m, p)
    T = 1.5
    w = 2 * np.pi / T
    J = np.zeros((n, n))
    J[0, 1], J[1, 0] = -w, w                     # Ṗ P⁻¹ for the rotation P(t)
    Pt = lambda t: _rotation(w * np.asarray(t), n)          # noqa: E731
    A = ltp.PeriodicMatrix.from_function(lambda t: J + Pt(t) @ A0 @ np.swapaxes(Pt(t), -1, -2), T)
    B = ltp.PeriodicMatrix.from_function(lambda t: Pt(t) @ B0, T)
    C = ltp.PeriodicMatrix.from_function(lambda t: C0 @ np.swapaxes(Pt(t), -1, -2), T)
    sys = ltp.ltpss(A, B, C, 0, period=T)
    R = np.diag([1.0, 0.5])
    K, X, E = ltp.lqr(sys, np.eye(n), R)
    K0, X0, _ = ct.lqr(A0, B0, np.eye(n), R)
    t = np.linspace(0, T, 7)
    P = Pt(t)
    Pinv = np.swapaxes(P, 1, 2)
    assert np.abs(X(t) - np.swapaxes(Pinv, 1, 2) @ X0 @ Pinv).max() < 1e-9 * np.abs(X0).max()
    assert np.abs(K(t) - K0 @ Pinv).max() < 1e-9 * np.abs(K0).max()
    eig = np.linalg.eigvals(A0 - B0 @ K0)
    np.testing.assert_allclose(np.sort(E.real), np.sort(eig.real), atol=1e-9)
    np.testing.assert_allclose(_sorted(np.exp(E * T)), _sorted(np.exp(eig * T)), atol=1e-9)
    # Kalman dual: P_cov(t) = P P0 Pᵀ, L(t) = P L0
    L, Pc, EL = ltp.lqe(sys, np.eye(m), [[0.3]])
    L0, P0, _ = ct.lqe(ct.ss(A0, B0, C0, 0), np.eye(m), [[0.3]])
    assert np.abs(Pc(t) - P @ P0 @ Pinv).max() < 1e-9 * np.abs(P0).max()
    assert np.abs(L(t) - P @ L0).max() < 1e-9 * np.abs(L0).max()
    np.testing.assert_allclose(np.sort(EL.real), np.sort(np.linalg.eigvals(A0 - L0 @ C0).real),
                               atol=1e-9)


@pytest.mark.parametrize("nsteps", [4, 7])
def test_lyapunov_transformed_discrete_plant(nsteps):
    n, m, p = 3, 1, 2
    A0, B0, C0, _ = _rand(4, n, m, p)
    A0 *= 0.9
    P = _rotation(2 * np.pi * np.arange(nsteps + 1) / nsteps, n)     # P_N = P_0 = I
    Pt = np.swapaxes(P, 1, 2)
    A = P[1:] @ A0 @ Pt[:-1]                     # A_p[k] = P_{k+1} A0 P_k⁻¹
    sysd = ltp.ltpss(A, P[1:] @ B0, C0 @ Pt[:-1], 0, period=nsteps * 0.05, dt=0.05)
    K, X, E = ltp.dlqr(sysd, np.eye(n), [[0.7]])
    K0, X0, _ = ct.dlqr(A0, B0, np.eye(n), [[0.7]])
    assert np.abs(X.sample(nsteps) - P[:-1] @ X0 @ Pt[:-1]).max() < 1e-9 * np.abs(X0).max()
    assert np.abs(K.sample(nsteps) - K0 @ Pt[:-1]).max() < 1e-9 * np.abs(K0).max()
    np.testing.assert_allclose(_sorted(E ** nsteps),
                               _sorted(np.linalg.eigvals(A0 - B0 @ K0) ** nsteps), atol=1e-9)
    L, Pc, EL = ltp.dlqe(sysd, [[1.0]], np.eye(p))
    L0, P0, _ = ct.dlqe(ct.ss(A0, B0, C0, 0, 1), [[1.0]], np.eye(p))
    assert np.abs(Pc.sample(nsteps) - P[:-1] @ P0 @ Pt[:-1]).max() < 1e-9 * np.abs(P0).max()
    assert np.abs(L.sample(nsteps) - P[1:] @ L0).max() < 1e-9 * np.abs(L0).max()
    np.testing.assert_allclose(_sorted(EL ** nsteps),
                               _sorted(np.linalg.eigvals(A0 - L0 @ C0) ** nsteps), atol=1e-9)


#
# Genuinely periodic plants
#

def _riccati_ode_residual(sys, Q, R, X, times, h=1e-4):
    """max |−Ẋ − (AᵀX + XA − XBR⁻¹BᵀX + Q)| / max |X|, Ẋ by 4th-order differences."""
    Xd = (8 * (X(times + h) - X(times - h)) - X(times + 2 * h) + X(times - 2 * h)) / (12 * h)
    A, B, Xt = sys.A(times), sys.B(times), X(times)
    At = np.swapaxes(A, 1, 2)
    rhs = At @ Xt + Xt @ A - Xt @ B @ np.linalg.solve(R, np.swapaxes(B, 1, 2) @ Xt) + Q
    return np.abs(Xd + rhs).max() / np.abs(Xt).max()


def test_care_switching_plant_satisfies_the_riccati_ode():
    sys = switching_mathieu()
    Q, R = np.eye(2), np.array([[0.5]])
    K, X, E = ltp.lqr(sys, Q, R)
    times = np.array([0.03, 0.11, 0.2, 0.31, 0.44])      # away from the switch at 0.25
    assert _riccati_ode_residual(sys, Q, R, X, times) < 1e-9
    # X is continuous across the switch and periodic
    assert np.abs(X(0.25 - 1e-9) - X(0.25 + 1e-9)).max() < 1e-6
    assert np.abs(X(0.0) - X(0.5)).max() < 1e-12
    assert np.all(E.real < 0)
    # exponents equal those of the closed loop built with feedback
    loop = ltp.feedback(ltp.ltpss(sys.A, sys.B, np.eye(2), 0, period=0.5), K)
    np.testing.assert_allclose(_sorted(ltp.floquet_exponents(loop)), _sorted(E), atol=1e-8)


@pytest.mark.slow
def test_care_stiff_plant():
    # exponents 0 and -24 open loop, plus a fast mode at -300 (multiplier e^-1885)
    T = 2 * np.pi
    A1 = np.zeros((3, 3), complex)
    A1[1, :2] = [-5.0, 5.0j]                     # -10 cos t, -10 sin t
    A = ltp.PeriodicMatrix([A1.conj(), [[0, 1, 0], [0, -24, 1], [0, 0, -300]], A1], T)
    sys = ltp.ltpss(A, [[0.0], [1.0], [1.0]], np.eye(3), 0, period=T)
    Q, R = np.eye(3), np.array([[1.0]])
    K, X, E = ltp.lqr(sys, Q, R)
    assert np.all(np.isfinite(E)) and np.all(E.real < 0)
    assert np.min(E.real) < -290                 # the fast mode kept its exponent
    times = np.array([0.4, 1.9, 3.3, 5.1])
    assert _riccati_ode_residual(sys, Q, R, X, times) < 1e-9
    assert np.abs(X(0.0) - X(T)).max() < 1e-12


def test_mathieu_lqr_cost_by_simulation_and_no_better_constant_gain():
    T = 0.5
    wp, wn, zeta, beta = 2 * np.pi / T, 2 * np.pi, 0.05, 0.4
    A = ltp.PeriodicMatrix([[[0, 0], [-0.5 * beta * wn ** 2, 0]],
                            [[0, 1], [-wn ** 2, -2 * zeta * wn]],
                            [[0, 0], [-0.5 * beta * wn ** 2, 0]]], T)
    B = ltp.PeriodicMatrix([[[0.0], [0.4]], [[0.0], [1.0]], [[0.0], [0.4]]], T)
    sys = ltp.ltpss(A, B, np.eye(2), 0, period=T)
    Q, R = np.eye(2), np.array([[0.1]])
    K, X, E = ltp.lqr(sys, Q, R)
    x0 = np.array([1.0, -0.5])
    t = np.linspace(0, 30 * T, 30 * 200 + 1)

    def cost(gain):
        resp = ltp.forced_response(ltp.feedback(sys, gain), t, 0.0, x0)
        x = resp.states
        Kt = gain(t) if isinstance(gain, ltp.PeriodicMatrix) else np.broadcast_to(gain, (len(t), 1, 2))
        u = -np.einsum('tij,jt->it', Kt, x)
        assert np.abs(x[:, -1]).max() < 1e-4 * np.abs(x0).max()      # decayed
        return simpson(np.einsum('it,ij,jt->t', x, Q, x) + np.einsum('it,ij,jt->t', u, R, u),
                       x=t)

    optimal = x0 @ X(0.0) @ x0
    assert ltp.is_stable(ltp.feedback(sys, K))
    assert abs(cost(K) - optimal) < 1e-6 * optimal
    gains = [ct.lqr(sys.average(), Q, R)[0]] + [ct.lqr(sys.linearize(s), Q, R)[0]
                                                for s in (0.0, 0.1)]
    for gain in gains:
        assert cost(gain) > optimal * (1 + 1e-3)


def test_lqg_separation_and_discrete_closed_loop():
    A = lambda t: np.array([[0.0, 1.0], [1 + 0.5 * np.cos(t), -0.1]])   # noqa: E731
    sys = ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi)
    ctrl = ltp.lqg(sys, np.eye(2), [[1.0]], [[1.0]], [[0.1]], name='lqg')
    loop = ltp.feedback(sys, ctrl, sign=1)
    _, _, EK = ltp.lqr(sys, np.eye(2), [[1.0]])
    _, _, EL = ltp.lqe(sys, [[1.0]], [[0.1]])
    got = ltp.floquet_exponents(loop)
    np.testing.assert_allclose(np.sort(got.real), np.sort(np.concatenate([EK, EL]).real),
                               atol=1e-8)
    assert ctrl.name == 'lqg' and ctrl.input_labels == sys.output_labels
    sysd = ltp.sample_system(sys, 2 * np.pi / 8)
    ctrld = ltp.lqg(sysd, np.eye(2), [[1.0]], [[1.0]], [[0.1]])
    loopd = ltp.feedback(sysd, ctrld, sign=1)
    _, _, EKd = ltp.dlqr(sysd, np.eye(2), [[1.0]])
    _, _, ELd = ltp.dlqe(sysd, [[1.0]], [[0.1]])
    np.testing.assert_allclose(np.sort(np.abs(ltp.floquet_multipliers(loopd))),
                               np.sort(np.abs(np.concatenate([EKd, ELd]) ** 8)), atol=1e-10)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 10_000), N=st.integers(1, 6), n=st.integers(1, 4),
       m=st.integers(1, 3))
def test_dare_periodic_residual_and_weights_per_step(seed, N, n, m):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((N, n, n))
    B = rng.standard_normal((N, n, m))
    Q = np.stack([np.diag(rng.uniform(0.5, 2, n)) for _ in range(N)])
    R = np.stack([np.diag(rng.uniform(0.5, 2, m)) for _ in range(N)])
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', UserWarning)
        X, L, G = ltp.dare(A, B, Q, R)
    # a nearly uncontrollable draw (X ~ 1/σ_min² of the reachability) is
    # ill-conditioned: see test_dare_nearly_uncontrollable_plant
    assume(np.abs(X).max() < 1e6)
    for k in range(N):
        Xn = X[(k + 1) % N]
        rhs = A[k].T @ Xn @ A[k] - A[k].T @ Xn @ B[k] @ np.linalg.solve(
            R[k] + B[k].T @ Xn @ B[k], B[k].T @ Xn @ A[k]) + Q[k]
        assert np.abs(X[k] - rhs).max() < 1e-9 * np.abs(X).max()
        assert np.linalg.eigvalsh(X[k]).min() > 0
    mono = np.eye(n)
    for k in range(N):
        mono = (A[k] - B[k] @ G[k]) @ mono
    assert np.max(np.abs(L)) < 1
    np.testing.assert_allclose(_sorted(np.linalg.eigvals(mono)), _sorted(L ** N),
                               atol=1e-9 * max(1.0, np.abs(mono).max()))


def test_dare_nearly_uncontrollable_plant():
    # the reachability matrix has singular values 2.4 and 5e-5: X ~ 7e9 and
    # the closed loop is far from normal, so the Kronecker form of the
    # refinement's Stein equation is numerically singular; the solution must
    # still come, as accurate as scipy's, with a warning
    rng = np.random.default_rng(7255)
    A, B = rng.standard_normal((1, 2, 2)), rng.standard_normal((1, 2, 1))
    Q = np.diag(rng.uniform(0.5, 2, 2))[None]
    R = np.diag(rng.uniform(0.5, 2, 1))[None]
    with pytest.warns(UserWarning, match="nearly uncontrollable"):
        X, L, G = ltp.dare(A, B, Q, R)
    Xs = la.solve_discrete_are(A[0], B[0], Q[0], R[0])

    def residual(X):
        rhs = A[0].T @ X @ A[0] - A[0].T @ X @ B[0] @ np.linalg.solve(
            R[0] + B[0].T @ X @ B[0], B[0].T @ X @ A[0]) + Q[0]
        return np.abs(X - rhs).max() / np.abs(X).max()
    assert residual(X[0]) <= residual(Xs)
    assert np.abs(X[0] - Xs).max() < 1e-4 * np.abs(Xs).max()
    np.testing.assert_allclose(np.sort(np.abs(L)),
                               np.sort(np.abs(la.eigvals(A[0] - B[0] @ G[0]))), rtol=1e-6)
    assert np.max(np.abs(L)) < 1


#
# Bad input
#

def test_bad_input_names_the_argument():
    sys = ltp.ltpss([[1.0, 0.0], [0.0, 2.0]], [[1.0], [0.0]], np.eye(2), 0, period=1.0)
    with pytest.raises(ValueError, match="stabilizing"):
        ltp.lqr(sys, np.eye(2), [[1.0]])                  # mode 2 unreachable, unstable
    good = ltp.ltpss([[0.0, 1.0], [2.0, 0.0]], [[0.0], [1.0]], np.eye(2), 0, period=1.0)
    with pytest.raises(ValueError, match="R must be positive definite"):
        ltp.lqr(good, np.eye(2), [[-1.0]])
    with pytest.raises(ValueError, match="Q must be symmetric"):
        ltp.lqr(good, [[1.0, 1.0], [0.0, 1.0]], [[1.0]])
    with pytest.raises(ControlDimension, match="R must have shape"):
        ltp.lqr(good, np.eye(2), np.eye(2))
    with pytest.raises(ValueError, match="period"):
        ltp.lqr(good, ltp.PeriodicMatrix.constant(np.eye(2), np.sqrt(2)), [[1.0]])
    with pytest.raises(ControlArgument, match="sys must be an LTPStateSpace"):
        ltp.lqr(ct.ss(good.A(0), good.B(0), np.eye(2), 0), np.eye(2), [[1.0]])
    with pytest.raises(ValueError, match="RN must be positive definite"):
        ltp.lqe(good, [[1.0]], [[0.0, 0.0], [0.0, 0.0]])
    sysd = ltp.ltpss(np.eye(2) * 1.5, [[1.0], [0.0]], np.eye(2), 0, period=2.0, dt=1.0)
    with pytest.raises(ValueError, match="stabilizing"):
        ltp.dlqr(sysd, np.eye(2), [[1.0]])
    with pytest.raises(ValueError, match=r"Q \(101 steps\), R \(103 steps\) have"):
        ltp.dlqr(sysd, np.ones((101, 2, 2)), np.ones((103, 1, 1)))
    with pytest.raises(ValueError, match=r"A \(101 steps\), B \(103 steps\)"):
        ltp.dare(np.ones((101, 2, 2)), np.ones((103, 2, 1)), np.eye(2), [[1.0]])
    with pytest.raises(ControlArgument, match="period must be given"):
        ltp.care(np.eye(2), np.ones((2, 1)), np.eye(2), [[1.0]])
    with pytest.raises(ControlArgument, match="dlqr"):
        ltp.dlqr(good, np.eye(2), [[1.0]])


#
# Tabulated gains
#

def _untabulated_gain(B, R, S, X, t):
    t = np.atleast_1d(t)
    return np.linalg.solve(R(t), np.swapaxes(B(t), 1, 2) @ X(t) + np.swapaxes(S(t), 1, 2))


def test_gain_table_equals_untabulated_gain_with_varying_data():
    T = 2 * np.pi
    A = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 1.0], [-1 - 0.5 * np.cos(t), 0.1]]), T)
    B = ltp.PeriodicMatrix([[[0.0], [0.15j]], [[0.0], [1.0]], [[0.0], [-0.15j]]], T)
    R = ltp.PeriodicMatrix([[[0.25]], [[1.0]], [[0.25]]], T)
    S = ltp.PeriodicMatrix.constant([[0.1], [0.0]], T)
    X, _, G = ltp.care(A, B, np.eye(2), R, S)
    t = np.concatenate([np.random.default_rng(3).uniform(-3 * T, 3 * T, 300),
                        G.breakpoints[:5], G.breakpoints[:5] + 7 * T, [0.0, T, -T]])
    exact = _untabulated_gain(B, R, S, X, t)
    scale = 1 + np.abs(exact).max()
    assert np.abs(G(t) - exact).max() <= 1e-9 * scale
    scalar = np.array([G(float(ti)) for ti in t])
    assert np.abs(scalar - exact).max() <= 1e-9 * scale
    assert np.abs(scalar - G(t)).max() <= 1e-14 * scale
    for ti in (1, np.float64(0.7), np.int64(2), -0.4):
        assert G(ti).shape == (1, 2)
        np.testing.assert_allclose(G(ti), _untabulated_gain(B, R, S, X, float(ti))[0],
                                   rtol=0, atol=1e-9 * scale)


def test_gain_table_of_switching_data_is_right_continuous():
    sys = switching_mathieu()
    K, X, _ = ltp.lqr(sys, np.eye(2), [[1.0]])
    zero = ltp.PeriodicMatrix.constant(np.zeros((2, 1)), sys.period)
    one = ltp.PeriodicMatrix.constant([[1.0]], sys.period)
    t = np.concatenate([[0.0, 0.25, 0.5, 0.75, -0.25], np.linspace(-1, 1, 203)])
    exact = _untabulated_gain(ltp.PeriodicMatrix.constant([[0.0], [1.0]], sys.period),
                              one, zero, X, t)
    assert np.abs(K(t) - exact).max() <= 1e-9 * (1 + np.abs(exact).max())
    assert np.abs(np.array([K(ti) for ti in t]) - exact).max() <= 1e-9 * (1 + np.abs(exact).max())


def test_gain_table_of_lti_data_equals_python_control():
    A, B, _, _ = _rand(4, 3, 2, 1)
    Q, R = np.diag([1.0, 2.0, 0.5]), np.array([[1.0, 0.2], [0.2, 2.0]])
    K0 = ct.lqr(A, B, Q, R)[0]
    K, _, _ = ltp.lqr(ltp.ltpss(A, B, np.eye(3), 0, period=0.7), Q, R)
    t = np.random.default_rng(5).uniform(-5, 5, 50)
    assert np.abs(K(t) - K0).max() <= 1e-10 * np.abs(K0).max()
    assert max(np.abs(K(ti) - K0).max() for ti in t) <= 1e-10 * np.abs(K0).max()



def test_lqe_gain_table_of_switching_data():
    sys = switching_mathieu()
    L, P, _ = ltp.lqe(sys, [[1.0]], [[0.1]])
    t = np.concatenate([[0.0, 0.25, 0.5, 0.75, -0.25], np.linspace(-1, 1, 203)])
    exact = P(t) @ np.swapaxes(sys.C(t), 1, 2) / 0.1
    assert np.abs(L(t) - exact).max() <= 1e-9 * (1 + np.abs(exact).max())
    assert np.abs(np.array([L(ti) for ti in t]) - exact).max() <= 1e-9 * (1 + np.abs(exact).max())
