"""Periodic static output feedback (`ofstab`, `oflqr`): exact gradients, verified stability."""

import warnings

import control as ct
import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp


def _random_plant(seed, n=3, m=2, p=2, T=1.3):
    rng = np.random.default_rng(seed)
    A0 = rng.normal(size=(n, n)) - 5 * np.eye(n)
    A1 = 0.5 * rng.normal(size=(n, n))
    B0, C0 = rng.normal(size=(n, m)), rng.normal(size=(p, n))
    w = 2 * np.pi / T
    cos = lambda t: np.cos(w * np.asarray(t))[..., None, None]  # noqa: E731
    sin = lambda t: np.sin(w * np.asarray(t))[..., None, None]  # noqa: E731
    A = ltp.PeriodicMatrix.from_function(lambda t: A0 + A1 * cos(t), T)
    B = ltp.PeriodicMatrix.from_function(lambda t: B0 * (1 + 0.3 * sin(t)), T)
    return ltp.ltpss(A, B, C0, 0, period=T), rng


def _cost_and_gradient(sys, Q, R, theta, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        _, info = ltp.oflqr(sys, Q, R, K0=theta, maxiter=0, **kw)
    return info.cost, info.gradient


@pytest.mark.parametrize("kind", ['switching', 'harmonic', 'discrete'])
def test_lq_gradient_equals_finite_differences(kind):
    sys, rng = _random_plant({'switching': 1, 'harmonic': 2, 'discrete': 3}[kind])
    kw = {'switching': dict(times=[0.0, 0.4, 0.9]), 'harmonic': dict(order=1),
          'discrete': dict(times=[0.0, 3 * 1.3 / 7])}[kind]
    if kind == 'discrete':
        sys = ltp.sample_system(sys, 1.3 / 7)
    s = 2 if kind == 'discrete' else 3
    theta = 0.1 * rng.normal(size=(s, 2, 2))
    Q, R = np.eye(3), np.diag([1.0, 0.5])
    J, g = _cost_and_gradient(sys, Q, R, theta, **kw)
    for _ in range(2):
        d = rng.normal(size=theta.shape)
        eps = 1e-5
        fd = (_cost_and_gradient(sys, Q, R, theta + eps * d, **kw)[0]
              - _cost_and_gradient(sys, Q, R, theta - eps * d, **kw)[0]) / (2 * eps)
        assert abs(np.sum(g * d) - fd) <= 1e-6 * abs(fd)


def test_lq_cost_equals_an_independent_lyapunov_solution():
    sys, rng = _random_plant(4, m=1, p=2)
    K, info = ltp.oflqr(sys, np.eye(3), [[2.0]], times=[0.0, 0.65], maxiter=0,
                        K0=0.2 * rng.normal(size=(2, 1, 2)))
    loop = ltp.feedback(sys, K)
    KC = K @ sys.C
    P = ltp.lyap(loop.A, np.eye(3) + 2.0 * KC.T @ KC, adjoint=True)
    assert abs(info.cost - np.trace(P(0.0))) <= 1e-9 * info.cost


def _chocolate(D=0.0):
    # Bittanti and Colaneri's example: no constant output gain stabilizes it
    d = 0.9
    return ltp.ltpss([[0.0, 1.0], [-1.0, 2 * d]], [[0.0], [1.0]], [[-2.0, 2 * d]], D,
                     period=2.0)


def _independent_multipliers(sysd, K):
    # closed loop built by hand from the sampled data: A_k - B_k K_k C_k
    N = sysd.nsteps
    A, B, C, Kk = (M.sample(N) for M in (sysd.A, sysd.B, sysd.C, K))
    mono = np.eye(sysd.nstates)
    for k in range(N):
        mono = (A[k] - B[k] @ Kk[k] @ C[k]) @ mono
    return np.linalg.eigvals(mono)


def test_switching_or_harmonic_gain_stabilizes_where_no_constant_gain_does():
    sysd = ltp.sample_system(_chocolate(), 0.25)
    # a constant gain u = -k y: the loop is unstable for every k (a 1-D scan)
    ks = np.linspace(-20, 20, 801)
    ad = ct.c2d(ct.ss([[0.0, 1.0], [-1.0, 1.8]], [[0.0], [1.0]], [[-2.0, 1.8]], 0), 0.25)
    worst = [np.abs(np.linalg.eigvals(ad.A - k * ad.B @ ad.C)).max() for k in ks]
    assert min(worst) > 1
    K, info = ltp.ofstab(sysd, maxiter=5)
    assert not info.success and "not stable" in info.message
    K, info = ltp.ofstab(sysd, order=1, target=0.95)
    mu = _independent_multipliers(sysd, K)
    assert info.success and np.abs(mu).max() < 1
    np.testing.assert_allclose(np.sort(np.abs(mu)), np.sort(np.abs(info.multipliers)),
                               rtol=1e-4, atol=1e-12)
    assert info.sdeg == pytest.approx(np.abs(mu).max() ** (1 / sysd.nsteps), rel=1e-4)


def test_switching_gain_with_feedthrough_is_the_implemented_gain():
    sysd = ltp.sample_system(_chocolate(D=0.5), 0.25)
    K, info = ltp.ofstab(sysd, times=[0.0, 1.0], target=0.95)
    assert info.success
    # independent loop with D: u = -K(Cx + Du)  =>  u = -(I + KD)^-1 K C x
    N = sysd.nsteps
    A, B, C, D, Kk = (M.sample(N) for M in (sysd.A, sysd.B, sysd.C, sysd.D, K))
    mono = np.eye(2)
    for k in range(N):
        mono = (A[k] - B[k] @ np.linalg.solve(np.eye(1) + Kk[k] @ D[k], Kk[k] @ C[k])) @ mono
    mu = np.linalg.eigvals(mono)
    assert np.abs(mu).max() < 1
    np.testing.assert_allclose(np.sort(np.abs(mu)), np.sort(np.abs(info.multipliers)),
                               rtol=1e-4, atol=1e-12)


def test_full_state_switching_gain_reaches_the_periodic_lqr_cost():
    rng = np.random.default_rng(5)
    A = 0.8 * rng.normal(size=(3, 2, 2))
    B = rng.normal(size=(3, 2, 1))
    sysd = ltp.ltpss(A, B, np.eye(2), 0, period=3.0, dt=1.0)
    X0 = np.array([[2.0, 0.3], [0.3, 1.0]])
    K, info = ltp.oflqr(sysd, np.eye(2), [[0.5]], X0=X0, times=[0.0, 1.0, 2.0])
    Kd, X, _ = ltp.dlqr(sysd, np.eye(2), [[0.5]])
    assert info.success
    assert abs(info.cost - np.trace(X(0.0) @ X0)) <= 1e-6 * info.cost
    np.testing.assert_allclose(K.sample(3), Kd.sample(3), rtol=1e-4, atol=1e-5)


def test_bad_input():
    sysd = ltp.sample_system(_chocolate(), 0.25)
    with pytest.raises(ValueError, match="start at 0"):
        ltp.ofstab(sysd, times=[0.5, 1.0])
    with pytest.raises(ValueError, match="within"):
        ltp.ofstab(sysd, times=[0.0, 2.5])
    with pytest.raises(ValueError, match="multiples of dt"):
        ltp.ofstab(sysd, times=[0.0, 0.6])
    with pytest.raises(ControlArgument, match="not both"):
        ltp.ofstab(sysd, times=[0.0], order=1)
    with pytest.raises(ValueError, match="order"):
        ltp.ofstab(sysd, order=-1)
    with pytest.raises(ControlDimension, match="K0"):
        ltp.ofstab(sysd, times=[0.0, 1.0], K0=np.zeros((3, 1, 1)))
    with pytest.raises(ValueError, match="R must be positive definite"):
        ltp.oflqr(sysd, np.eye(2), [[0.0]])
    with pytest.raises(ControlDimension, match="X0"):
        ltp.oflqr(sysd, np.eye(2), [[1.0]], X0=np.eye(3))
