"""Time responses: LTI limit, thesis systems against independent integration."""

import numpy as np
import control as ct
import pytest
from control.exception import ControlArgument, ControlDimension
from scipy.integrate import solve_ivp

import ltpcontrol as ltp
from systems import mathieu, switching_mathieu


def reference(f, t, x0, breaks=()):
    """solve_ivp (DOP853, rtol 1e-11) of ẋ = f(t, x), restarted at `breaks` and samples."""
    x = np.empty((len(x0), len(t)))
    x[:, 0] = x0
    edges = np.unique(np.concatenate([t, [b for b in breaks if t[0] < b < t[-1]]]))
    xk = np.asarray(x0, float)
    for a, b in zip(edges[:-1], edges[1:]):
        sol = solve_ivp(f, (a, b), xk, method='DOP853', rtol=1e-11, atol=1e-13)
        xk = sol.y[:, -1]
        hit = np.isclose(t, b, rtol=0, atol=1e-12)
        if hit.any():
            x[:, hit] = xk[:, None]
    return x


def test_lti_limit_equals_python_control():
    # seeded: ct.rss occasionally draws ‖A‖ ~ 1e6 with slow poles, where the
    # step exponential itself is conditioned worse than the 1e-9 asked here
    np.random.seed(11)
    G = ct.rss(4, 2, 2, strictly_proper=False)
    sys = ltp.ltpss(G, 0.37)
    t = np.linspace(0, 10, 1001)
    u = np.vstack([np.sin(2 * t), np.sign(np.cos(t))])
    x0 = np.arange(1.0, 5.0)
    ours = ltp.forced_response(sys, t, u, x0)
    ref = ct.forced_response(G, t, u, x0)
    scale = np.abs(ref.y).max()
    np.testing.assert_allclose(ours.y, ref.y, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(ours.x, ref.x, rtol=0, atol=1e-9 * np.abs(ref.x).max())
    step, step_ref = ltp.step_response(sys, t), ct.step_response(G, t)
    np.testing.assert_allclose(step.y, step_ref.y, rtol=0, atol=1e-9 * np.abs(step_ref.y).max())
    Gs = ct.rss(3, 1, 2, strictly_proper=True)
    imp, imp_ref = ltp.impulse_response(ltp.ltpss(Gs, 1.0), t), ct.impulse_response(Gs, t)
    np.testing.assert_allclose(imp.y, imp_ref.y, rtol=0, atol=1e-9 * np.abs(imp_ref.y).max())
    ini = ltp.initial_response(sys, t, x0)
    np.testing.assert_allclose(ini.y, ct.initial_response(G, t, x0).y, rtol=0,
                               atol=1e-9 * np.abs(ini.y).max())


def test_lti_limit_discrete_equals_python_control():
    G = ct.drss(3, 1, 2)
    G.dt = 0.1
    sys = ltp.ltpss(G, 0.5)
    t = np.arange(50) * 0.1
    u = np.vstack([np.sin(t), np.cos(3 * t)])
    np.testing.assert_allclose(ltp.forced_response(sys, t, u, [1, 0, -1]).y,
                               ct.forced_response(G, t, u, [1, 0, -1]).y, rtol=1e-12, atol=1e-14)


def test_mathieu_matches_solve_ivp():
    sys = mathieu()
    t = np.arange(0, 2.0, 0.01)
    u = np.cos(2 * np.pi * 0.35 * t) + 0.5 * np.sin(11 * t)
    x0 = [0.1, -0.2]
    ours = ltp.forced_response(sys, t, u, x0)
    wp = 4 * np.pi

    def f(tau, x):
        ui = np.interp(tau, t, u)          # the same piecewise-linear input
        return [x[1], -(2 * np.pi) ** 2 * x[0] - 1.2 * np.pi * x[1]
                + (1 + 0.4 * np.cos(wp * tau)) * ui]
    x = reference(f, t, x0)
    y = (1 + 0.2 * np.cos(wp * t)) * x[0]
    assert np.abs(ours.y - y).max() <= 1e-8 * np.abs(y).max()


def test_switching_system_with_switch_inside_sample_interval():
    ts = 0.2537                              # not a multiple of the 0.01 s grid
    sys = switching_mathieu(t_switch=ts)
    t = np.arange(0, 2.0, 0.01)
    u = np.sin(2 * np.pi * 0.6 * t)
    x0 = [0.05, 0.3]
    ours = ltp.forced_response(sys, t, u, x0)
    wn, wp = 2 * np.pi, 4 * np.pi

    def f(tau, x):
        first = (tau % 0.5) < ts
        zeta, beta = (0.3, 0.1) if first else (0.1, 0.2)
        return [x[1], -(1 + 2 * beta * np.cos(wp * tau)) * wn ** 2 * x[0]
                - 2 * zeta * wn * x[1] + np.interp(tau, t, u)]
    breaks = np.concatenate([np.arange(0, 2.5, 0.5), np.arange(0, 2.5, 0.5) + ts])
    x = reference(f, t, x0, breaks)
    assert np.abs(ours.y - x[0]).max() <= 1e-8 * np.abs(x[0]).max()
    # the reference path of the library agrees too
    ivp = ltp.forced_response(sys, t[:60], u[:60], x0, method='solve_ivp', rtol=1e-11)
    assert np.abs(ivp.y - x[0, :60]).max() <= 1e-8 * np.abs(x[0]).max()


def test_many_traces_in_one_call_equal_single_calls():
    sys = mathieu()
    t = np.arange(0, 3.0, 0.01)
    freqs = np.array([0.25, 0.35, 1.15])
    U = np.cos(2 * np.pi * freqs[:, None] * t)[None]          # (1 input, 3 traces, L)
    batch = ltp.forced_response(sys, t, U)
    assert batch.outputs.shape == (1, 3, len(t)) and batch.ntraces == 3
    for r in range(3):
        single = ltp.forced_response(sys, t, U[0, r])
        np.testing.assert_allclose(batch.y[0, r], single.y[0], rtol=1e-13, atol=1e-15)


def test_zoh_hold_equals_exact_sampling():
    G = ct.rss(3, 1, 1)
    sys = ltp.ltpss(G, 0.3)
    t = np.arange(40) * 0.05
    u = np.sin(3 * t)
    Gd = ct.sample_system(G, 0.05, 'zoh')
    np.testing.assert_allclose(ltp.forced_response(sys, t, u, input_hold='zoh').y,
                               ct.forced_response(Gd, t, u).y, rtol=1e-10, atol=1e-13)


def test_discrete_periodic_system_matches_recursion():
    rng = np.random.default_rng(3)
    A = 0.5 * rng.normal(size=(5, 2, 2))
    B = rng.normal(size=(5, 2, 1))
    C = rng.normal(size=(5, 1, 2))
    sys = ltp.ltpss(A, B, C, 0, period=0.5, dt=0.1)
    t = np.arange(23) * 0.1 + 0.2               # starts at phase k = 2
    u = rng.normal(size=23)
    x = np.array([1.0, -1.0])
    y = []
    for i in range(23):
        k = (i + 2) % 5
        y.append((C[k] @ x).item())
        x = A[k] @ x + B[k, :, 0] * u[i]
    np.testing.assert_allclose(ltp.forced_response(sys, t, u, [1, -1]).y[0], y, rtol=1e-12)


def test_time_response_data_is_plottable():
    resp = ltp.step_response(mathieu(), 2.0)
    cplt = resp.plot()
    assert type(cplt).__name__ == 'ControlPlot'


@pytest.mark.parametrize("call, exc, match", [
    (lambda: ltp.forced_response(mathieu(), [0, 1, 0.5], [0, 0, 0]), ValueError, "increasing"),
    (lambda: ltp.forced_response(mathieu(), np.arange(5.0), np.zeros(4)), ControlDimension,
     "inputs"),
    (lambda: ltp.forced_response(mathieu(), np.arange(5.0), np.zeros(5), [1, 2, 3]),
     ControlDimension, "initial_state"),
    (lambda: ltp.forced_response(mathieu(), np.arange(5.0), np.full(5, np.nan)),
     ValueError, "inputs"),
    (lambda: ltp.forced_response(mathieu(), np.arange(5.0), 0, method='rk4'), ValueError,
     "method"),
    (lambda: ltp.forced_response(mathieu(), np.arange(5.0), 0, input_hold='cubic'),
     ValueError, "input_hold"),
    (lambda: ltp.forced_response(ct.rss(2), np.arange(5.0)), ControlArgument, "LTI"),
    (lambda: ltp.forced_response(mathieu(), np.arange(5.0), 0, foo=1), TypeError,
     "unrecognized"),
    (lambda: ltp.step_response(mathieu(), 1.0, input_indices=[3]), ValueError, "input_indices"),
    (lambda: ltp.forced_response(ltp.ltpss([[0.5]], [[1]], [[1]], 0, period=1.0, dt=0.1),
                                 [0, 0.15], 0), ValueError, "multiples of dt"),
])
def test_bad_input(call, exc, match):
    with pytest.raises(exc, match=match):
        call()
