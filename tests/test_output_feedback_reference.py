"""Periodic output feedback on the reference toolbox's test plants (PeriodicSystems.jl).

Pitelkau's satellite (discrete LQ output feedback, the toolbox's Q, R and
120 steps per orbit) and Bittanti and Colaneri's chocolate plant
(continuous switching and harmonic stabilization).  Every gain is judged by
closed-loop multipliers computed here, independently of the library: a
hand-made product of the sampled closed-loop steps, or a `solve_ivp`
monodromy.
"""

import numpy as np
import pytest
from control.exception import ControlDimension
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

W0 = 0.00103448                      # orbital rate (rad/s)
TP = 2 * np.pi / W0
Q_SAT, R_SAT = np.diag([2.0, 1.0, 0.0, 0.0]), np.array([[1e-11]])


def _pitelkau():
    a = np.array([[0, 0, 5.318064566757217e-02, 0], [0, 0, 0, 5.318064566757217e-02],
                  [-1.352134256362805e-03, 0, 0, -7.099273035392090e-02],
                  [0, -7.557182037479544e-04, 3.781555288420663e-02, 0]])

    def b(t):
        t = np.asarray(t, float)
        out = np.zeros(t.shape + (4, 1))
        out[..., 2, 0] = 0.1389735e-6 * np.sin(W0 * t)
        out[..., 3, 0] = -0.3701336e-7 * np.cos(W0 * t)
        return out
    return ltp.ltpss(a, ltp.PeriodicMatrix.from_function(b, TP), np.eye(4)[:2], 0, period=TP)


@pytest.fixture(scope='module')
def satellite():
    return ltp.sample_system(_pitelkau(), TP / 120)


def _steps(sysd, K):
    N = sysd.nsteps
    A, B, C, Kk = (M.sample(N) for M in (sysd.A, sysd.B, sysd.C, K))
    return A - B @ Kk @ C, Kk @ C


def _lq_cost(sysd, K, Q, R):
    """tr P_0 (X_0 = I) summed over one period by hand, then over all periods
    by doubling the series Σ_j (Ψᵀ)^j W Ψ^j."""
    Ac, KC = _steps(sysd, K)
    W, Phi = np.zeros((4, 4)), np.eye(4)
    for k in range(sysd.nsteps):
        W += Phi.T @ (Q + KC[k].T @ R @ KC[k]) @ Phi
        Phi = Ac[k] @ Phi
    S, Pm = W, Phi
    for _ in range(60):
        S, Pm = S + Pm.T @ S @ Pm, Pm @ Pm
    return np.trace(S), Phi


def test_pitelkau_constant_gain_at_120_steps_per_orbit(satellite):
    # the toolbox's pdlqofc_sw(psys, Q, R, [120]) configuration: one gain per orbit
    K, info = ltp.oflqr(satellite, Q_SAT, R_SAT)
    cost, mono = _lq_cost(satellite, K, Q_SAT, R_SAT)
    mu = np.linalg.eigvals(mono)
    assert info.success and "local minimum" in info.message
    assert np.abs(mu).max() < 1
    np.testing.assert_allclose(np.sort(np.abs(mu)), np.sort(np.abs(info.multipliers)),
                               rtol=1e-6, atol=1e-14)
    assert info.sdeg == pytest.approx(np.abs(mu).max() ** (1 / 120), rel=1e-9)
    assert info.cost == pytest.approx(cost, rel=1e-9)
    _, X, _ = ltp.dlqr(satellite, Q_SAT, R_SAT)
    assert info.cost >= np.trace(X(0.0))           # state feedback is a lower bound
    # a local minimum: no nearby gain is cheaper
    F = info.params[0]
    for dF in ([[1e-3, 0]], [[0, 1e-3]], [[-1e-3, 0]], [[0, -1e-3]]):
        Kp = ltp.PeriodicMatrix.from_samples(np.broadcast_to(F * (1 + np.array(dF)), (120, 1, 2)),
                                             TP, kind='hold')
        assert _lq_cost(satellite, Kp, Q_SAT, R_SAT)[0] > info.cost


