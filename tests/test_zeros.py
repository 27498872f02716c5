"""Zeros of LTP systems: LTI limit, Lyapunov transforms and published examples."""

import numpy as np
import pytest
import control as ct
from control.exception import ControlDimension

import ltpcontrol as ltp
from analysis_systems import stable_rss, transformed, zhou_hagiwara_A


def _match(z, ref, tol):
    from scipy.optimize import linear_sum_assignment
    z, ref = np.atleast_1d(z), np.atleast_1d(ref)
    if z.shape != ref.shape:
        return False
    cost = np.abs(z[:, None] - ref[None, :])
    rows, cols = linear_sum_assignment(cost)
    return cost[rows, cols].max(initial=0.0) <= tol


@pytest.mark.parametrize('T', [0.3, 0.9])
def test_zeros_lti_continuous(T):
    # zeros with |Im| < ω_p/2, so the strip holds them unshifted
    G = stable_rss(4, 2, 2, seed=11)
    ref = ct.zeros(G)
    assert np.abs(ref.imag).max() < np.pi / T
    z = ltp.zeros(ltp.ltpss(G, period=T))
    assert _match(z, ref, 1e-9 * max(1, np.abs(ref).max()))
    assert _match(ct.zeros(ltp.ltpss(G, period=T)), ref, 1e-9 * max(1, np.abs(ref).max()))


@pytest.mark.parametrize('N', [3, 4])
def test_zeros_lti_discrete(N):
    G = stable_rss(3, 2, 2, seed=20 + N, dt=0.1)
    ref = ct.zeros(G)
    z = ltp.zeros(ltp.ltpss(G, period=0.1 * N))
    # per-step values are principal N-th roots: compare the period values z^N
    assert _match(z ** N, ref ** N, 1e-9)


@pytest.mark.parametrize('seed', [4, 6])
def test_zeros_lyapunov_transformed(seed):
    G = stable_rss(3, 1, 1, seed=seed)
    sys, _ = transformed(G, 1.0)
    assert _match(ltp.zeros(sys), ct.zeros(G), 1e-9)


def test_zeros_bittanti_colaneri():
    # Periodic Systems (2009) p. 26: zero = mean of (-2 + 3 sin t)/(2 - sin t) = -3 + 4/√3
    A = ltp.PeriodicMatrix([[[0.5j, 0], [-0.5, 0]], [[-1, 0], [1, -3]],
                            [[-0.5j, 0], [-0.5, 0]]], 2 * np.pi)
    assert np.allclose(A(0.7), [[-1 + np.sin(0.7), 0], [1 - np.cos(0.7), -3]])
    B = ltp.PeriodicMatrix([[[-0.5], [-0.5j]], [[-1], [2]], [[-0.5], [0.5j]]], 2 * np.pi)
    assert np.allclose(B(0.7), [[-1 - np.cos(0.7)], [2 - np.sin(0.7)]])
    z = ltp.zeros(ltp.ltpss(A, B, [[0, 1]], 0, period=2 * np.pi))
    assert _match(z, [-3 + 4 / np.sqrt(3)], 1e-8)


@pytest.mark.parametrize('beta', [0.5])
def test_zeros_zhou_hagiwara_switching_input(beta):
    # b(t) = [0; 1 - 2β sin 2t] on [0, π/2), [0; 1] on [π/2, π); published zero -3.5
    T = np.pi
    first = ltp.PeriodicMatrix([[[0], [-1j * beta]], [[0], [1]], [[0], [1j * beta]]], T)
    B = ltp.PeriodicMatrix.switching([first, [[0.0], [1.0]]], [0, T / 2], T)
    assert np.allclose(B(0.3), [[0], [1 - 2 * beta * np.sin(0.6)]])
    z = ltp.zeros(ltp.ltpss(zhou_hagiwara_A(), B, [[1, 1]], 0, period=T))
    assert _match(z, [-3.5], 1e-8)


def test_zeros_zhou_tac2009():
    # b(t) = [0; 1 - 2β cos 2t], β = 0.5, c = [0 1]: published zero -1.5
    T = np.pi
    B = ltp.PeriodicMatrix([[[0], [-0.5]], [[0], [1]], [[0], [-0.5]]], T)
    z = ltp.zeros(ltp.ltpss(zhou_hagiwara_A(), B, [[0, 1]], 0, period=T))
    assert _match(z, [-1.5], 1e-8)


def test_zeros_bad_input():
    sys = ltp.ltpss(-np.eye(2), np.ones((2, 2)), np.ones((1, 2)), 0, period=1.0)
    with pytest.raises(ValueError, match="structure"):
        ltp.zeros(sys, structure='yes')
    square = ltp.ltpss(-np.eye(2), np.ones((2, 1)), np.ones((1, 2)), 0, period=1.0)
    with pytest.raises(ValueError, match="rtol"):
        ltp.zeros(square, rtol=2)
    with pytest.raises(ValueError, match="nharmonics"):
        ltp.zeros(square, 0)
