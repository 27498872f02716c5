"""Ill-posed loops (I + D(t) singular at some instant of the period) are
refused by every loop function, with the instant named, and no margin is
reported across a gain that makes the loop ill-posed."""

import numpy as np
import control as ct
import pytest

import ltpcontrol as ltp

LOOP_FUNCTIONS = [
    lambda L: ltp.nyquist_htf(L, 3),
    lambda L: ltp.harmonic_margins(L, 3, check=False),
    lambda L: ltp.stability_margins(L, nharmonics=3),
    lambda L: ltp.sensitivity_htf(L, 2),
    lambda L: ltp.complementary_sensitivity_htf(L, 2),
    lambda L: ltp.siso_equivalent(L, 2, [0.5]),
    lambda L: ltp.feedback(L, 1),
]


@pytest.mark.parametrize("fun", LOOP_FUNCTIONS)
def test_constant_ill_posed_loop_refused(fun):
    # (1 - s)/(s + 2) has D = -1: 1 + D = 0
    L = ltp.ltpss(ct.tf([-1, 1], [1, 2]), period=1.0)
    with pytest.raises(ValueError, match="ill-posed"):
        fun(L)


@pytest.mark.parametrize("fun", LOOP_FUNCTIONS)
def test_periodic_ill_posed_loop_refused_between_samples(fun):
    # 1 + D(t) = 0.5 (1 - cos(t - t0)) vanishes only at t0, between any uniform samples
    t0 = 0.123456789
    D = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[-0.5 - 0.5 * np.cos(t - t0)]]), 2 * np.pi)
    L = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], D, period=2 * np.pi)
    with pytest.raises(ValueError, match=r"ill-posed.*at t = 0\.123457"):
        fun(L)


def test_mimo_ill_posed_instant():
    # 2x2 D(t) with det(I + D(t)) changing sign at t = 1 and t = 2π - 1
    D = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 1 + np.cos(t) - np.cos(1.0)], [1.0, 0.0]]), 2 * np.pi)
    L = ltp.ltpss(np.zeros((2, 2)) - np.eye(2), np.eye(2), np.eye(2), D, period=2 * np.pi)
    with pytest.raises(ValueError, match=r"at t = (1\b|5\.28319)"):
        ltp.nyquist_htf(L, 2)


def test_gain_margin_ends_at_an_ill_posed_gain():
    # D(t) = -0.4 - 0.3 cos(t - 0.3): I + k D(t) singular first at k = 1/0.7
    D = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[-0.4 - 0.3 * np.cos(t - 0.3)]]), 2 * np.pi)
    L = ltp.ltpss([[-1.0]], [[1.0]], [[0.1]], D, period=2 * np.pi)
    m = ltp.harmonic_margins(L, 5)
    assert abs(m.gain_upper.value - 1 / 0.7) < 1e-9
    assert m.gain_upper.frequency == np.inf
    with pytest.raises(ValueError, match="ill-posed"):
        ltp.feedback(ltp.series(L, m.gain_upper.value), 1)
    # just inside, the closed loop exists and is stable
    assert ltp.is_stable(ltp.feedback(ltp.series(L, 0.999 * m.gain_upper.value), 1))
    assert all(g.value < 1 / 0.7 for g in m.gain_crossings)


def test_nonzero_feedthrough_is_not_a_truncation_edge():
    # a constant D fills the edge blocks of L̂_N exactly: no edge warning
    import warnings
    G = ct.tf([0.5, 3], [1, 2])
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        m = ltp.harmonic_margins(ltp.ltpss(G, period=0.5), 4)
    assert m.gain_upper.value == np.inf
