"""Discrete periodic systems: sub-periods, time-varying dimensions, minimal realizations.

Truths: the constant-dimension solvers on zero-padded data (the reference
toolbox's ``pm2pa`` equivalence), residuals of the step equations, python-control
in the LTI limit, the time-lifted LTI system (an exact equivalent), and
closed-loop simulation.
"""

import numpy as np
import control as ct
import pytest
import scipy.signal
from control.exception import ControlDimension
from hypothesis import given, settings, strategies as st

import ltpcontrol as ltp

NA, MA = [5, 3, 3, 4, 1], [3, 3, 4, 1, 5]       # the reference toolbox's dims


def _tv_random(seed, na, ma, scale=1.0):
    rng = np.random.default_rng(seed)
    return [scale * rng.standard_normal((m, n)) for n, m in zip(na, ma)]


def _tv_plant(seed, scale):
    """Two inputs, one output, states [5, 3, 3, 4, 1] (the toolbox's dimensions)."""
    A = _tv_random(seed, NA, MA, scale)
    rng = np.random.default_rng(seed)
    return ltp.dltpss(A, [rng.standard_normal((m, 2)) for m in MA],
                      [rng.standard_normal((1, n)) for n in NA], rng.standard_normal((1, 2)))


def _sym(rng, n):
    x = rng.standard_normal((n, n))
    return x + x.T


def _pad(mats, size):
    out = np.zeros((len(mats), size, size))
    for k, m in enumerate(mats):
        out[k, :m.shape[0], :m.shape[1]] = m
    return out


#
# Sub-periods
#

def test_dlyap_period_3_with_q_period_2():
    rng = np.random.default_rng(1)
    A = 0.5 * rng.standard_normal((3, 3, 3))
    Q = np.array([_sym(rng, 3) for _ in range(2)])
    X = ltp.dlyap(A, Q)
    assert X.shape == (6, 3, 3)
    res = max(np.abs(A[k % 3] @ X[k] @ A[k % 3].T + Q[k % 2] - X[(k + 1) % 6]).max()
              for k in range(6))
    assert res <= 1e-12
    # the same as the hand-tiled problem
    Xt = ltp.dlyap(np.tile(A, (2, 1, 1)), np.tile(Q, (3, 1, 1)))
    assert np.abs(X - Xt).max() <= 1e-13 * np.abs(X).max()
    Xa = ltp.dlyap(A, Q, adjoint=True)
    res = max(np.abs(A[k % 3].T @ Xa[(k + 1) % 6] @ A[k % 3] + Q[k % 2] - Xa[k]).max()
              for k in range(6))
    assert res <= 1e-12


def test_lyap_continuous_subperiods():
    A = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[-1.0 + 0.5 * np.cos(2 * np.pi * t / 3), 0.2], [0.0, -2.0]]), 3.0)
    Q = ltp.PeriodicMatrix.from_function(
        lambda t: np.diag([1.0 + 0.3 * np.sin(np.pi * t), 1.0]), 2.0)
    X = ltp.lyap(A, Q)
    assert np.isclose(X.period, 6.0)
    X6 = ltp.lyap(A.with_period(6.0), Q.with_period(6.0))
    assert np.abs(X(1.3) - X6(1.3)).max() < 1e-9


def _mathieu_sub_periods():
    """A of period 1 and a state weight of period 1.5 (common period 3), both in
    Fourier form (exact interpolants of their 8 samples)."""
    t = np.arange(8) / 8
    A = ltp.PeriodicMatrix.from_samples(
        [[[0.0, 1.0], [-1 - 0.3 * np.cos(2 * np.pi * s), -0.2]] for s in t], 1.0)
    Q = ltp.PeriodicMatrix.from_samples(
        [np.diag([1 + 0.5 * np.sin(2 * np.pi * s), 1.0]) for s in t], 1.5)
    return ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=1.0), Q


def test_care_lqr_lqe_continuous_subperiods():
    sys, _ = _mathieu_sub_periods()
    R = [[1.0]]
    # an output weight of period 1.5: the state weight CᵀQyC, period 3 with A's 1
    Qy = ltp.PeriodicMatrix.from_samples(
        [[[1 + 0.5 * np.sin(2 * np.pi * s / 8)]] for s in range(8)], 1.5)
    Q = sys.C.T @ Qy @ sys.C
    X, E, G = ltp.care(sys.A, sys.B, Q, R)
    assert np.isclose(X.period, 3.0) and np.all(E.real < 0)
    # truth: the Riccati equation at the three phases of A (central differences)
    h, t = 1e-5, np.array([0.4, 1.3, 2.2])
    for ti in t:
        dX = (X(ti + h) - X(ti - h)) / (2 * h)
        a, b, x = sys.A(ti), sys.B(ti), X(ti)
        res = dX + a.T @ x + x @ a - x @ b @ b.T @ x + Q(ti)
        assert np.abs(res).max() < 1e-5 * np.abs(x).max()
    K, Xl, _ = ltp.lqr(sys, Qy, R, output=True)
    assert np.isclose(K.period, 3.0)
    assert np.abs(Xl(t) - X(t)).max() < 1e-9 * np.abs(X(t)).max()
    L, P, E = ltp.lqe(sys, [[1.0]], 0.1 * Qy)
    assert np.isclose(L.period, 3.0) and np.isclose(P.period, 3.0) and np.all(E.real < 0)


