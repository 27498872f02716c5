"""Graded Floquet factors of stiff periodic systems (private helpers)."""

import numpy as np
import pytest

import ltpcontrol as ltp
from ltpcontrol._core.fastform import fast_form
from ltpcontrol._core.graded import ordered_schur, stiff_log_multipliers
from ltpcontrol._core.periodic_schur import product_eigenvalues
from ltpcontrol._core.steps import floquet_norm
from ltpcontrol._core.transition import uniform_transitions


def _lagged_oscillators(stiff, seed=0):
    """Two coupled Mathieu oscillators driving two lags at -stiff (no feedback)."""
    rng = np.random.default_rng(seed)
    w = 2 * np.pi
    drive = rng.standard_normal((2, 2))
    lags = -stiff * (1 + 0.5 * rng.random(2))

    def A(t):
        K = np.array([[1.0 + 0.3 * np.cos(w * t), 0.2], [0.2, 2.3 + 0.2 * np.sin(2 * w * t)]])
        out = np.zeros((6, 6))
        out[:2, 2:4] = np.eye(2)
        out[2:4, :2] = -w ** 2 * K
        out[2:4, 2:4] = -0.3 * np.eye(2)
        out[4:, 2:4] = drive
        out[4:, 4:] = np.diag(lags)
        return out
    # its exact Fourier form (harmonics 0-2), as the library evaluates it
    return fast_form(ltp.PeriodicMatrix.from_function(A, 1.0)), lags


@pytest.mark.parametrize('band', [4.0, 16.0])
def test_ordered_schur_orders_the_bands(band):
    rng = np.random.default_rng(1)
    V = rng.standard_normal((7, 7))
    X = V @ np.diag([-1.0, -300.0, -2.0, -40.0, -600.0, 0.5, -41.0]) @ np.linalg.inv(V)
    S, U = ordered_schur(X, band)
    levels = np.floor(np.diag(S) / band)
    assert np.all(np.diff(levels) <= 0)
    assert np.allclose(U @ S @ U.T, X, atol=1e-10 * np.abs(X).max())
    assert np.allclose(U.T @ U, np.eye(7), atol=1e-13)


def test_stiff_exponents_keep_their_relative_accuracy():
    # multipliers e^{-3e4}: the lag rates are the exact exponents
    A, lags = _lagged_oscillators(3e4)
    logmod, _ = stiff_log_multipliers(A, floquet_norm(A))
    assert np.allclose(np.sort(logmod)[:2], np.sort(lags), rtol=1e-12, atol=0)


def test_graded_factors_agree_with_the_plain_factors():
    # moderately stiff: plain factors of spread <= 1 resolve everything too
    A, _ = _lagged_oscillators(300.0)
    grid = np.linspace(0, 1, 601)
    plain, _ = product_eigenvalues(uniform_transitions(A, grid[:-1], np.diff(grid)))
    graded, _ = stiff_log_multipliers(A, floquet_norm(A))
    assert np.abs(plain - graded).max() <= 1e-12 * np.abs(plain).max()
