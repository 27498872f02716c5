"""The gain of `ltp.care` is a verified table, or the exact gain when not verified.

Tests of internals: they import private names (see the Developer notes).
"""

import pickle

import control as ct
import numpy as np
import pytest

import ltpcontrol as ltp
from ltpcontrol._analysis import gain_table
from ltpcontrol._analysis.gain_table import _GainTable

A = np.array([[0.0, 1.0], [2.0, -1.0]])


class riccati_untabulated:
    """Context in which gain tables are never verified (the exact gain is kept)."""

    def __enter__(self):
        self.saved = gain_table._GAIN_TOL, gain_table._GAIN_DEPTH
        gain_table._GAIN_TOL, gain_table._GAIN_DEPTH = -1.0, 0

    def __exit__(self, *exc):
        gain_table._GAIN_TOL, gain_table._GAIN_DEPTH = self.saved
B = np.array([[0.0], [1.0]])


def test_gain_is_a_table_with_a_scalar_path():
    T = 2 * np.pi
    Ap = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 1.0], [-1 - 0.5 * np.cos(t), 0.1]]), T)
    X, _, G = ltp.care(Ap, B, np.eye(2), [[1.0]])
    assert isinstance(G._func, _GainTable)                    # tabulated when designed
    assert G._func.coefs is not None and G._func.exact is None
    t = np.linspace(-T, 2 * T, 97)
    np.testing.assert_allclose(np.array([G._func.scalar(ti) for ti in t]), G._func(t),
                               rtol=0, atol=1e-14)
    # data-backed: picklable although A is a local function
    G2 = pickle.loads(pickle.dumps(G))
    np.testing.assert_array_equal(G2(t), G(t))
    assert G2(0.3).shape == (1, 2)


def test_gain_not_verified_stays_untabulated(monkeypatch, tmp_path):
    monkeypatch.setattr(gain_table, '_GAIN_TOL', -1.0)
    monkeypatch.setattr(gain_table, '_GAIN_DEPTH', 1)
    Ap = ltp.PeriodicMatrix.from_function(lambda t: A + 1e-9 * np.cos(2 * np.pi * t), 1.0)
    with pytest.warns(UserWarning, match="could not be verified"):
        X, _, G = ltp.care(Ap, B, np.eye(2), [[1.0]])
    G0 = ct.care(A, B, np.eye(2), [[1.0]])[2]
    np.testing.assert_allclose(G(0.3), G0, rtol=1e-7)
    np.testing.assert_allclose(G(np.array([0.1, 0.7])), np.stack([G0, G0]), rtol=1e-7)
    assert G._func.coefs is None and G._func.exact is not None
    G2 = pickle.loads(pickle.dumps(G))
    np.testing.assert_allclose(G2(0.3), G0, rtol=1e-7)
    with pytest.raises(TypeError, match="could not be tabulated"):
        ltp.save(tmp_path / 'gain.npz', G)


def test_lqe_gain_is_a_table_like_lqr():
    T = 2 * np.pi
    sys = ltp.ltpss(lambda t: np.array([[0.0, 1.0], [-1 - 0.5 * np.cos(t), -0.1]]),
                    [[0.0], [1.0]], [[1.0, 0.0]], 0, period=T)
    with riccati_untabulated():
        L_exact, _, _ = ltp.lqe(sys, [[1.0]], [[0.1]])
    exact = L_exact._func.exact
    L, P, _ = ltp.lqe(sys, [[1.0]], [[0.1]])
    assert isinstance(L._func, _GainTable)                  # tabulated when designed
    assert L._func.coefs is not None and L._func.exact is None
    t = np.random.default_rng(1).uniform(-T, 2 * T, 41)
    np.testing.assert_allclose(L(t), exact(t), rtol=0, atol=1e-9 * np.abs(exact(t)).max())
    # L = P Cᵀ R⁻¹ of the filter Riccati solution
    np.testing.assert_allclose(L(t), P(t) @ np.array([[1.0], [0.0]]) / 0.1,
                               rtol=0, atol=1e-8 * np.abs(L(t)).max())
    np.testing.assert_allclose(np.array([L._func.scalar(ti) for ti in t]), L(t),
                               rtol=0, atol=1e-14)
    assert L(0.3).shape == (2, 1)
    L2 = pickle.loads(pickle.dumps(L))           # data-backed although A is a local function
    np.testing.assert_array_equal(L2(t), L(t))


def test_lqe_gain_table_equals_python_control():
    A, C = np.array([[0.0, 1.0], [-2.0, -0.3]]), np.array([[1.0, 0.5]])
    sys = ltp.ltpss(A, B, C, 0, period=0.7)
    L, _, _ = ltp.lqe(sys, [[1.0]], [[0.2]])
    L0 = ct.lqe(ct.ss(A, B, C, 0), [[1.0]], [[0.2]])[0]
    t = np.random.default_rng(2).uniform(0, 0.7, 25)
    assert L.is_constant                         # LTI data: a constant gain
    assert np.abs(L(t) - L0).max() <= 1e-10 * np.abs(L0).max()
    assert max(np.abs(L(ti) - L0).max() for ti in t) <= 1e-10 * np.abs(L0).max()
