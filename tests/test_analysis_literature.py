"""Published periodic-systems examples reproduced by the analysis and design
functions (the facts and numbers of the cited papers; the truths are closed
forms, python-control on LTI data, or brute force computed here)."""

import warnings

import numpy as np
import pytest
import control as ct

import ltpcontrol as ltp

from analysis_systems import lifted as _lifted, pencil_zeros as _pencil_zeros, rotation


def _riccati_residual(A, B, Q, R, X):
    Bt, Xs = np.swapaxes(B, 1, 2), np.roll(X, -1, axis=0)
    res = X - np.swapaxes(A, 1, 2) @ (Xs - Xs @ B @ np.linalg.solve(R + Bt @ Xs @ B, Bt @ Xs)) \
        @ A - Q
    return np.linalg.norm(res) / np.linalg.norm(X)


def _johanson():
    """Johansson et al. (2007): unstable A, B, rotated by P(t) with ω = 2, T = π."""
    A, B = np.array([[1.0, 0.5], [3.0, 5.0]]), np.array([[3.0], [1.0]])
    P, dP = rotation(2, -2.0)         # P = [[cos 2t, sin 2t], [-sin 2t, cos 2t]]
    Pinv = lambda t: np.swapaxes(P(t), -1, -2)
    Ap = ltp.PeriodicMatrix.from_function(lambda t: dP(t) @ Pinv(t) + P(t) @ A @ Pinv(t), np.pi)
    return A, B, P, Pinv, Ap


def test_johansson_periodic_lqr_of_a_rotated_unstable_plant():
    # X_p(t) = P(t)⁻ᵀ X P(t)⁻¹ for Q_p = P⁻ᵀ Q P⁻¹, closed-loop exponents those
    # of the LTI design (Varga's PeriodicMatrixEquations test data)
    A, B, P, Pinv, Ap = _johanson()
    Xref, Lref, Kref = ct.care(A, B, np.eye(2), [[1.0]])
    Bp = ltp.PeriodicMatrix.from_function(lambda t: P(t) @ B, np.pi)
    Qp = ltp.PeriodicMatrix.from_function(lambda t: np.swapaxes(Pinv(t), -1, -2) @ Pinv(t),
                                          np.pi)
    X, L, K = ltp.care(Ap, Bp, Qp, [[1.0]])
    t = np.linspace(0, np.pi, 7)
    Xp = np.swapaxes(Pinv(t), -1, -2) @ Xref @ Pinv(t)
    assert np.allclose(X(t), Xp, rtol=1e-9, atol=1e-9 * np.abs(Xref).max())
    assert np.allclose(K(t), Kref @ Pinv(t), atol=1e-8)
    assert np.allclose(np.sort(L.real), np.sort(np.linalg.eigvals(A - B @ Kref).real),
                       atol=1e-9)


def test_johansson_periodic_kalman_filter_of_the_rotated_plant():
    # dual: C = [3 1], P_p(t) = P(t) X Pᵀ(t) with process noise P Q Pᵀ
    A, _, P, Pinv, Ap = _johanson()
    C = np.array([[3.0, 1.0]])
    Xref, _, _ = ct.care(A.T, C.T, np.eye(2), [[1.0]])
    Cp = ltp.PeriodicMatrix.from_function(lambda t: C @ Pinv(t), np.pi)
    G = ltp.PeriodicMatrix.from_function(P, np.pi)          # noise enters through P(t)
    sys = ltp.ltpss(Ap, G, Cp, 0, period=np.pi)
    L, Pcov, E = ltp.lqe(sys, np.eye(2), [[1.0]])
    t = np.linspace(0, np.pi, 5)
    assert np.allclose(Pcov(t), P(t) @ Xref @ np.swapaxes(P(t), -1, -2), rtol=1e-9,
                       atol=1e-9 * np.abs(Xref).max())
    assert np.allclose(L(t), P(t) @ Xref @ C.T, atol=1e-8 * np.abs(Xref).max())
    assert np.allclose(np.sort(E.real), np.sort(np.linalg.eigvals(A - Xref @ C.T @ C).real),
                       atol=1e-9)


def test_hench_laub_example_2_periodic_riccati():
    # Hench & Laub (IEEE TAC 1994), Example 2: N = 3, n = 3, Q_k = C_kᵀC_k, R = 1
    A = np.array([[[-3, 2, 9], [0, 0, -4], [3, -2, 3]],
                  [[6, -3, 0], [4, -2, 2], [2, -1, 4]],
                  [[2, -3, -3], [4, -15, -3], [-2, 9, 1]]], float)
    B = np.array([[[1], [1], [0]], [[0], [1], [0]], [[0], [1], [1]]], float)
    C = np.eye(3)[:, None, :]
    Q = np.swapaxes(C, 1, 2) @ C
    X, L, G = ltp.dare(A, B, Q, [[1.0]])
    assert _riccati_residual(A, B, Q, np.ones((1, 1)), X) < 1e-13
    # brute force: the backward Riccati recursion run to its periodic steady state
    Xb = np.zeros((3, 3))
    for _ in range(300):
        for k in (2, 1, 0):
            a, b = A[k], B[k]
            Xb = a.T @ Xb @ a - a.T @ Xb @ b @ np.linalg.solve(1 + b.T @ Xb @ b, b.T @ Xb @ a) \
                + Q[k]
            Xb = 0.5 * (Xb + Xb.T)
    assert np.allclose(X[0], Xb, rtol=1e-10, atol=1e-10 * np.abs(Xb).max())
    assert np.isclose(X[0, 0, 0], 1692.72512594, rtol=1e-10)
    mono = (A[2] - B[2] @ G[2]) @ (A[1] - B[1] @ G[1]) @ (A[0] - B[0] @ G[0])
    big = lambda z: np.sort_complex(z[np.abs(z) > 1e-6])
    assert np.allclose(big(L ** 3), big(np.linalg.eigvals(mono)), atol=1e-10)


