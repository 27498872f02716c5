"""Discrete LQ output-feedback cost: cyclic solver, exact Hessian, Newton step."""

import numpy as np
import pytest

from ltpcontrol._analysis.lyapunov import cyclic_lyap
from ltpcontrol._analysis.output_feedback_lq import DiscreteLQ, cyclic_congruence, _trust_newton


def _lq(seed, N=5, n=3, m=2, p=2, pieces=(0, 3)):
    rng = np.random.default_rng(seed)
    A = 0.5 * rng.normal(size=(N, n, n))
    B, C = rng.normal(size=(N, n, m)), rng.normal(size=(N, p, n))
    Q = np.broadcast_to(np.eye(n), (N, n, n))
    R = np.broadcast_to(np.diag(np.linspace(1.0, 0.5, m)), (N, m, m))
    idx = np.searchsorted(pieces, np.arange(N), side='right') - 1
    phi = (idx[:, None] == np.arange(len(pieces))).astype(float)
    return DiscreteLQ(A, B, C, Q, R, np.eye(n), phi), rng


@pytest.mark.parametrize("N", [1, 4, 7])
def test_cyclic_congruence_equals_the_sparse_cyclic_solver(N):
    rng = np.random.default_rng(N)
    T = 0.6 * rng.normal(size=(N, 3, 3))
    S = rng.normal(size=(2, N, 3, 3))
    S = S + np.swapaxes(S, -1, -2)
    X, _ = cyclic_congruence(T, S)
    for b in range(2):
        np.testing.assert_allclose(X[b], cyclic_lyap(T, S[b]), rtol=1e-11, atol=1e-12)


@pytest.mark.parametrize("seed", [1, 2])
def test_hessian_equals_finite_differences_of_the_gradient(seed):
    lq, rng = _lq(seed)
    theta = 0.05 * rng.normal(size=8)
    J, g, H = lq(theta, hessian=True)
    assert np.isfinite(J)
    np.testing.assert_allclose(H, H.T, rtol=1e-12, atol=0)
    eps = 1e-6
    for i in range(8):
        e = np.zeros(8)
        e[i] = eps
        fd = (lq(theta + e)[1] - lq(theta - e)[1]) / (2 * eps)
        assert np.abs(fd - H[i]).max() <= 1e-6 * np.abs(H).max()


def test_unstable_loop_has_infinite_cost():
    lq, rng = _lq(3)
    J, g, H = lq(1e3 * np.ones(8), hessian=True)
    assert J == np.inf and H is None and not np.any(g)


def test_trust_newton_certifies_a_local_minimum():
    lq, rng = _lq(4)
    theta, nit, ok, dec = _trust_newton(lambda t, h: lq(t, hessian=h), np.zeros(8), 50, 1e-12)
    J, g, H = lq(theta, hessian=True)
    assert ok and dec <= 1e-12 * J
    assert np.linalg.eigvalsh(H).min() > 0
    # no random nearby point is lower
    for _ in range(20):
        assert lq(theta + 1e-3 * rng.normal(size=8))[0] >= J


@pytest.mark.parametrize("metric", [False, True])
def test_trust_newton_whitened_by_the_curvature_certifies_the_same_minimum(metric):
    lq, rng = _lq(4)
    ref, _, ok_ref, _ = _trust_newton(lambda t, h: lq(t, hessian=h), np.zeros(8), 50, 1e-12)
    M = lq.curvature(np.zeros(8)) if metric else None
    theta, nit, ok, dec = _trust_newton(lambda t, h: lq(t, hessian=h), np.zeros(8), 50, 1e-12,
                                       metric=M, stall=1e-9, floor=1e-12)
    assert ok and ok_ref and dec <= 1e-12 * lq(theta)[0]
    np.testing.assert_allclose(theta, ref, rtol=1e-6, atol=1e-9)
    assert np.linalg.eigvalsh(lq(theta, hessian=True)[2]).min() > 0
