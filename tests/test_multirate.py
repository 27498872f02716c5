"""Multirate sampled-data models and the margins of multirate loops.

Truths: an independent exact simulation of the continuous plant (the matrix
exponential over the variable-length intervals between input changes), the
lifted LTI closed loop assembled from the lifted plant and controller with
python-control, python-control's margins of LTI loops, and the LQ cost
measured along a simulation of the continuous plant.
"""

import numpy as np
import control as ct
import pytest
import scipy.linalg as la
from control.exception import ControlDimension

import ltpcontrol as ltp


def _expm_step(A, B, h):
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = A, B
    E = la.expm(M * h)
    return E[:n, :n], E[:n, n:]


def _exact_samples(G, Ts, held, periods, K, x0=None):
    """y(k Ts) of the continuous plant driven by inputs held at their own rates."""
    events = [s for s in range(K + 1) if any(s % q == 0 for q in periods)]
    x = np.zeros(G.nstates) if x0 is None else x0
    y = np.zeros((K, G.noutputs))
    for a, b in zip(events[:-1], events[1:]):
        u = held[a]
        for s in range(a, min(b, K)):
            Ad, Bd = _expm_step(G.A, G.B, (s - a) * Ts)     # one step from the event
            y[s] = G.C @ (Ad @ x + Bd @ u) + G.D @ u
        Ad, Bd = _expm_step(G.A, G.B, (b - a) * Ts)
        x = Ad @ x + Bd @ u
    return y