def test_continuous_incommensurate_weights_named():
    sys, _ = _mathieu_sub_periods()
    Qi = ltp.PeriodicMatrix.constant(np.eye(2), np.sqrt(2))
    with pytest.raises(ValueError, match="Q: periods"):
        ltp.lqr(sys, Qi, [[1.0]])
    with pytest.raises(ValueError, match="Q: periods"):
        ltp.care(sys.A, sys.B, Qi, [[1.0]])
    with pytest.raises(ValueError, match="RN: periods"):
        ltp.lqe(sys, [[1.0]], ltp.PeriodicMatrix.constant([[1.0]], np.sqrt(2)))


def test_dare_dlqr_subperiods():
    rng = np.random.default_rng(2)
    A = rng.standard_normal((3, 2, 2))
    B = rng.standard_normal((2, 2, 1))
    X, L, G = ltp.dare(A, B, np.eye(2), np.ones((1, 1, 1)))
    assert X.shape == (6, 2, 2) and np.all(np.abs(L) < 1)
    Xt, _, _ = ltp.dare(np.tile(A, (2, 1, 1)), np.tile(B, (3, 1, 1)), np.eye(2), [[1.0]])
    assert np.abs(X - Xt).max() < 1e-10 * np.abs(X).max()
    sysd = ltp.ltpss(A, B[0], np.eye(2), 0, period=3.0, dt=1.0)
    K, X, E = ltp.dlqr(sysd, np.array([np.eye(2), 2 * np.eye(2)]), [[1.0]])
    assert np.isclose(K.period, 6.0) and np.all(np.abs(E) < 1)


def test_incommensurate_and_bad_chains_named():
    with pytest.raises(ValueError, match=r"A \(101 steps\), Q \(103 steps\)"):
        ltp.dlyap(np.zeros((101, 1, 1)), np.zeros((103, 1, 1)))
    with pytest.raises(ValueError, match="Q: periods"):
        ltp.lyap(ltp.PeriodicMatrix.constant(-np.eye(1), 1.0),
                 ltp.PeriodicMatrix([[[0.5]], [[1.0]], [[0.5]]], np.sqrt(2)))
    with pytest.raises(ControlDimension, match=r"A\[1\] has 3 rows but A\[0\]"):
        ltp.dlyap([np.ones((2, 2)), np.ones((3, 2))], [np.eye(2), np.eye(3)])
    with pytest.raises(ControlDimension, match=r"A\[1\] has 3 rows"):
        ltp.dltpss([np.ones((1, 2)), np.ones((3, 1))], [[[1.0]]], [[[1.0, 0.0]]], 0)
    with pytest.raises(ControlDimension, match=r"Q\[1\] must be"):
        ltp.dlyap([np.ones((1, 2)), np.ones((2, 1))], [np.eye(1), np.eye(1)])


#
# Time-varying dimensions
#

@pytest.mark.parametrize('adjoint', [False, True])
def test_dlyap_dims_53341_residual_and_padded(adjoint):
    rng = np.random.default_rng(3)
    A = _tv_random(4, NA, MA)
    Q = [_sym(rng, n if adjoint else m) for n, m in zip(NA, MA)]
    X = ltp.dlyap(A, Q, adjoint=adjoint)
    assert [x.shape[0] for x in X] == NA
    if adjoint:
        res = [A[k].T @ X[(k + 1) % 5] @ A[k] + Q[k] - X[k] for k in range(5)]
    else:
        res = [A[k] @ X[k] @ A[k].T + Q[k] - X[(k + 1) % 5] for k in range(5)]
    scale = max(np.abs(x).max() for x in X)
    assert max(np.abs(r).max() for r in res) <= 1e-12 * max(scale, 1.0)
    # zero padding to 5x5 (the toolbox's pm2pa) and the constant-dimension solver
    Ap = _pad(A, 5)
    Qp = _pad(Q, 5)
    Xp = ltp.dlyap(Ap, Qp, adjoint=adjoint)
    for k in range(5):
        assert np.abs(Xp[k][:NA[k], :NA[k]] - X[k]).max() <= 1e-10 * scale


