"""Periodic Sylvester equations against independent integration and the LTI solver."""

import numpy as np
import pytest
import scipy.linalg as la
from scipy.integrate import solve_ivp

import ltpcontrol as ltp
from control.exception import ControlDimension


def test_continuous_periodic_sylvester_equals_independent_integration():
    rng = np.random.default_rng(0)
    n, m, T = 3, 2, 1.4
    w = 2 * np.pi / T
    A0, A1 = rng.normal(size=(n, n)) - 2 * np.eye(n), 0.5 * rng.normal(size=(n, n))
    B0, C0 = rng.normal(size=(m, m)) + 0.5 * np.eye(m), rng.normal(size=(n, m))
    Af = lambda t: A0 + A1 * np.sin(w * np.asarray(t))[..., None, None]  # noqa: E731
    Cf = lambda t: C0 * (1 + np.cos(2 * w * np.asarray(t)))[..., None, None]  # noqa: E731
    A = ltp.PeriodicMatrix.from_function(Af, T)
    C = ltp.PeriodicMatrix.from_function(Cf, T)
    X = ltp.sylvester(A, B0, C)
    t = np.array([0.0, 0.37, 0.9, T])
    sol = solve_ivp(lambda s, x: (Af(s) @ x.reshape(n, m) + x.reshape(n, m) @ B0
                                  + Cf(s)).ravel(), (0, T), X(0.0).ravel(), t_eval=t,
                    method='DOP853', rtol=1e-13, atol=1e-13)
    ref = sol.y.T.reshape(len(t), n, m)
    assert np.abs(X(t) - ref).max() <= 1e-10 * np.abs(ref).max()
    # LTI data: the algebraic Sylvester equation
    Xc = ltp.sylvester(A0, B0, C0, period=T)
    np.testing.assert_allclose(Xc(0.2), la.solve_sylvester(A0, B0, -C0), rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("N", [1, 4, 5])
def test_discrete_periodic_sylvester_residual_and_dense_solution(N):
    rng = np.random.default_rng(N)
    A, B = rng.normal(size=(N, 3, 3)), 0.5 * rng.normal(size=(N, 2, 2))
    C = rng.normal(size=(N, 3, 2))
    X = ltp.dsylvester(A, B, C)
    res = X[(np.arange(N) + 1) % N] - (A @ X @ B + C)
    assert np.abs(res).max() <= 1e-12 * max(1.0, np.abs(X).max())
    # independent: fixed point of the period map x -> Φ x + c by a dense solve
    M, c = np.eye(6), np.zeros(6)
    for k in range(N):
        step = np.kron(A[k], B[k].T)
        M, c = step @ M, step @ c + C[k].ravel()
    x0 = np.linalg.solve(np.eye(6) - M, c)
    np.testing.assert_allclose(X[0].ravel(), x0, rtol=1e-9, atol=1e-12)


def test_not_unique_is_refused():
    with pytest.raises(ValueError, match="unique"):
        ltp.dsylvester(np.array([[[2.0]]]), np.array([[[0.5]]]), np.ones((1, 1, 1)))
    with pytest.raises(ControlDimension, match='C must'):
        ltp.dsylvester(np.eye(2), np.eye(1), np.ones((1, 1)))
