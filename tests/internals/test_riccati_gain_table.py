"""The gain of `ltp.care` is a verified table, or the exact gain when not verified.

Tests of internals: they import private names (see the Developer notes).
"""

import pickle

import control as ct
import numpy as np
import pytest

import ltpcontrol as ltp
from ltpcontrol._analysis import riccati
from ltpcontrol._analysis.riccati import _GainTable

A = np.array([[0.0, 1.0], [2.0, -1.0]])
B = np.array([[0.0], [1.0]])


def test_gain_is_a_table_with_a_scalar_path():
    T = 2 * np.pi
    Ap = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 1.0], [-1 - 0.5 * np.cos(t), 0.1]]), T)
    X, _, G = ltp.care(Ap, B, np.eye(2), [[1.0]])
    assert isinstance(G._func, _GainTable) and G._func.coefs is None      # built on first use
    G(0.1)
    assert G._func.coefs is not None and G._func.exact is None
    t = np.linspace(-T, 2 * T, 97)
    np.testing.assert_allclose(np.array([G._func.scalar(ti) for ti in t]), G._func(t),
                               rtol=0, atol=1e-14)
    # data-backed: picklable although A is a local function
    G2 = pickle.loads(pickle.dumps(G))
    np.testing.assert_array_equal(G2(t), G(t))
    assert G2(0.3).shape == (1, 2)


def test_gain_not_verified_stays_untabulated(monkeypatch, tmp_path):
    monkeypatch.setattr(riccati, '_GAIN_TOL', -1.0)
    monkeypatch.setattr(riccati, '_GAIN_DEPTH', 1)
    X, _, G = ltp.care(A, B, np.eye(2), [[1.0]], period=1.0)
    G0 = ct.care(A, B, np.eye(2), [[1.0]])[2]
    np.testing.assert_allclose(G(0.3), G0, rtol=1e-9)
    np.testing.assert_allclose(G(np.array([0.1, 0.7])), np.stack([G0, G0]), rtol=1e-9)
    assert G._func.coefs is None and G._func.exact is not None
    G2 = pickle.loads(pickle.dumps(G))
    np.testing.assert_allclose(G2(0.3), G0, rtol=1e-9)
    with pytest.raises(TypeError, match="could not be tabulated"):
        ltp.save(tmp_path / 'gain.npz', G)
