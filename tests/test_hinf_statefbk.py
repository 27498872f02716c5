"""Periodic H∞ state feedback: certified bounds, the LTI optimum, the LMI optimum, bad input."""

import control as ct
import numpy as np
import pytest
import scipy.linalg as la
from control.exception import ControlArgument

import ltpcontrol as ltp

A0 = np.array([[0.0, 1.0], [-2.0, 0.3]])
B1 = np.array([[1.0], [0.5]])
B2 = np.array([[0.0], [1.0]])
C1 = np.array([[1.0, 0.0], [0.0, 0.5], [0.0, 0.0]])
D12 = np.array([[0.0], [0.0], [1.0]])


def _plant(A=A0, period=1.0):
    return ltp.ltpss(A, np.hstack([B1, B2]), C1, np.hstack([np.zeros((3, 1)), D12]),
                     period=period)


def _lti_optimum():
    # bisection on the LTI H∞ Riccati equation solved by scipy (indefinite R)
    def achievable(g):
        B, R = np.hstack([B1, B2]), np.diag([-g ** 2, 1.0])
        try:
            X = la.solve_continuous_are(A0, B, C1.T @ C1, R)
        except (ValueError, np.linalg.LinAlgError):
            return False
        closed = A0 - B @ np.linalg.solve(R, B.T @ X)
        return np.linalg.eigvalsh(X).min() >= 0 and np.linalg.eigvals(closed).real.max() < 0
    lo, hi = 0.1, 100.0
    while hi / lo > 1 + 1e-9:
        g = np.sqrt(lo * hi)
        lo, hi = (lo, g) if achievable(g) else (g, hi)
    return hi


def test_lti_case_bound_is_the_optimum_and_covers_the_closed_loop_norm():
    K, info = ltp.hinf_statefbk(_plant(), 1, tol=1e-4)
    assert info.success and K.is_constant
    gopt = _lti_optimum()
    assert gopt <= info.gamma <= gopt * (1 + 1e-4)
    assert info.gamma_lower < gopt
    # slycot's hinfsyn, measuring the state (C2 = I) through a small D21
    eps, n = 1e-4, 2
    Bx = np.hstack([B1, np.zeros((n, n)), B2])
    Dx = np.zeros((3 + n, 1 + n + 1))
    Dx[:3, -1:], Dx[3:, 1:1 + n] = D12, eps * np.eye(n)
    gam = ct.hinfsyn(ct.ss(A0, Bx, np.vstack([C1, np.eye(n)]), Dx), n, 1)[2]
    assert abs(info.gamma - gam) <= 2e-4 * gam
    # the closed loop built by hand, its norm computed independently
    k = K(0.3)
    loop = ct.ss(A0 - B2 @ k, B1, C1 - D12 @ k, 0)
    g_ct = ct.linfnorm(loop, tol=1e-10)[0]
    g_ltp = ltp.hinfnorm(ltp.ltpss(loop, period=1.0), tol=1e-8)[0]
    assert abs(g_ct - g_ltp) <= 1e-7 * g_ct
    assert g_ct <= info.gamma * (1 + 1e-9)
    # default tolerance: within 1 % of the optimum
    _, info = ltp.hinf_statefbk(_plant(), 1)
    assert info.success and gopt <= info.gamma <= 1.01 * gopt


