"""The banded resolvent solves of an A(t) with few harmonics equal the
modal (eigendecomposition) evaluation of the same harmonic state space."""

import numpy as np

import ltpcontrol as ltp


def test_banded_solves_equal_modal_evaluation():
    rng = np.random.default_rng(0)
    n = 3
    A0 = rng.standard_normal((n, n)) - 2 * np.eye(n)
    A1 = 0.5 * rng.standard_normal((n, n))
    A = ltp.PeriodicMatrix(np.stack([A1 / 2, A0, A1 / 2]).astype(complex), 2 * np.pi)
    sys = ltp.ltpss(A, rng.standard_normal((n, 1)), rng.standard_normal((1, n)), 0.3,
                    period=2 * np.pi)
    s = 1j * np.linspace(-0.5, 0.5, 7) + 0.1
    banded = ltp.htf(sys, 4, method='solve', internal_harmonics=20)(s)   # 123 states
    modal = ltp.htf(sys, 4, method='modal', internal_harmonics=20)(s)
    assert np.abs(banded - modal).max() <= 1e-10 * np.abs(modal).max()


def test_banded_nyquist_count_of_a_periodic_loop():
    # the same loop counted through banded solves (exact Fourier A) and through
    # dense ones (the same A as a callable): equal counts and curves
    rng = np.random.default_rng(1)
    n = 4
    A0 = rng.standard_normal((n, n)) - 1.0 * np.eye(n)
    A1 = 0.8 * rng.standard_normal((n, n))
    B, C = rng.standard_normal((n, 1)), rng.standard_normal((1, n))
    exact = ltp.PeriodicMatrix(np.stack([A1 / 2, A0, A1 / 2]).astype(complex), 2 * np.pi)
    func = ltp.PeriodicMatrix.from_function(lambda t: A0 + A1 * np.cos(t), 2 * np.pi)
    r1 = ltp.nyquist_htf(ltp.ltpss(exact, B, C, 0.5, period=2 * np.pi), 6,
                         internal_harmonics=16)
    r2 = ltp.nyquist_htf(ltp.ltpss(func, B, C, 0.5, period=2 * np.pi), 6,
                         internal_harmonics=16)
    assert r1.closed_loop_unstable == r2.closed_loop_unstable == r1.floquet_unstable
    np.testing.assert_allclose(r1.det[:50], r2.det[:50], rtol=1e-8)