def test_core_multipliers_1x2_2x1_2x2():
    # n = (2, 1, 2): factors 1x2, 2x1, 2x2; the 1x1 cyclic product is 1
    A0 = np.array([[1.0, 0.5]])
    A1 = np.array([[2.0], [1.0]])
    A2 = np.array([[0.25, 0.0], [0.0, 1.0]])
    sys = ltp.dltpss([A0, A1, A2], [np.ones((1, 1)), np.ones((2, 1)), np.ones((2, 1))],
                     [np.ones((1, 2)), np.ones((1, 1)), np.ones((1, 2))], 0)
    assert sys.nstates == (2, 1, 2)
    mu = ltp.floquet_multipliers(sys)
    np.testing.assert_allclose(mu, [1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(sys.floquet_multipliers(start=1), [1.0], atol=1e-15)
    # padded to 2x2 at every step: the constant-dimension multipliers agree
    padded = ltp.ltpss(_pad([A0, A1, A2], 2), np.zeros((2, 1)), np.zeros((1, 2)), 0,
                       period=3.0, dt=1.0)
    np.testing.assert_allclose(np.sort(np.abs(ltp.floquet_multipliers(padded))),
                               np.sort(np.abs(mu)), atol=1e-14)


def test_random_tv_multipliers_equal_padded():
    A = _tv_random(5, NA, MA, 0.6)
    sys = ltp.dltpss(A, [np.ones((m, 1)) for m in MA], [np.ones((1, n)) for n in NA], 0)
    mu = sys.floquet_multipliers()
    assert mu.shape == (5,) and np.count_nonzero(mu) == 1
    padded = ltp.ltpss(_pad(A, 5), np.zeros((5, 1)), np.zeros((1, 5)), 0, period=5.0, dt=1.0)
    mup = ltp.floquet_multipliers(padded)
    np.testing.assert_allclose(np.sort_complex(mup), np.sort_complex(mu), atol=1e-12)


def _reference_tv_plant():
    # the reference toolbox's time-varying-dimension LQ example
    return ltp.dltpss([np.array([[1.0, 2.0]]), np.array([[7.0], [8.0]])],
                      [np.array([[3.0]]), np.array([[9.0], [10.0]])],
                      [np.array([[4.0, 5.0]]), np.array([[11.0]])], [[1.0]])


def test_tv_dlqr_riccati_residual_and_simulated_cost():
    sys = _reference_tv_plant()
    Q = [np.eye(2), np.eye(1)]
    R = [np.eye(1), 2 * np.eye(1)]
    K, X, E = ltp.dlqr(sys, Q, R)
    assert np.all(np.abs(E) < 1)
    for k in range(2):
        a, b, xn = sys.A[k], sys.B[k], X[(k + 1) % 2]
        t = a.T @ xn @ b
        res = a.T @ xn @ a + Q[k] - t @ np.linalg.solve(R[k] + b.T @ xn @ b, t.T) - X[k]
        assert np.abs(res).max() <= 1e-10 * np.abs(X[k]).max()
    # simulated closed-loop cost from x0 equals x0' X_0 x0
    x = np.array([1.0, -0.5])
    cost = 0.0
    for j in range(200):
        k = j % 2
        u = -K[k] @ x
        cost += x @ Q[k] @ x + u @ R[k] @ u
        x = sys.A[k] @ x + sys.B[k] @ u
    x0 = np.array([1.0, -0.5])
    assert abs(cost - x0 @ X[0] @ x0) <= 1e-9 * cost


def test_tv_dlqe_is_stable_and_lti_limit():
    L, P, E = ltp.dlqe(_reference_tv_plant(), np.eye(1), np.eye(1))
    assert [l.shape for l in L] == [(1, 1), (2, 1)] and np.all(np.abs(E) < 1)
    G = ct.drss(3, 2, 2, strictly_proper=False)
    sys = ltp.dltpss([G.A], [G.B], [G.C], [G.D])
    K, X, _ = ltp.dlqr(sys, np.eye(3), np.eye(2))
    K0, X0, _ = ct.dlqr(G.A, G.B, np.eye(3), np.eye(2))
    assert np.abs(K[0] - K0).max() < 1e-10 and np.abs(X[0] - X0).max() < 1e-9 * np.abs(X0).max()
    L, P, _ = ltp.dlqe(sys, np.eye(2), np.eye(2))
    L0, P0, _ = ct.dlqe(G.A, G.B, G.C, np.eye(2), np.eye(2))
    assert np.abs(L[0] - L0).max() < 1e-10 and np.abs(P[0] - P0).max() < 1e-9 * np.abs(P0).max()


def test_tv_norms_equal_lifted_and_constant_dims():
    sys = _tv_plant(6, 0.4)
    L = ltp.lift(sys, method='time')
    assert np.isclose(ltp.norm(sys, 2), ct.norm(L, 2) / np.sqrt(5), rtol=1e-9)
    # an independent lower bound from the lifted frequency response on a grid
    grid = max(np.linalg.norm(L(np.exp(1j * w)), 2) for w in np.linspace(0, np.pi, 200))
    assert grid <= ltp.norm(sys, 'inf') * (1 + 1e-9) <= grid * 1.05
    # constant dimensions: the LTPStateSpace norms
    rng = np.random.default_rng(60)
    s3 = ltp.ltpss(0.4 * rng.standard_normal((3, 3, 3)), rng.standard_normal((3, 3, 2)),
                   rng.standard_normal((3, 1, 3)), 0, period=3.0, dt=1.0)
    assert np.isclose(ltp.norm(ltp.dltpss(s3), 2), ltp.norm(s3, 2), rtol=1e-10)
    assert np.isclose(ltp.norm(ltp.dltpss(s3), 'inf'), ltp.norm(s3, 'inf'), rtol=1e-5)


def test_tv_simulation_equals_lifted_and_interconnections():
    A = _tv_random(7, NA, MA, 0.5)
    rng = np.random.default_rng(7)
    sys = ltp.dltpss(A, [rng.standard_normal((m, 1)) for m in MA],
                     [rng.standard_normal((2, n)) for n in NA], np.zeros((2, 1)))
    U = rng.standard_normal((15, 1))
    y, x = sys.forced_response(U)
    L = ltp.lift(sys, method='time')
    _, yl = ct.forced_response(L, U=U.reshape(3, 5).T, X0=np.zeros(5))
    assert np.abs(yl.T.reshape(15, 2) - y).max() < 1e-12 * max(1, np.abs(y).max())
    # parallel with itself doubles the output; series with a static gain scales it
    y2, _ = (sys + sys).forced_response(U)
    assert np.abs(y2 - 2 * y).max() < 1e-12 * max(1, np.abs(y).max())
    gain = ltp.dltpss([np.zeros((0, 0))], [np.zeros((0, 2))], [np.zeros((2, 0))],
                      [3.0 * np.eye(2)])
    y3, _ = (gain * sys).forced_response(U)
    assert np.abs(y3 - 3 * y).max() < 1e-12 * max(1, np.abs(y).max())
    assert 'states (5, 3, 3, 4, 1)' in repr(sys) and 'step 4: A 5x1' in str(sys)


#
# Minimal realizations and balanced truncation
#

def _hidden_modes(seed, N=3):
    rng = np.random.default_rng(seed)
    Ac = rng.standard_normal((N, 2, 2))
    A = np.zeros((N, 4, 4))
    A[:, :2, :2] = Ac
    A[:, 2, 2] = 1.5 * rng.standard_normal(N)           # unreachable mode (may be unstable)
    A[:, 3, 3] = rng.standard_normal(N)                 # unobservable mode
    A[:, 0, 2], A[:, 3, 0], A[:, 3, 2] = 0.7, 0.5, 0.3
    B = np.zeros((N, 4, 1))
    B[:, :2] = rng.standard_normal((N, 2, 1))
    B[:, 3] = rng.standard_normal((N, 1))
    C = np.zeros((N, 1, 4))
    C[:, :, :2] = rng.standard_normal((N, 1, 2))
    C[:, 0, 2] = rng.standard_normal(N)
    D = rng.standard_normal((N, 1, 1))
    T = np.eye(4) + 0.5 * rng.standard_normal((N, 4, 4))   # random periodic change of state
    Ti = np.linalg.inv(T)
    At = np.array([T[(k + 1) % N] @ A[k] @ Ti[k] for k in range(N)])
    Bt = np.array([T[(k + 1) % N] @ B[k] for k in range(N)])
    Ct = np.array([C[k] @ Ti[k] for k in range(N)])
    core = ltp.ltpss(A[:, :2, :2], B[:, :2], C[:, :, :2], D, period=N * 1.0, dt=1.0)
    return ltp.ltpss(At, Bt, Ct, D, period=N * 1.0, dt=1.0), core


@pytest.mark.parametrize('seed, N', [(3, 3), (11, 3), (4, 6), (21, 8)])
def test_minreal_hidden_modes_random_transformation(seed, N):
    big, core = _hidden_modes(seed, N)
    red = ltp.minreal(big)
    assert red.nstates == 2
    L1, L2 = ltp.lift(big, method='time'), ltp.lift(red, method='time')
    L0 = ltp.lift(core, method='time')            # the exact transfer function
    for z in (0.3 + 0.2j, np.exp(0.7j), 2.0, -1.5j):
        scale = max(1, np.abs(L0(z)).max())
        data = np.abs(L1(z) - L0(z)).max()         # rounding in the transformed data
        assert np.abs(L2(z) - L1(z)).max() <= max(1e-10 * scale, 10 * data)
        assert np.abs(L2(z) - L0(z)).max() <= max(1e-10 * scale, 10 * data)


def test_minreal_time_varying_order():
    # the periodic realization of a lifted system has orders 2, 3, 4 (state
    # plus stored inputs); its minimal realization drops the stored inputs
    rng = np.random.default_rng(8)
    base = ltp.dltpss(list(0.5 * rng.standard_normal((3, 2, 2))),
                      list(rng.standard_normal((3, 2, 1))), list(rng.standard_normal((3, 1, 2))),
                      list(rng.standard_normal((3, 1, 1))))
    Lb = ltp.lift(base, method='time')
    big = ltp.unlift(Lb, 3)
    assert big.nstates == (2, 3, 4)
    red = ltp.minreal(big)
    assert max(red.nstates) <= 2
    Lr = ltp.lift(red, method='time')
    for z in (0.5j, 1.7):
        assert np.abs(Lr(z) - Lb(z)).max() < 1e-10 * np.abs(Lb(z)).max()
    # an order that really varies: a state that exists at one step only
    tv = ltp.dltpss([np.array([[0.5]]), np.array([[1.0], [0.2]]), np.array([[0.3, 0.0]])],
                    [np.array([[1.0]]), np.array([[0.0], [1.0]]), np.array([[0.0]])],
                    [np.array([[1.0]]), np.array([[1.0]]), np.array([[0.0, 1.0]])], 0)
    assert ltp.minreal(tv).nstates == tv.nstates
    assert ltp.minreal(tv + tv).nstates == tv.nstates


def test_minreal_lti_written_as_periodic_equals_python_control():
    # python-control's own minreal cases (matlab_test.testMinreal)
    G = ct.ss([[-2, 0.5, 0], [0.5, -0.3, 0], [0, 0, -0.1]], [[0.3, -1.3], [0.1, 0.], [1., 0.]],
              [[0., 0.1, 0.], [-0.3, -0.2, 0.]], [[0., -0.8], [-0.3, 0.]])
    for sys in (G, ct.c2d(G, 0.1)):
        red = ltp.minreal(ltp.ltpss(sys, period=0.3) if sys.dt == 0 else
                          ltp.ltpss(sys.A, sys.B, sys.C, sys.D, period=0.3, dt=0.1))
        want = ct.minreal(sys, verbose=False)
        assert red.nstates == want.nstates == 2
        got = np.sort_complex(np.linalg.eigvals(red.A(0.0)))
        np.testing.assert_allclose(got, np.sort_complex(np.linalg.eigvals(want.A)), rtol=1e-8)


def _pole_zero_pair(c):
    """(s+1)(s+c)/((s+2)(s²+s+1)) as a 3-state (controllable canonical) realization."""
    num = np.polymul([1.0, 1.0], [1.0, c])
    den = np.polymul([1.0, 2.0], [1.0, 1.0, 1.0])
    return ct.ss(*scipy.signal.tf2ss(num, den))


def _in_periodic_basis(G, N, seed):
    """The discrete LTI system G in the state basis x_k = T_k z_k (N steps)."""
    rng = np.random.default_rng(seed)
    n = G.nstates
    T = [np.linalg.qr(rng.standard_normal((n, n)))[0] @ np.diag(rng.uniform(0.5, 2.0, n))
         for _ in range(N)]
    A = [np.linalg.solve(T[(k + 1) % N], G.A @ T[k]) for k in range(N)]
    B = [np.linalg.solve(T[(k + 1) % N], G.B) for k in range(N)]
    return ltp.dltpss(A, B, [G.C @ T[k] for k in range(N)], [G.D], G.dt)


@pytest.mark.parametrize('c', [2.00000000001, 2.0])
def test_minreal_near_cancellation_as_python_control(c):
    # python-control's near-cancellation test (xferfcn_test.test_minreal,
    # minreal_test.testMinrealtf): TransferFunction.minreal cancels the pole -2
    # against the zero -c with its default tolerance 1000 sqrt(eps)|z|
    s = ct.tf('s')
    h = (s + 1) * (s + c) / (s + 2) / (s ** 2 + s + 1)
    hm = ct.minreal(h, verbose=False)
    hr = (s + 1) / (s ** 2 + s + 1)
    np.testing.assert_array_almost_equal(hm.num[0][0], hr.num[0][0])
    np.testing.assert_array_almost_equal(hm.den[0][0], hr.den[0][0])
    G = _pole_zero_pair(c)
    assert G.nstates == 3
    # continuous, constant matrices: the same cancellation, the same reduced tf
    red = ltp.minreal(ltp.ltpss(G, period=0.2))
    assert red.nstates == 2
    got = ct.tf(red.to_ss())
    lead = got.den[0][0][0]
    np.testing.assert_array_almost_equal(got.num[0][0][-2:] / lead, hr.num[0][0])
    np.testing.assert_array_almost_equal(got.den[0][0] / lead, hr.den[0][0])
    # discrete, through the periodic staircase: the sampled system in a random
    # periodic basis (3 steps) against the sampled python-control result
    Gd = ct.c2d(G, 0.1)
    hd = ct.minreal(ct.tf(Gd), verbose=False)
    assert hd.den[0][0].size - 1 == 2
    P = _in_periodic_basis(Gd, 3, seed=1)
    assert ltp.minreal(ltp.ltpss(Gd.A, Gd.B, Gd.C, Gd.D, period=0.3, dt=0.1)).nstates == 2
    redd = ltp.minreal(P)
    assert redd.nstates == (2, 2, 2)
    L = ltp.lift(redd, method='time')
    Lw = ltp.lift(ltp.ltpss(ct.ss(hd), period=0.3), method='time')
    for z in (0.3 + 0.2j, np.exp(0.7j), 2.0):
        np.testing.assert_allclose(L(z), Lw(z), rtol=1e-9, atol=1e-9)


def test_minreal_keeps_a_pair_python_control_keeps():
    # a pole-zero pair 1e-3 apart is no cancellation for python-control
    s = ct.tf('s')
    h = (s + 1) * (s + 2.001) / (s + 2) / (s ** 2 + s + 1)
    assert ct.minreal(h, verbose=False).den[0][0].size - 1 == 3
    G = _pole_zero_pair(2.001)
    assert ltp.minreal(ltp.ltpss(G, period=0.2)).nstates == 3
    assert ltp.minreal(_in_periodic_basis(ct.c2d(G, 0.1), 3, seed=2)).nstates == (3, 3, 3)


def test_tv_balred_bound_and_hsv():
    A = _tv_random(9, [4, 3, 5], [3, 5, 4], 0.45)
    rng = np.random.default_rng(9)
    sys = ltp.dltpss(A, [rng.standard_normal((m, 1)) for m in [3, 5, 4]],
                     [rng.standard_normal((1, n)) for n in [4, 3, 5]], 0)
    assert sys.is_stable()
    hsv = ltp.hsvd(sys)
    assert [len(h) for h in hsv] == [4, 3, 5]
    red, bound = ltp.balred(sys, 2, return_bound=True)
    assert red.nstates == (2, 2, 2)
    err = ltp.norm(sys - red, 'inf')
    assert 0 < err <= bound * (1 + 1e-8)


#
# Lifting forms
#

def test_lifting_forms_agree_and_round_trip():
    sys = _tv_plant(10, 0.6)
    L = ltp.lift(sys, method='time')
    Ast, E, Bst, Cst, Dst = ltp.lift(sys, method='stacked')
    Cy = ltp.lift(sys, method='cyclic')
    N = 5
    for z in (0.4 + 0.3j, 1.3):
        Hs = Cst @ np.linalg.solve(z * E - Ast, Bst) + Dst
        assert np.abs(Hs - L(z)).max() < 1e-10 * np.abs(L(z)).max()
        zc = z ** (1 / N)
        Hc = Cy(zc)
        i, j = np.meshgrid(np.arange(N), np.repeat(np.arange(N), 2), indexing='ij')
        assert np.abs(Hc - zc ** (j - i) * L(z)).max() < 1e-9 * np.abs(L(z)).max()
    # the cyclic form's eigenvalues are the N-th roots of the core multipliers
    mu = sys.floquet_multipliers()[0]
    ev = np.linalg.eigvals(Cy.A)
    assert np.abs(ev ** N - mu).min() < 1e-10
    # round trips
    sp = ltp.lift(sys, method='stacked', sparse=True)
    for back in (ltp.unlift(sp, N, method='stacked', nstates=NA),
                 ltp.unlift(Cy, N, method='cyclic', nstates=NA)):
        assert all(np.array_equal(a, b) for a, b in zip(back.A, sys.A))
        assert all(np.array_equal(a, b) for a, b in zip(back.B, sys.B))
    L2 = ltp.lift(ltp.unlift(L, N), method='time')
    for z in (0.4j, 2.0):
        assert np.abs(L2(z) - L(z)).max() < 1e-12 * np.abs(L(z)).max()


def test_lift_constant_dims_forms_match_existing_time_lifting():
    rng = np.random.default_rng(12)
    s = ltp.ltpss(0.5 * rng.standard_normal((4, 2, 2)), rng.standard_normal((4, 2, 1)),
                  rng.standard_normal((4, 1, 2)), rng.standard_normal((4, 1, 1)),
                  period=4.0, dt=1.0)
    L = ltp.lift(s, method='time', start=1)
    Lt = ltp.lift(ltp.dltpss(s), method='time', start=1)
    for M, Mt in zip((L.A, L.B, L.C, L.D), (Lt.A, Lt.B, Lt.C, Lt.D)):
        assert np.abs(M - Mt).max() < 1e-13
    with pytest.raises(ValueError, match="not block lower triangular"):
        ltp.unlift(ct.ss(L.A, L.B, L.C, np.ones_like(L.D), 4.0), 4)
    with pytest.raises(ValueError, match="sparse"):
        ltp.lift(s, sparse=True)


@settings(max_examples=15, deadline=None)
@given(st.lists(st.integers(1, 3), min_size=2, max_size=4), st.integers(0, 10 ** 6))
def test_unlift_cyclic_round_trip_property(dims, seed):
    rng = np.random.default_rng(seed)
    N = len(dims)
    A = [rng.standard_normal((dims[(k + 1) % N], dims[k])) for k in range(N)]
    sys = ltp.dltpss(A, [rng.standard_normal((dims[(k + 1) % N], 1)) for k in range(N)],
                     [rng.standard_normal((1, dims[k])) for k in range(N)], 0)
    back = ltp.unlift(ltp.lift(sys, method='cyclic'), N, method='cyclic', nstates=dims)
    assert back.nstates == sys.nstates
    assert all(np.array_equal(a, b) for a, b in zip(back.A, sys.A))


def test_ltpss_components_of_sub_periods():
    rng = np.random.default_rng(13)
    A3 = 0.5 * rng.standard_normal((3, 2, 2))
    B2 = rng.standard_normal((2, 2, 1))
    sys = ltp.ltpss(A3, B2, np.ones((1, 2)), 0, period=6.0, dt=1.0)
    assert sys.nsteps == 6
    np.testing.assert_array_equal(sys.B.sample(6), np.tile(B2, (3, 1, 1)))
    np.testing.assert_array_equal(sys.A.sample(6), np.tile(A3, (2, 1, 1)))
    with pytest.raises(ControlDimension, match="B has 4 matrices but the period has 6"):
        ltp.ltpss(A3, np.ones((4, 2, 1)), np.ones((1, 2)), 0, period=6.0, dt=1.0)
    # the same system built with dltpss from the two sub-periods
    tv = ltp.dltpss(A3, B2, np.ones((1, 2)), 0)
    assert tv.nsteps == 6
    np.testing.assert_allclose(tv.floquet_multipliers(), ltp.floquet_multipliers(sys),
                               atol=1e-14)


def test_tv_simulation_equals_zero_padded_system():
    # the reference toolbox's time-response case: dims 10, 8, 6, 4, 2
    rng = np.random.default_rng(14)
    na = [10, 8, 6, 4, 2]
    ma = na[1:] + na[:1]
    A = [0.3 * rng.standard_normal((m, n)) for n, m in zip(na, ma)]
    B = [rng.standard_normal((m, 2)) for m in ma]
    C = [rng.standard_normal((3, n)) for n in na]
    D = rng.standard_normal((3, 2))
    sys = ltp.dltpss(A, B, C, D)
    U = rng.standard_normal((11, 2))
    x0 = rng.standard_normal(10)
    y, x = sys.forced_response(U, x0)
    Bp = np.zeros((5, 10, 2))
    Cp = np.zeros((5, 3, 10))
    for k in range(5):
        Bp[k, :ma[k]] = B[k]
        Cp[k, :, :na[k]] = C[k]
    padded = ltp.ltpss(_pad(A, 10), Bp, Cp, D, period=5.0, dt=1.0)
    res = ltp.forced_response(padded, np.arange(11.0), U.T, X0=x0)
    assert np.abs(np.asarray(res.outputs).T - y).max() < 1e-12 * np.abs(y).max()


def test_tv_feedback_equals_lifted_feedback_and_gram_is_stable():
    rng = np.random.default_rng(15)
    P = ltp.dltpss(_tv_random(15, [3, 2, 4], [2, 4, 3], 0.5),
                   [rng.standard_normal((m, 1)) for m in [2, 4, 3]],
                   [rng.standard_normal((1, n)) for n in [3, 2, 4]], 0)
    Kc = ltp.dltpss([np.array([[0.3]])], [np.array([[1.0]])], [np.array([[0.5]])],
                    [np.array([[0.2]])])
    closed = P.feedback(Kc)
    Kc3 = ltp.dltpss(*(list(M) * 3 for M in (Kc.A, Kc.B, Kc.C, Kc.D)))   # on P's period
    lifted = ct.feedback(ltp.lift(P, method='time'), ltp.lift(Kc3, method='time'))
    Lc = ltp.lift(closed, method='time')
    for z in (0.4j, 1.5):
        assert np.abs(Lc(z) - lifted(z)).max() < 1e-10 * max(1, np.abs(lifted(z)).max())
    assert ltp.is_stable(closed) == bool(np.abs(np.linalg.eigvals(lifted.A)).max() < 1)
    if ltp.is_stable(P):
        Pc = ltp.gram(P, 'c')
        assert [p.shape[0] for p in Pc] == [3, 2, 4]


@settings(max_examples=12, deadline=None)
@given(st.lists(st.integers(1, 4), min_size=1, max_size=5), st.integers(1, 3),
       st.integers(0, 10 ** 6), st.booleans())
def test_tv_dlyap_residual_property(dims, q_steps, seed, adjoint):
    rng = np.random.default_rng(seed)
    N = len(dims)
    A = [0.5 * rng.standard_normal((dims[(k + 1) % N], dims[k])) for k in range(N)]
    L = int(np.lcm(N, q_steps))
    size = [dims[k % N] if adjoint else dims[(k + 1) % N] for k in range(L)]
    # Q of q_steps matrices must fit every step it is repeated at
    if any(size[k] != size[k % q_steps] for k in range(L)):
        return
    Q = [_sym(rng, size[k]) for k in range(q_steps)]
    X = ltp.dlyap(A, Q, adjoint=adjoint)
    assert len(X) == L
    scale = max(1.0, max(np.abs(x).max() for x in X))
    for k in range(L):
        a, q = A[k % N], Q[k % q_steps]
        r = a.T @ X[(k + 1) % L] @ a + q - X[k] if adjoint else \
            a @ X[k] @ a.T + q - X[(k + 1) % L]
        assert np.abs(r).max() <= 1e-11 * scale


def test_tv_static_gain_on_either_side():
    s = ltp.dltpss([[[0.5]]], [[[1.0]]], [[[1.0], [2.0]]], 0)
    y, _ = s.forced_response(np.ones((3, 1)))
    y1, _ = (np.array([[1.0, 1.0]]) * s).forced_response(np.ones((3, 1)))
    np.testing.assert_allclose(y1[:, 0], y.sum(axis=1), atol=1e-15)
    y2, _ = (s * np.array([[2.0]])).forced_response(np.ones((3, 1)))
    np.testing.assert_allclose(y2, 2 * y, atol=1e-15)


def test_tv_hankel_norm_equals_constant_dimension_norm():
    rng = np.random.default_rng(16)
    s3 = ltp.ltpss(0.4 * rng.standard_normal((3, 3, 3)), rng.standard_normal((3, 3, 2)),
                   rng.standard_normal((3, 1, 3)), 0, period=3.0, dt=1.0)
    assert np.isclose(ltp.norm(ltp.dltpss(s3), 'hankel'), ltp.norm(s3, 'hankel'), rtol=1e-9)


#
# Storage and time responses
#

def _varying_states():
    rng = np.random.default_rng(12)
    n = [2, 1, 3]
    A = [0.6 * rng.standard_normal((n[(k + 1) % 3], n[k])) for k in range(3)]
    B = [rng.standard_normal((n[(k + 1) % 3], 2)) for k in range(3)]
    C = [rng.standard_normal((1, n[k])) for k in range(3)]
    return ltp.dltpss(A, B, C, list(rng.standard_normal((3, 1, 2))), 0.05, name='plant')


def test_save_load_time_varying_dimensions(tmp_path):
    sys = _varying_states()
    gain = ltp.dltpss([np.zeros((0, 0))], [np.zeros((0, 2))], [np.zeros((1, 0))],
                      [[[1.0, -2.0]]], 0.05)             # no state at all
    for obj in (sys, gain, ltp.minreal(sys + sys)):
        path = tmp_path / 'tv.npz'
        ltp.save(path, obj)
        back = ltp.load(path)
        assert isinstance(back, ltp.DiscreteLTPSystem)
        assert (back.nstates, back.ninputs, back.noutputs, back.dt, back.name) == \
            (obj.nstates, obj.ninputs, obj.noutputs, obj.dt, obj.name)
        for k in 'ABCD':
            assert all(np.array_equal(a, b) for a, b in zip(getattr(back, k), getattr(obj, k)))
    # a file whose dimension chain does not close is refused as corrupt
    import json
    ltp.save(tmp_path / 'tv.npz', sys)             # states (2, 1, 3)
    data = dict(np.load(tmp_path / 'tv.npz'))
    tree = json.loads(str(data['tree']))
    tree['A'][1] = tree['A'][0]                    # A_1 now 1x2 where 3x1 belongs
    data['tree'] = np.array(json.dumps(tree))
    np.savez(tmp_path / 'bad.npz', **data)
    with pytest.raises(ValueError, match='corrupt'):
        ltp.load(tmp_path / 'bad.npz')


def test_forced_response_equals_lifted_simulation():
    sys = _varying_states()
    N, P = 3, 4                                    # four periods
    rng = np.random.default_rng(13)
    U = rng.standard_normal((2, N * P))
    resp = ltp.forced_response(sys, inputs=U)
    np.testing.assert_allclose(resp.time, np.arange(N * P) * 0.05)
    assert resp.states.shape == (0, N * P)         # the state dimension varies
    # truth: the time-lifted LTI system simulated by python-control
    L = ltp.lift(sys, method='time')
    Ul = U.reshape(2, P, N).transpose(2, 0, 1).reshape(N * 2, P)   # [u_0; u_1; u_2] per period
    yl = ct.forced_response(L, inputs=Ul).outputs.reshape(N, P)
    np.testing.assert_allclose(resp.outputs[0], yl.T.reshape(-1), rtol=1e-12, atol=1e-12)
    # a start at step 1 with an initial state of n_1 entries: the shifted system
    x0 = rng.standard_normal(sys.nstates[1])
    r1 = ltp.forced_response(sys, 0.05 * np.arange(1, 7), U[:, :6], x0)
    y1, _ = sys.shifted(1).forced_response(U[:, :6].T, x0)
    np.testing.assert_allclose(r1.outputs[0], y1[:, 0], rtol=1e-14)
    # several traces at once, and the free response
    Um = rng.standard_normal((2, 3, 6))
    rm = ltp.forced_response(sys, inputs=Um)
    for i in range(3):
        np.testing.assert_allclose(rm.outputs[0, i], ltp.forced_response(
            sys, inputs=Um[:, i]).outputs[0], rtol=1e-14)
    x0 = rng.standard_normal(sys.nstates[0])
    free = ltp.initial_response(sys, 0.05 * 5, x0)
    np.testing.assert_allclose(free.outputs, ltp.forced_response(
        sys, 0.05 * np.arange(6), np.zeros((2, 6)), x0).outputs[0], rtol=1e-14)


def test_forced_response_constant_dims_states_and_refusals():
    rng = np.random.default_rng(14)
    sys = ltp.dltpss(list(0.5 * rng.standard_normal((2, 2, 2))), [[[1.0], [0.0]]],
                     [[[1.0, 1.0]]], 0)
    U = rng.standard_normal(5)
    resp = ltp.forced_response(sys, inputs=U, initial_state=[1.0, -1.0])
    _, xs = sys.forced_response(U[:, None], [1.0, -1.0])
    np.testing.assert_allclose(resp.states, np.array(xs[:-1]).T, rtol=1e-15)
    varying_inputs = ltp.dltpss([[[0.5]], [[0.5]]], [[[1.0]], [[1.0, 1.0]]], [[[1.0]]], 0)
    with pytest.raises(ControlDimension, match='number of inputs varies'):
        ltp.forced_response(varying_inputs, inputs=np.ones(4))
    with pytest.raises(ControlDimension, match='initial_state'):
        ltp.forced_response(_varying_states(), inputs=np.ones((2, 3)), initial_state=[1.0])
    with pytest.raises(ValueError, match='multiples of dt'):
        ltp.forced_response(_varying_states(), [0.0, 0.07], np.ones((2, 2)))
