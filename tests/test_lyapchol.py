"""Factored periodic Lyapunov solutions: RᵀR equals `lyap` / `dlyap` to 1e-12."""

import control as ct
import numpy as np
import pytest
from control.exception import ControlDimension

import ltpcontrol as ltp


def _rel(R, X):
    return np.abs(np.swapaxes(R, -1, -2) @ R - X).max() / np.abs(X).max()


@pytest.mark.parametrize("N", [1, 4, 5])
def test_discrete_factor_product_equals_dlyap(N):
    rng = np.random.default_rng(N)
    A = 0.6 * rng.normal(size=(N, 3, 3))
    A /= max(1.0, np.abs(np.linalg.eigvals(np.linalg.multi_dot(list(A[::-1]) + [np.eye(3)])))
             .max() ** (1 / N) / 0.9)                 # multipliers inside the circle
    B, C = rng.normal(size=(N, 3, 2)), rng.normal(size=(N, 1, 3))
    R = ltp.dlyapchol(A, B)
    assert np.array_equal(R, np.triu(R)) and np.all(np.diagonal(R, axis1=1, axis2=2) >= 0)
    assert _rel(R, ltp.dlyap(A, B @ np.swapaxes(B, 1, 2))) <= 1e-12
    R = ltp.dlyapchol(A, C, adjoint=True)
    assert _rel(R, ltp.dlyap(A, np.swapaxes(C, 1, 2) @ C, adjoint=True)) <= 1e-12


def test_continuous_factor_product_equals_lyap():
    rng = np.random.default_rng(7)
    T = 1.3
    A0, A1 = rng.normal(size=(3, 3)) - 4 * np.eye(3), rng.normal(size=(3, 3))
    A = ltp.PeriodicMatrix.from_function(
        lambda t: A0 + A1 * np.cos(2 * np.pi / T * np.asarray(t))[..., None, None], T)
    B, C = rng.normal(size=(3, 2)), rng.normal(size=(2, 3))
    t = np.array([0.0, 0.1234, 0.7, 1.29])           # grid points and between them
    assert _rel(ltp.lyapchol(A, B)(t), ltp.lyap(A, B @ B.T)(t)) <= 1e-12
    assert _rel(ltp.lyapchol(A, C, adjoint=True)(t),
                ltp.lyap(A, C.T @ C, adjoint=True)(t)) <= 1e-12
    # LTI data: python-control's solution
    Al, Bl = np.array([[-1.0, 2.0], [0.0, -3.0]]), np.array([[1.0], [1.0]])
    assert _rel(ltp.lyapchol(Al, Bl, period=1.0)(0.3), ct.lyap(Al, Bl @ Bl.T)) <= 1e-12


def test_bad_input():
    with pytest.raises(ValueError, match="unit circle"):
        ltp.dlyapchol(np.array([[[1.2]], [[0.9]]]), [[1.0]])
    with pytest.raises(ValueError, match="unit circle"):
        ltp.lyapchol([[0.5]], [[1.0]], period=1.0)
    with pytest.raises(ControlDimension, match="B must have"):
        ltp.dlyapchol(np.eye(2), np.ones((3, 1)))
    with pytest.raises(ControlDimension, match="same number of steps"):
        ltp.dlyapchol(np.zeros((2, 2, 2)), np.ones((3, 2, 1)))
    with pytest.raises(ValueError, match="period"):
        ltp.lyapchol([[-1.0]], [[1.0]])
    with pytest.raises(TypeError, match="adjoint"):
        ltp.dlyapchol(np.eye(1) * 0.5, [[1.0]], adjoint=1)


def test_hankel_singular_values_from_the_factors_equal_the_gramians():
    # hsvd uses the factors; the gramians of lyap give the same values
    sys = ltp.ltpss([[-1.0, 0.0], [1.0, -2.0]],
                    lambda t: np.array([[1.0 + 0.5 * np.cos(t)], [0.0]]),
                    [[0.0, 1.0]], 0, period=2 * np.pi)
    t = np.array([0.0, 1.0, np.pi])
    P = ltp.lyap(sys.A, sys.B @ sys.B.T)(t)
    Q = ltp.lyap(sys.A, sys.C.T @ sys.C, adjoint=True)(t)
    ref = np.sqrt(np.sort(np.linalg.eigvals(P @ Q).real, axis=1)[:, ::-1])
    np.testing.assert_allclose(ltp.hsvd(sys, t=t), ref, rtol=1e-10)
