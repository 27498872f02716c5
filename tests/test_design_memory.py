"""Periodic LQR/Kalman/LQG on stiff plants: bounded memory, gains tabulated when designed."""

import time
import tracemalloc

import numpy as np

import ltpcontrol as ltp

T = 1.0


def _stiff_plant():
    # slow periodic (Mathieu-like) dynamics and a fast pole at -300/T: the solver grid
    # exceeds the 256 steps on which gains are tabulated directly
    def A(t):
        t = np.asarray(t, float)
        a = np.zeros(np.shape(t) + (3, 3))
        a[..., 0, 1] = 1.0
        a[..., 1, 0] = -(2 * np.pi) ** 2 * (1 + 0.3 * np.cos(2 * np.pi * t / T))
        a[..., 1, 1] = -0.5
        a[..., 0, 2] = 0.5
        a[..., 2, 0] = 1.0
        a[..., 2, 2] = -300.0 / T
        return a
    return ltp.ltpss(A, [[0.0], [1.0], [1.0]], [[1.0, 0.0, 1.0]], 0, period=T)


def test_stiff_lqr_lqe_lqg_bounded_and_tabulated_when_designed():
    sys = _stiff_plant()
    tracemalloc.start()
    try:
        K, X, E = ltp.lqr(sys, np.eye(3), [[1.0]])
        L, P, EL = ltp.lqe(sys, [[1.0]], [[0.01]])
        peak_design = tracemalloc.get_traced_memory()[1]
        tracemalloc.reset_peak()
        t = np.linspace(0, T, 1001)
        start = time.process_time()
        Kt, Lt = K(t), L(t)
        evaluation = time.process_time() - start
        peak_eval = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    # the unbounded version stacked sub-steps proportional to the stiffness
    # (hundreds of MB); the bounded one stays within a few tens of MB
    assert peak_design < 60e6, peak_design
    assert peak_eval < 5e6, peak_eval
    assert evaluation < 1.0                    # a table look-up, not a Riccati flow
    # the tables equal the exact gains R⁻¹BᵀX(t) and P(t)Cᵀ RN⁻¹ (X, P exact flows)
    ts = np.array([0.1234, 0.377, 0.61, 0.9])
    Kx = np.array([[0.0, 1.0, 1.0]]) @ X(ts)
    Lx = P(ts) @ np.array([[1.0], [0.0], [1.0]]) / 0.01
    assert np.abs(K(ts) - Kx).max() <= 1e-8 * np.abs(Kx).max()
    assert np.abs(L(ts) - Lx).max() <= 1e-8 * np.abs(Lx).max()
    assert np.all(np.isfinite(Kt)) and np.all(np.isfinite(Lt))
    assert np.all(E.real < 0) and np.all(EL.real < 0)
    assert E.real.min() < -250                  # the fast pole is kept