def test_multirate_period_and_exact_samples():
    rng = np.random.default_rng(0)
    G = ct.rss(3, 2, 2, strictly_proper=False)
    Ts, ki, ko, K = 0.1, [2, 3], [1, 2], 48
    M = ltp.sample_multirate(G, Ts, ki, ko)
    assert M.nsteps == 6 and np.isclose(M.period, 6 * Ts) and M.dt == Ts
    held = np.zeros((K, 2))
    for i, q in enumerate(ki):
        values = rng.standard_normal(K)
        held[:, i] = values[(np.arange(K) // q) * q]
    u = rng.standard_normal((K, 2))          # values between updates are ignored
    upd = np.array([[s % q == 0 for q in ki] for s in range(K)])
    u[upd] = held[upd]
    y = np.asarray(ltp.forced_response(M, np.arange(K) * Ts, u.T).outputs)
    yref = _exact_samples(G, Ts, held, ki, K)
    scale = max(1.0, np.abs(yref).max())
    for j, q in enumerate(ko):
        at = np.arange(0, K, q)
        assert np.abs(y[j, at] - yref[at, j]).max() <= 1e-12 * scale
        # between its samples the output holds the last one
        between = np.arange(K)
        assert np.abs(y[j, between] - y[j, (between // q) * q]).max() <= 1e-14 * scale


def test_multirate_periods_of_the_reference_examples():
    G = ct.ss([[0, -np.pi / 6], [np.pi / 6, 0]], np.eye(2), np.eye(2), 0)
    assert ltp.sample_multirate(G, 1.0).nsteps == 1
    assert ltp.sample_multirate(G, 1.0, [2, 3]).nsteps == 6
    assert ltp.sample_multirate(G, 1.0, None, [1, 2]).nsteps == 2
    Gd = ct.drss(2, 2, 2)
    Gd.dt = 0.5
    assert ltp.sample_multirate(Gd, None, [2, 3], [1, 2]).nsteps == 6
    # an LTI loop at one rate is the ZOH discretization
    single = ltp.sample_multirate(G, 0.3)
    np.testing.assert_allclose(single.A(0.0), ct.c2d(G, 0.3).A, atol=1e-14)


def test_multirate_bad_input_names_the_argument():
    G = ct.rss(2, 2, 2)
    with pytest.raises(ValueError, match="input_periods must hold positive integers"):
        ltp.sample_multirate(G, 0.1, [1.5, 2])
    with pytest.raises(ValueError, match="output_periods must hold positive integers"):
        ltp.sample_multirate(G, 0.1, [1, 2], [0, 1])
    with pytest.raises(ControlDimension, match="input_periods must have 2 entries"):
        ltp.sample_multirate(G, 0.1, [1, 2, 3])
    with pytest.raises(ValueError, match=r"input_periods\[0\] \(101 steps\)"):
        ltp.sample_multirate(G, 0.1, [101, 103], [1, 1])


def _loop(seed):
    """A multirate plant and a periodic static output feedback of its period."""
    rng = np.random.default_rng(seed)
    G = ct.ss([[0.0, 1.0], [-2.0, -0.3]], [[0.0], [1.0]], [[1.0, 0.0], [0.0, 1.0]], 0)
    P = ltp.sample_multirate(G, 0.2, [2], [1, 3])               # period 6 steps
    gains = 0.5 + rng.random((6, 1, 2))
    K = ltp.ltpss(np.zeros((6, 1, 1)), np.zeros((6, 1, 2)), np.zeros((6, 1, 1)), gains,
                  period=P.period, dt=P.dt)
    return P, K


@pytest.mark.parametrize('scale', [0.3, 1.0, 4.0, 12.0])
def test_multirate_loop_verdict_equals_lifted_closed_loop(scale):
    P, K = _loop(1)
    K = K * scale
    closed = ltp.feedback(P, K)
    PL, KL = ltp.lift(P, method='time'), ltp.lift(K, method='time')
    lifted = ct.feedback(PL, KL)
    lifted_stable = bool(np.max(np.abs(np.linalg.eigvals(lifted.A))) < 1)
    assert ltp.is_stable(closed) == lifted_stable


def test_lifted_margins_bracket_the_loss_of_stability():
    P, K = _loop(2)
    loop = ltp.series(P, K)                                   # u -> P -> K -> (fed back)
    gm, pm, gl = ltp.lifted_margins(loop)
    assert 1 < gm < np.inf and 0 < pm <= 180
    for g, expect in ((gm * (1 - 1e-6), True), (gm * (1 + 1e-6), False)):
        assert ltp.is_stable(ltp.feedback(P, K * g)) == expect


def test_lifted_margins_lti_written_as_periodic():
    L = ct.c2d(ct.tf([1.0], [1, 2, 1, 0]), 0.05)
    gm, pm, _ = ltp.lifted_margins(ltp.ltpss(ct.ss(L), period=0.15))
    want = ct.stability_margins(L, method='frd')
    assert np.isclose(gm, want[0], rtol=1e-6) and np.isclose(pm, want[1], rtol=1e-6)


def test_multirate_lq_controller_verified_on_the_continuous_plant():
    # fast input (every step), slow output; LQ state feedback on the periodic
    # model, its cost checked along an exact simulation of the continuous plant
    G = ct.ss([[0.0, 1.0], [3.0, -0.2]], [[0.0, 0.0], [1.0, 0.5]], [[1.0, 0.0]], 0)
    Ts, ki = 0.05, [1, 3]
    M = ltp.sample_multirate(G, Ts, ki, [2])
    N = M.nsteps
    Q = np.diag([1.0, 0.1, 0.0, 0.0])
    Kp, X, E = ltp.dlqr(M, Q, np.eye(2))
    assert np.all(np.abs(E) < 1)
    z = np.array([1.0, 0.0, 0.0, 0.0])
    x, held, cost = z[:2].copy(), np.zeros(2), 0.0
    for s in range(600):
        u = -Kp(s * Ts) @ z
        cost += z @ Q @ z + u @ u
        for i, q in enumerate(ki):
            if s % q == 0:
                held[i] = u[i]
        Ad, Bd = _expm_step(G.A, G.B, Ts)
        x = Ad @ x + Bd @ held                                # the continuous plant
        y_hold = z[3] if s % 2 else (G.C @ z[:2])[0]
        z = np.array([x[0], x[1], held[1], y_hold])
    assert abs(x).max() < 1e-6
    z0 = np.array([1.0, 0.0, 0.0, 0.0])
    assert abs(cost - z0 @ X(0.0) @ z0) <= 1e-8 * cost
    # the Kalman predictor of the same model is stable
    L, P, Ee = ltp.dlqe(M, np.eye(2), [[0.01]])
    assert np.all(np.abs(Ee) < 1)


def test_multirate_periodic_plant_against_solve_ivp():
    from scipy.integrate import solve_ivp
    Ts = 0.05
    T = 4 * Ts
    b = lambda t: np.array([[0.0], [1.0 + 0.5 * np.cos(2 * np.pi * t / T)]])
    plant = ltp.ltpss([[0.0, 1.0], [-2.0, -0.3]], b, [[1.0, 0.0]], 0, period=T)
    M = ltp.sample_multirate(plant, Ts, [3], [2])
    assert M.nsteps == 12
    rng = np.random.default_rng(4)
    K = 36
    held = rng.standard_normal(K)[(np.arange(K) // 3) * 3]
    y = np.asarray(ltp.forced_response(M, np.arange(K) * Ts, held[None, :]).outputs)
    sol = solve_ivp(lambda t, x: plant.A(t) @ x + b(t)[:, 0] * held[min(int(t / Ts + 1e-9), K - 1)],
                    (0, (K - 1) * Ts), np.zeros(2), t_eval=np.arange(K) * Ts, rtol=1e-11,
                    atol=1e-13, max_step=Ts / 4)
    at = np.arange(0, K, 2)
    assert np.abs(y[at] - sol.y[0, at]).max() < 1e-8