def test_discrete_periodic_bound_equals_the_lmi_optimum():
    rng = np.random.default_rng(3)
    N, n = 3, 2
    A = 0.9 * rng.normal(size=(N, n, n))
    B = rng.normal(size=(N, n, 1))
    lmi = ltp.lmi_statefbk(ltp.ltpss(A, B, np.eye(n), 0, period=0.3, dt=0.1),
                           objective='hinf')
    # the same problem as a generalized plant: w enters through I, z = [x; u]
    Bw = np.concatenate([np.broadcast_to(np.eye(n), (N, n, n)), B], axis=2)
    C = np.concatenate([np.broadcast_to(np.eye(n), (N, n, n)), np.zeros((N, 1, n))], axis=1)
    D = np.zeros((N, n + 1, n + 1))
    D[:, n:, n:] = 1.0
    K, info = ltp.hinf_statefbk(ltp.ltpss(A, Bw, C, D, period=0.3, dt=0.1), 1, tol=1e-4)
    assert info.success
    assert info.gamma_lower <= lmi.bound * (1 + 1e-6) and lmi.bound <= info.gamma * (1 + 1e-6)
    # the closed loop built by hand from the samples
    Kk = K.sample(N)
    loop = ltp.ltpss(A - B @ Kk, np.broadcast_to(np.eye(n), (N, n, n)),
                     np.concatenate([np.broadcast_to(np.eye(n), (N, n, n)), -Kk], axis=1),
                     np.zeros((N, n + 1, n)), period=0.3, dt=0.1)
    assert ltp.norm(loop, 'inf', tol=1e-9) <= info.gamma


def _periodic_plant():
    T = 2 * np.pi
    cos = lambda t: np.cos(np.asarray(t, float))[..., None, None]  # noqa: E731
    sin = lambda t: np.sin(np.asarray(t, float))[..., None, None]  # noqa: E731
    A = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 1.0], [-1.0, 0.1]]) + np.array([[0, 0], [-0.8, 0]]) * cos(t),
        T)
    B = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 0.0], [1.0, 1.0]]) + np.array([[0, 0], [0, 0.5]]) * sin(t),
        T)
    return ltp.ltpss(A, B, [[1.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 1.0]], period=T)


def test_periodic_level_achieved_or_refused():
    P = _periodic_plant()
    K, info = ltp.hinf_statefbk(P, 1, gamma=1.5)
    assert info.success and info.gamma == 1.5
    loop = ltp.ltpss(P.A - P.B[:, 1:] @ K, P.B[:, :1], P.C - P.D[:, 1:] @ K, 0,
                     period=P.period)
    assert np.all(np.abs(ltp.floquet_multipliers(loop)) < 1)
    assert ltp.norm(loop, 'inf', tol=1e-3) <= 1.5       # a certified upper bound
    for gamma in (1.2, 0.88):
        # 0.88: the Hamiltonian has a stable subspace, but the Riccati solution
        # escapes to infinity inside the period (its loop would be unstable)
        K, info = ltp.hinf_statefbk(P, 1, gamma=gamma)
        assert K is None and not info.success and "not achievable" in info.message


def test_bad_input_and_unstabilizable_plant():
    P = _plant()
    with pytest.raises(ControlArgument, match="ncon"):
        ltp.hinf_statefbk(P, 2)
    with pytest.raises(ValueError, match="gamma"):
        ltp.hinf_statefbk(P, 1, gamma=-1.0)
    with pytest.raises(ValueError, match="tol"):
        ltp.hinf_statefbk(P, 1, tol=0)
    D = np.hstack([np.ones((3, 1)), D12])
    with pytest.raises(ValueError, match="D11"):
        ltp.hinf_statefbk(ltp.ltpss(A0, np.hstack([B1, B2]), C1, D, period=1.0), 1)
    with pytest.raises(ValueError, match="D12"):
        ltp.hinf_statefbk(ltp.ltpss(A0, np.hstack([B1, B2]), C1, np.zeros((3, 2)),
                                    period=1.0), 1)
    # an unstable mode the control does not reach: no level is achievable
    A = np.array([[1.0, 0.0], [0.0, -1.0]])
    Pu = ltp.ltpss(A, np.hstack([B1, [[0.0], [1.0]]]), C1, np.hstack([np.zeros((3, 1)), D12]),
                   period=1.0)
    K, info = ltp.hinf_statefbk(Pu, 1)
    assert K is None and not info.success and "not stabilizable" in info.message
