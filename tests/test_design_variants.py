"""Output-weighted LQR and the representatives of the closed-loop exponents on LTI data."""

import control as ct
import numpy as np
import pytest

import ltpcontrol as ltp


def _plant(seed):
    rng = np.random.default_rng(seed)
    A = np.array([[0.0, 9.0, 0.0], [-9.0, -0.2, 1.0], [0.3, 0.0, -1.0]])   # fast oscillation
    B, C = rng.normal(size=(3, 2)), rng.normal(size=(2, 3))
    D = 0.3 * rng.normal(size=(2, 2))
    return A, B, C, D


def test_output_weighted_lqr_equals_python_control():
    A, B, C, D = _plant(0)
    Qy, R = np.diag([2.0, 1.0]), np.diag([1.0, 0.5])
    K, X, E = ltp.lqr(ltp.ltpss(A, B, C, D, period=1.3), Qy, R, output=True)
    K0, X0, E0 = ct.lqr(A, B, C.T @ Qy @ C, R + D.T @ Qy @ D, C.T @ Qy @ D)
    assert np.abs(K(0.3) - K0).max() <= 1e-10 * np.abs(K0).max()
    assert np.abs(X(0.3) - X0).max() <= 1e-10 * np.abs(X0).max()
    G = ct.ss(A, B, C, D)
    Gd = ct.c2d(G, 0.1)
    Kd, Xd, _ = ltp.dlqr(ltp.ltpss(Gd, period=0.3), Qy, R, output=True)
    K0, X0, _ = ct.dlqr(Gd.A, Gd.B, Gd.C.T @ Qy @ Gd.C, R + Gd.D.T @ Qy @ Gd.D,
                        Gd.C.T @ Qy @ Gd.D)
    assert np.abs(Kd(0.1) - K0).max() <= 1e-10 * np.abs(K0).max()
    with pytest.raises(ct.ControlArgument, match="integral_action"):
        ltp.lqr(ltp.ltpss(A, B, C, D, period=1.3), Qy, R, output=True,
                integral_action=np.eye(3)[:1])


def _sorted(E):
    return E[np.lexsort((E.imag, E.real))]


@pytest.mark.parametrize("T", [0.25, 1.3])
def test_lti_exponents_are_those_of_the_loop_built_from_the_gain(T):
    # |Im λ| = 9 exceeds ω_p/2 for T = 1.3: the representative matters
    A, B, C, _ = _plant(1)
    sys = ltp.ltpss(A, B, C, 0, period=T)
    K, _, E = ltp.lqr(sys, np.eye(3), np.eye(2))
    L, _, EL = ltp.lqe(sys, np.eye(2), np.eye(2))
    assert K.is_constant and L.is_constant
    loop = ltp.ltpss(sys.A - sys.B @ K, sys.B, sys.C, 0, period=T)
    np.testing.assert_allclose(_sorted(E), _sorted(ltp.floquet_exponents(loop)), atol=1e-9)
    est = ltp.ltpss(sys.A - L @ sys.C, sys.B, sys.C, 0, period=T)
    np.testing.assert_allclose(_sorted(EL), _sorted(ltp.floquet_exponents(est)), atol=1e-9)
    sysd = ltp.ltpss(ct.c2d(ct.ss(A, B, C, 0), T / 4), period=T)
    Kd, _, Ed = ltp.dlqr(sysd, np.eye(3), np.eye(2))
    Ld, _, ELd = ltp.dlqe(sysd, np.eye(2), np.eye(2))
    loopd = ltp.ltpss(sysd.A - sysd.B @ Kd, sysd.B, sysd.C, 0, period=T, dt=T / 4)
    estd = ltp.ltpss(sysd.A - Ld @ sysd.C, sysd.B, sysd.C, 0, period=T, dt=T / 4)
    np.testing.assert_allclose(_sorted(Ed), _sorted(ltp.floquet_exponents(loopd)), atol=1e-9)
    np.testing.assert_allclose(_sorted(ELd), _sorted(ltp.floquet_exponents(estd)), atol=1e-9)


def test_kalman_gain_with_separate_noise_inputs_and_feedthrough_equals_python_control():
    A, B, C, D = _plant(2)
    rng = np.random.default_rng(7)
    G, Dw = rng.normal(size=(3, 2)), 0.5 * rng.normal(size=(2, 2))
    QN, RN = np.diag([1.0, 0.4]), np.diag([0.2, 0.1])
    RNe, NNe = RN + Dw @ QN @ Dw.T, QN @ Dw.T
    L, P, E = ltp.lqe(ltp.ltpss(A, B, C, D, period=0.9), QN, RN, G=G, Dw=Dw)
    # python-control's lqe has no cross covariance: its dual care does
    P0, _, K0 = ct.care(A.T, C.T, G @ QN @ G.T, RNe, G @ NNe)
    L0 = K0.T
    assert L.is_constant
    assert np.abs(L(0.2) - L0).max() <= 1e-9 * np.abs(L0).max()
    assert np.abs(P(0.2) - P0).max() <= 1e-9 * np.abs(P0).max()
    Gd = ct.c2d(ct.ss(A, B, C, D), 0.1)
    Ld, Pd, _ = ltp.dlqe(ltp.ltpss(Gd, period=0.3), QN, RN, G=G)
    L0, P0, _ = ct.dlqe(Gd.A, G, Gd.C, QN, RN)
    assert np.abs(Ld(0.1) - L0).max() <= 1e-9 * np.abs(L0).max()
    # with Dw: the correlated problem through B = G (python-control's dlqe has no NN)
    Ld, _, _ = ltp.dlqe(ltp.ltpss(Gd, period=0.3), QN, RN, G=G, Dw=Dw)
    Lx, _, _ = ltp.dlqe(ltp.ltpss(Gd.A, G, Gd.C, 0, period=0.3, dt=0.1), QN, RNe, NNe)
    assert np.abs(Ld(0.1) - Lx(0.1)).max() <= 1e-12 * np.abs(Lx(0.1)).max()
    with pytest.raises(ct.ControlDimension, match="G must have"):
        ltp.lqe(ltp.ltpss(A, B, C, D, period=0.9), QN, RN, G=G[:2])
