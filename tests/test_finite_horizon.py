"""Finite-horizon Riccati/Lyapunov equations and H2 norm against independent integration."""

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

import ltpcontrol as ltp
from control.exception import ControlDimension


def _data(seed=0, n=3, m=2):
    rng = np.random.default_rng(seed)
    A0, A1 = rng.normal(size=(n, n)), 0.5 * rng.normal(size=(n, n))
    B = rng.normal(size=(n, m))
    T = 1.7
    w = 2 * np.pi / T
    Afun = lambda t: A0 + A1 * np.cos(w * np.asarray(t))[..., None, None]  # noqa: E731
    A = ltp.PeriodicMatrix.from_function(Afun, T)
    Q = np.diag([1.0, 2.0, 0.5])[:n, :n]
    R = np.diag([1.0, 0.3])[:m, :m]
    Xf = np.eye(n) * 0.7
    return A, Afun, B, Q, R, Xf


def _backward(rhs, Xf, t):
    n = Xf.shape[0]
    sol = solve_ivp(lambda s, x: -rhs(s, x.reshape(n, n)).ravel(), (t[-1], t[0]), Xf.ravel(),
                    t_eval=t[::-1], method='DOP853', rtol=1e-13, atol=1e-13)
    return sol.y.T[::-1].reshape(len(t), n, n)


def test_riccati_and_lyapunov_equal_independent_integration():
    A, Afun, B, Q, R, Xf = _data()
    t = np.linspace(0.0, 2.5, 6)
    X = ltp.care_finite(A, B, Q, R, Xf, t)
    S = B @ np.linalg.solve(R, B.T)
    ref = _backward(lambda s, x: Afun(s).T @ x + x @ Afun(s) - x @ S @ x + Q, Xf, t)
    assert np.abs(X - ref).max() <= 1e-10 * np.abs(ref).max()
    Y = ltp.lyap_finite(A, Q, Xf, t)
    ref = _backward(lambda s, x: Afun(s).T @ x + x @ Afun(s) + Q, Xf, t)
    assert np.abs(Y - ref).max() <= 1e-10 * np.abs(ref).max()
    # a long horizon approaches the periodic stabilizing solution of care
    Xp, _, _ = ltp.care(A, B, Q, R)
    Xlong = ltp.care_finite(A, B, Q, R, Xf, [0.0, 20 * A.period])
    assert np.abs(Xlong[0] - Xp(0.0)).max() <= 1e-8 * np.abs(Xp(0.0)).max()


def test_finite_horizon_h2_norm_equals_quadrature_of_the_impulse_responses():
    A, Afun, B, Q, R, Xf = _data(1, n=2, m=1)
    C = np.array([[1.0, -0.5]])
    sys = ltp.ltpss(A, B, C, 0, period=A.period)
    t0, tf = 0.3, 2.0
    # ∫_{t0}^{tf} ∫_s^{tf} |C Φ(t, s) B|² dt ds by independent integration
    def energy(s):
        sol = solve_ivp(lambda t, x: Afun(t) @ x, (s, tf), B[:, 0], method='DOP853',
                        rtol=1e-12, atol=1e-14, dense_output=True)
        return quad(lambda t: float((C @ sol.sol(t))[0] ** 2), s, tf, epsabs=1e-13)[0]
    ref = np.sqrt(quad(energy, t0, tf, epsabs=1e-12, limit=40)[0])
    assert abs(ltp.h2norm_finite(sys, t0, tf) - ref) <= 1e-8 * ref


def test_bad_input():
    A, _, B, Q, R, Xf = _data()
    with pytest.raises(ValueError, match="increasing"):
        ltp.care_finite(A, B, Q, R, Xf, [1.0, 0.5])
    with pytest.raises(ValueError, match="symmetric"):
        ltp.lyap_finite(A, Q, np.triu(np.ones((3, 3))), [0.0, 1.0])
    with pytest.raises(ControlDimension, match='Xf'):
        ltp.care_finite(A, B, Q, R, np.eye(2), [0.0, 1.0])