def test_pitelkau_satellite_periodic_riccati():
    # Pitelkau's magnetically actuated satellite (T = 2π/ω, ω = 0.00103448):
    # undamped (Floquet exponents on the imaginary axis), sampled with 120
    # steps, weighted by R = 1e-11: a badly scaled periodic Riccati equation
    w = 0.00103448
    a = np.array([[0, 0, 5.318064566757217e-02, 0], [0, 0, 0, 5.318064566757217e-02],
                  [-1.352134256362805e-03, 0, 0, -7.099273035392090e-02],
                  [0, -7.557182037479544e-04, 3.781555288420663e-02, 0]])
    b = lambda t: np.array([[0.0], [0.0], [0.1389735e-6 * np.sin(w * t)],
                            [-0.3701336e-7 * np.cos(w * t)]])
    sys = ltp.ltpss(a, b, np.eye(2, 4), np.zeros((2, 1)), period=2 * np.pi / w)
    assert np.all(np.abs(ltp.floquet_exponents(sys).real) < 1e-10)
    assert not ltp.is_stable(sys)
    sysd = ltp.sample_system(sys, sys.period / 120)
    assert np.allclose(np.abs(ltp.floquet_multipliers(sysd)), 1.0, atol=1e-10)
    A, B = sysd.A.sample(120), sysd.B.sample(120)
    q, r = np.diag([2.0, 1.0, 0.0, 0.0]), np.array([[1e-11]])
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        X, L, G = ltp.dare(A, B, q, r)
    assert _riccati_residual(A, B, np.broadcast_to(q, A.shape), r, X) < 1e-12
    assert np.abs(X - np.swapaxes(X, 1, 2)).max() == 0.0
    assert np.all(np.abs(L) < 1)
    K, _, E = ltp.dlqr(sysd, q, r)
    assert np.array_equal(K.sample(120), G) and np.array_equal(E, L)


def test_varga_discrete_poles_and_zeros_example():
    # PeriodicSystems.jl: A_k cycles through three matrices with period 6
    # (N = 6), B_k and C_k through two; per-step poles 2 and 0 (monodromy
    # eigenvalues 64 and 0); zeros^6 are those of the lifted system
    A3 = np.array([[[8.0, 0], [0, 0]], [[1, 1], [1, 1]], [[0, 1], [1, 0]]])
    A = np.concatenate([A3, A3])
    B = np.array([[[1.0], [0]], [[1], [1]]] * 3)
    C = np.array([[[1.0, 1]], [[1, 0]]] * 3)
    D = np.ones((6, 1, 1))
    sys = ltp.ltpss(A, B, C, D, period=6.0, dt=1.0)
    assert np.allclose(np.sort(np.abs(ltp.floquet_exponents(sys))), [0.0, 2.0], atol=1e-12)
    assert not ltp.is_stable(sys)
    z = np.sort_complex(ltp.zeros(sys) ** 6)
    zl = _pencil_zeros(_lifted(A, B, C, D))
    assert len(z) == len(zl) and np.allclose(z, zl, rtol=1e-8, atol=1e-8)


def test_bittanti_colaneri_discrete_norms():
    # Bittanti & Colaneri's example (in Varga's norm tests): A = [[0, 1],
    # [-0.1, 0]], B = [0; 1], C alternating between two rows, N = 2
    A = np.array([[[0.0, 1.0], [-0.1, 0.0]]] * 2)
    B = np.array([[[0.0], [1.0]]] * 2)
    C = np.array([[[-0.25, -0.1]], [[-1.2, 0.3]]])
    D = np.zeros((2, 1, 1))
    sys = ltp.ltpss(A, B, C, D, period=2.0, dt=1.0)
    Gl = _lifted(A, B, C, D)
    assert np.isclose(ltp.norm(sys, 'inf', tol=1e-10), ct.norm(Gl, 'inf', tol=1e-10),
                      rtol=1e-9)
    assert np.isclose(ltp.norm(sys, 2), ct.norm(Gl, 2) / np.sqrt(2), rtol=1e-12)


@pytest.mark.parametrize('D', [0.0, 1.0])
def test_varga_continuous_norms_of_an_lti_plant_and_its_rotation(D):
    # PeriodicSystems.jl norm tests: A0 = [[-1, -0.5], [-3, -5]], B = [3; 1],
    # C = [1 2], D = 0 or 1, as periodic with T = 2π and rotated by ω = 2, T = π
    A0, B0, C0 = np.array([[-1, -0.5], [-3, -5.0]]), np.array([[3.0], [1.0]]), [[1.0, 2.0]]
    G = ct.ss(A0, B0, C0, D)
    P, dP = rotation(2, -2.0)
    Pinv = lambda t: np.swapaxes(P(t), -1, -2)
    rot = ltp.ltpss(ltp.PeriodicMatrix.from_function(
        lambda t: dP(t) @ Pinv(t) + P(t) @ A0 @ Pinv(t), np.pi),
        ltp.PeriodicMatrix.from_function(lambda t: P(t) @ B0, np.pi),
        ltp.PeriodicMatrix.from_function(lambda t: C0 @ Pinv(t), np.pi), D, period=np.pi)
    ref = ct.norm(G, 'inf', tol=1e-10)
    for sys in (ltp.ltpss(G, period=2 * np.pi), rot):
        assert np.isclose(ltp.norm(sys, 'inf', tol=1e-9), ref, rtol=1e-8)
        if D == 0:
            assert np.isclose(ltp.norm(sys, 2), ct.norm(G, 2), rtol=1e-9)