def test_pitelkau_constant_gain_at_10_steps_per_orbit():
    # the homotopy from zero does not stabilize this plant; the projected
    # state-feedback start does (a grid search finds max|mu| = 0.917)
    sat = ltp.sample_system(_pitelkau(), TP / 10)
    K, info = ltp.ofstab(sat)
    mu = np.linalg.eigvals(np.linalg.multi_dot(_steps(sat, K)[0][::-1]))
    assert info.success and np.abs(mu).max() < 1
    K, info = ltp.oflqr(sat, Q_SAT, R_SAT)
    cost, mono = _lq_cost(sat, K, Q_SAT, R_SAT)
    assert info.success and np.abs(np.linalg.eigvals(mono)).max() < 1
    assert info.cost == pytest.approx(cost, rel=1e-9)
    _, X, _ = ltp.dlqr(sat, Q_SAT, R_SAT)
    assert info.cost >= np.trace(X(0.0))


d = 0.9


def _chocolate(D):
    return ltp.ltpss([[0.0, 1.0], [-1.0, 2 * d]], [[0.0], [1.0]], [[-2.0, 2 * d]], D,
                     period=2.0)


def _monodromy_ivp(sys, gain, breaks, loop_gain=False):
    """Closed loop u = -K(Cx + Du) (or u = -K C x with `loop_gain`) by solve_ivp
    over the pieces of the period."""
    A, B, C, D = (np.asarray(M(0.0)).reshape(M.shape) for M in (sys.A, sys.B, sys.C, sys.D))

    def rhs(t, x):
        k = gain(t)
        F = k if loop_gain else np.linalg.solve(np.eye(1) + k @ D, k)
        return (A - B @ F @ C) @ x
    X = np.eye(2)
    for t0, t1 in zip(breaks[:-1], breaks[1:]):
        X = np.column_stack([solve_ivp(rhs, (t0, t1), x, rtol=1e-11, atol=1e-13,
                                       method='DOP853').y[:, -1] for x in X.T])
    return np.linalg.eigvals(X)


@pytest.mark.slow
def test_chocolate_no_constant_gain_but_a_harmonic_one():
    sys = _chocolate(0.0)
    # u = -k y closes A - k b c with trace 2d(1 - k) and determinant 1 - 2k:
    # stable needs k > 1 and k < 1/2
    for k in np.linspace(-20, 20, 401):
        assert np.linalg.eigvals(np.array([[0, 1], [-1 + 2 * k, 2 * d * (1 - k)]])).real.max() >= 0
    K, info = ltp.ofstab(sys, order=1, target=-0.05, maxiter=50)
    mu = _monodromy_ivp(sys, lambda t: np.asarray(K(np.array([t]))).reshape(1, 1), [0.0, 2.0])
    assert info.success and np.abs(mu).max() < 1
    np.testing.assert_allclose(np.sort(np.abs(mu)), np.sort(np.abs(info.multipliers)),
                               rtol=1e-6)


def test_chocolate_switching_gain_with_feedthrough():
    sys = _chocolate(1.0)
    # the toolbox's hand-made loop gain (u = +F C x, F = -4.22 then 2.12, switching
    # at t = 1) is stable by our check
    toolbox = _monodromy_ivp(sys, lambda t: np.array([[4.22 if t < 1 else -2.12]]),
                             [0.0, 1.0, 2.0], loop_gain=True)
    assert np.abs(toolbox).max() < 1
    K, info = ltp.ofstab(sys, times=[0.0, 1.0], target=-0.05, maxiter=50)
    gains = K.sample(2)                          # the implemented gain on [0, 1) and [1, 2)
    mu = _monodromy_ivp(sys, lambda t: gains[0] if t < 1 else gains[1], [0.0, 1.0, 2.0])
    assert info.success and np.abs(mu).max() < 1
    np.testing.assert_allclose(np.sort(np.abs(mu)), np.sort(np.abs(info.multipliers)),
                               rtol=1e-6)


def test_bad_input_continuous():
    sys = _chocolate(0.0)
    with pytest.raises(ValueError, match="start at 0"):
        ltp.ofstab(sys, times=[0.5, 1.5])              # leaves [0, 0.5) uncovered
    with pytest.raises(ValueError, match="within"):
        ltp.ofstab(sys, times=[0.0, 2.0])              # a piece beyond the period
    with pytest.raises(ValueError, match="within"):
        ltp.ofstab(sys, times=[0.0, 1.0, 1.0])         # an empty piece
    with pytest.raises(ControlDimension, match="K0"):
        ltp.ofstab(sys, order=1, K0=np.zeros((2, 1, 1)))   # 3 harmonic parameters
    with pytest.raises(ControlDimension, match="K0"):
        ltp.oflqr(sys, np.eye(2), [[1.0]], K0=np.zeros((1, 2)))
    with pytest.raises(ControlDimension, match="Q"):
        ltp.oflqr(sys, np.eye(3), [[1.0]])
