"""Periodic delay-differential equations: multipliers against closed forms and independent solvers."""

import control as ct
import numpy as np
import pytest

import ltpcontrol as ltp
from delay_systems import (delayed_mathieu, milling, milling_h, mos_multipliers, turning,
                           turning_critical, MILL)


def test_turning_critical_depth_equals_closed_form_lobes():
    # five spindle speeds on four lobes; three written with the delay as period, two with an
    # unrelated period (the history then spans several periods)
    taus = np.array([3.0, 5.0, 8.0, 13.0, 21.0])
    periods = {3.0: 3.0, 5.0: 2.0, 8.0: 8.0, 13.0: 13.0, 21.0: 7.3}
    chart = ltp.stability_chart(lambda tau, w: turning(tau, w, period=periods[tau]), taus,
                                [0.0, 0.45], n_jobs=1, tol=1e-9)
    crit = chart.critical()
    ref = np.array([turning_critical(t) for t in taus])
    np.testing.assert_allclose(crit, ref, rtol=1e-6)


def _dcurve_distance(delta, b, kappa):
    """Relative distance of (δ, b) to the closed-form ε = 0 boundaries (λ = 0 and λ = jω)."""
    best = abs(b - delta) / max(1.0, abs(b))
    for k in range(0, 12):
        lo, hi = k / 2 + 1e-12, (k + 1) / 2 - 1e-12
        f = lambda w: w**2 - kappa * w / np.tan(2 * np.pi * w) - delta
        if f(lo) * f(hi) > 0:
            continue
        from scipy.optimize import brentq
        w = brentq(f, lo, hi, xtol=1e-15)
        bw = -kappa * w / np.sin(2 * np.pi * w)
        best = min(best, abs(bw - b) / max(1.0, abs(b)))
    return best


def test_delayed_mathieu_without_forcing_equals_closed_form_d_curves():
    kappa = 0.1
    deltas = np.array([0.1, 0.3, 1.0, 2.2])
    chart = ltp.stability_chart(lambda d, b: delayed_mathieu(d, b, 0.0, kappa), deltas,
                                np.linspace(-1.5, 1.5, 13), n_jobs=1, tol=1e-9)
    assert len(chart.boundary) >= 6 and not chart.failures
    assert len(set(chart.boundary[:, 0])) >= 3
    for d, b in chart.boundary:
        assert _dcurve_distance(d, b, kappa) < 1e-7, (d, b)


def test_delayed_mathieu_boundary_converges_and_equals_method_of_steps():
    # ε = 1: boundary in b at δ = 2.5 from two discretization degrees, then the independent
    # solve_ivp monodromy puts its dominant multiplier on the unit circle there
    kappa, eps, delta = 0.1, 1.0, 2.5
    fam = lambda d, b: delayed_mathieu(d, b, eps, kappa)
    c16 = ltp.stability_chart(fam, [delta], np.linspace(-1.0, 1.0, 9), n_jobs=1, tol=1e-11,
                              order=16)
    c24 = ltp.stability_chart(fam, [delta], np.linspace(-1.0, 1.0, 9), n_jobs=1, tol=1e-11,
                              order=24)
    assert len(c16.boundary) == 2
    np.testing.assert_allclose(c16.boundary, c24.boundary, rtol=1e-8, atol=1e-10)
    F = lambda t: np.array([[0.0, 1.0], [-delta - eps * np.cos(t), -kappa]])
    for _, b in c24.boundary[:1]:
        rho = lambda bb: abs(mos_multipliers(F, lambda t: bb, 2 * np.pi, (0.0, 2 * np.pi),
                                             M=24)[0])
        slope = (abs(ltp.floquet_multipliers(fam(delta, b * (1 + 1e-4)))[0])
                 - abs(ltp.floquet_multipliers(fam(delta, b * (1 - 1e-4)))[0])) / (2e-4 * b)
        assert abs((rho(b) - 1) / slope) < 1e-8 * max(1.0, abs(b))


@pytest.mark.slow
def test_milling_critical_depth_equals_method_of_steps():
    # Insperger-Stépán's 1-DOF benchmark: up-milling, 2 teeth, 5 % radial immersion
    rpms = np.array([6000.0, 7500.0, 10000.0, 15500.0, 19000.0])
    chart = ltp.stability_chart(milling, rpms, np.linspace(1e-5, 4e-3, 13), n_jobs=1,
                                tol=1e-9)
    crit = chart.critical()
    assert np.all(np.isfinite(crit)) and not chart.failures
    wn, zeta, m = 2 * np.pi * MILL['fn'], MILL['zeta'], MILL['m']
    for rpm, ap in zip(rpms, crit):
        h, t_ex, T = milling_h(rpm)
        F = lambda t: np.array([[0.0, 1.0], [-wn**2 - ap * h(t) / m, -2 * zeta * wn]])
        mu = abs(mos_multipliers(F, lambda t: ap * h(t) / m, T, (0.0, t_ex), M=14,
                                 rtol=1e-10, constant_outside=True)[0])
        slope = (abs(ltp.floquet_multipliers(milling(rpm, ap * 1.001))[0])
                 - abs(ltp.floquet_multipliers(milling(rpm, ap * 0.999))[0])) / (0.002 * ap)
        assert abs((mu - 1) / slope) < 1e-6 * ap, (rpm, ap)


#
# Frequency and time domain
#

def test_htf_of_lti_plant_with_input_delay_equals_exp_times_g():
    G = ct.rss(3, 2, 2, strictly_proper=False)
    T, tau = 0.7, 0.33
    sys = ltp.series(ltp.delay(tau), ltp.ltpss(G, T))
    H = ltp.htf(sys, 3)
    for s in (0.3 + 1.7j, 2.1j, -0.2 + 0.4j):
        Hs = H(s)
        for k in range(-3, 4):
            sk = s + 1j * k * 2 * np.pi / T
            blk = Hs[(k + 3) * 2:(k + 4) * 2, (k + 3) * 2:(k + 4) * 2]
            ref = np.exp(-sk * tau) * G(sk)
            np.testing.assert_allclose(blk, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    off = Hs.copy()
    for k in range(7):
        off[2 * k:2 * k + 2, 2 * k:2 * k + 2] = 0
    assert np.max(np.abs(off)) == 0


def test_htf_of_periodic_state_delay_system_solves_the_harmonic_balance():
    # x' = a(t) x + b x(t - tau) + u: the HTF column of harmonic 0 satisfies the harmonic
    # balance (s_k - ...) X_k = U_k with the delay exact, checked by a long simulation's
    # steady-state response to a sinusoid
    T, tau, w = 1.0, 0.3, 2.0
    a = ltp.PeriodicMatrix.from_function(lambda t: np.array([[-2.0 + 0.5 * np.cos(2 * np.pi * t)]]), T)
    sys = ltp.ltpdss(a, [[1.0]], [[1.0]], 0, period=T, delays=[(tau, [[0.7]])])
    H = ltp.htf(sys, 2, internal_harmonics=14)
    t = np.arange(0, 16.0 + 1e-9, 0.01)
    r = ltp.forced_response(sys, t, np.cos(w * t))
    Hs = H(1j * w)
    tail = t > 12
    # steady state: y = Re Σ_k H_{k,0}(jw) e^{j(w + k ω_p) t}
    pred = sum((Hs[k + 2, 2] * np.exp(1j * (w + k * 2 * np.pi / T) * t[tail])).real
               for k in range(-2, 3))
    np.testing.assert_allclose(r.outputs[tail], pred, atol=2e-4)


def _mos_reference(A, Ad, tau, hist, t, u, c):
    from scipy.integrate import solve_ivp
    brk = np.unique(np.concatenate([t, np.arange(0, t[-1], tau), [t[-1]]]))
    segs, x0 = [], hist(0.0)

    def xdel(s):
        if s < 0:
            return hist(s)
        for a, b, sol in segs:
            if a - 1e-12 <= s <= b + 1e-12:
                return sol(min(max(s, a), b))
    for a, b in zip(brk[:-1], brk[1:]):
        sol = solve_ivp(lambda s, x: A(s) @ x + Ad @ xdel(s - tau)
                        + np.array([0, 1.0]) * np.interp(s, t, u), (a, b), x0,
                        method='DOP853', rtol=1e-13, atol=1e-13, dense_output=True)
        segs.append((a, b, sol.sol))
        x0 = sol.y[:, -1]
    return np.array([c @ xdel(s) for s in t])


def test_forced_response_with_history_equals_method_of_steps():
    T, tau = 1.0, 0.37            # the delay is not a multiple of the time step
    A = lambda t: np.array([[0.0, 1.0], [-4 - np.cos(2 * np.pi * t), -0.3]])
    Ad = np.array([[0.0, 0.0], [0.8, 0.1]])
    sys = ltp.ltpdss(A, [[0.0], [1.0]], [[1.0, 0.5]], 0, period=T, delays=[(tau, Ad)])
    hist = lambda s: np.array([np.sin(s), np.cos(s)])
    t = np.linspace(0, 2, 101)
    u = np.sin(3 * t)
    r = ltp.forced_response(sys, t, u, hist(0.0), history=hist)
    ref = _mos_reference(A, Ad, tau, hist, t, u, np.array([1.0, 0.5]))
    np.testing.assert_allclose(r.outputs, ref, atol=1e-8)
    # the sampled-history form and a batch of two traces give the same
    th = np.linspace(-0.5, 0.0, 2001)
    r2 = ltp.forced_response(sys, t, np.stack([u, u])[None], np.stack([hist(0.0)] * 2, 1),
                             history=hist)
    np.testing.assert_allclose(r2.outputs[0], np.stack([r.outputs] * 2), atol=1e-12)
    r3 = ltp.forced_response(sys, t, u, hist(0.0), history=(th, hist(th)))
    np.testing.assert_allclose(r3.outputs, r.outputs, atol=1e-6)


#
# Block diagrams with delays
#

def test_feedback_through_a_delay_is_the_state_delay_system():
    T, tau, k = 1.0, 0.45, 0.8
    b = lambda t: np.array([[0.0], [1 + 0.3 * np.cos(2 * np.pi * t)]])
    P = ltp.ltpss([[0.0, 1.0], [-1.0, -0.2]], b, [[1.0, 0.0]], 0, period=T)
    loop = ltp.feedback(P, k * ltp.delay(tau))
    Bk = ltp.PeriodicMatrix.from_function(lambda t: -k * b(t) @ np.array([[1.0, 0.0]]), T)
    direct = ltp.ltpdss(P.A, P.B, P.C, 0, period=T, delays=[(tau, Bk)])
    np.testing.assert_allclose(ltp.floquet_multipliers(loop)[:4],
                               ltp.floquet_multipliers(direct)[:4], atol=1e-10)
    # the same loop by signal names, and with the delay in the forward path
    Pn = ltp.ltpss(P.A, P.B, P.C, 0, period=T, inputs='u', outputs='y', name='P')
    D = ltp.delay(tau, inputs='y', outputs='yd', name='D')
    loop2 = ltp.interconnect([Pn, D, ct.summing_junction(['r', f'-yd'], 'e'),
                              ct.tf(k, 1, inputs='e', outputs='u', name='K')],
                             inplist='r', outlist='y')
    np.testing.assert_allclose(ltp.floquet_multipliers(loop2)[:4],
                               ltp.floquet_multipliers(direct)[:4], atol=1e-10)
    fwd = ltp.feedback(ltp.series(ltp.delay(tau), P), k)
    assert fwd.state_delays and abs(ltp.floquet_multipliers(fwd)[0]
                                    - ltp.floquet_multipliers(direct)[0]) < 1e-10


def test_delay_in_a_discrete_loop_is_a_shift_register():
    P = ltp.ltpss([[0.9]], lambda t: np.array([[1 + 0.5 * np.cos(2 * np.pi * t)]]), [[1.0]], 0,
                  period=1.0).sample(0.1)
    L = ltp.feedback(P, 0.3 * ltp.delay(0.2))
    assert isinstance(L, ltp.LTPStateSpace) and L.nstates == 3
    # x[k+1] = a x[k] + b[k] (u - 0.3 x[k-2])
    Ad, Bd = P.A.sample(10)[:, 0, 0], P.B.sample(10)[:, 0, 0]
    x, xs = 0.0, [0.0, 0.0]
    out = []
    for k in range(25):
        out.append(x)
        xn = Ad[k % 10] * x + Bd[k % 10] * (1.0 - 0.3 * xs[-2])
        xs.append(x)
        x = xn
    r = ltp.forced_response(L, np.arange(25) * 0.1, np.ones(25))
    np.testing.assert_allclose(r.outputs, out, atol=1e-12)
    with pytest.raises(ValueError, match="whole number of steps"):
        ltp.feedback(P, ltp.delay(0.15))


def test_delay_margin_of_lti_loop_written_as_periodic_equals_phase_margin_over_crossover():
    G = ct.tf([3.0], [1.0, 1.0, 0.0])               # 3 / (s (s + 1))
    gm, pm, wg, wc = ct.margin(G)
    dm = ltp.delay_margin(ltp.ltpss(G, 0.8), max_delay=2.0, num=8, tol=1e-8)
    np.testing.assert_allclose(dm, np.deg2rad(pm) / wc, rtol=1e-6)
    # a periodic loop: unstable beyond the margin, stable below it
    b = lambda t: np.array([[0.0], [1 + 0.5 * np.cos(2 * np.pi * t / 0.8)]])
    L = ltp.ltpss([[0.0, 1.0], [0.0, -1.0]], b, [[3.0, 0.0]], 0, period=0.8)
    dm = ltp.delay_margin(L, max_delay=2.0, num=8, tol=1e-5)
    for d, stable in ((dm * 0.999, True), (dm * 1.001, False)):
        assert ltp.is_stable(ltp.feedback(ltp.series(ltp.delay(d), L), 1.0)) == stable


#
# Charts: parallel, partial results
#

def _family(a, b):
    if a > 1.5 and b > 0.5:
        raise RuntimeError("no model here")
    return ltp.ltpdss([[-a]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(1.0, [[b]])])


def test_chart_keeps_finished_points_when_the_factory_raises():
    x, y = [1.0, 2.0], [-0.5, 0.2, 1.0, 2.5]
    with pytest.raises(ltp.StabilityChartError, match="2 of 8 points failed") as info:
        ltp.stability_chart(_family, x, y, n_jobs=1)
    chart = info.value.chart
    assert np.isfinite(chart.radius).sum() == 6 and len(chart.failures) == 2
    with pytest.warns(UserWarning, match="failed"):
        kept = ltp.stability_chart(_family, x, y, n_jobs=1, on_error='keep')
    np.testing.assert_array_equal(np.isnan(kept.radius), np.isnan(chart.radius))
    # |b| < a is stable: the boundary b = a on the first column
    np.testing.assert_allclose(kept.critical()[0], 1.0, rtol=1e-8)


def test_chart_parallel_equals_serial():
    x, y = np.array([0.5, 1.0, 1.5]), np.linspace(0.0, 2.0, 5)
    fam = lambda a, b: ltp.ltpdss([[-a]], [[1.0]], [[1.0]], 0, period=1.0,
                                  delays=[(1.0, [[b]])])
    serial = ltp.stability_chart(fam, x, y, n_jobs=1)
    par = ltp.stability_chart(fam, x, y, n_jobs=2, backend='threading', progress=True)
    np.testing.assert_allclose(par.radius, serial.radius, rtol=1e-12)
    np.testing.assert_allclose(par.boundary, serial.boundary, rtol=1e-12)
    cplt = par.plot()
    assert cplt.axes.shape == (1, 1)


def test_chart_runs_on_a_dask_client():
    distributed = pytest.importorskip('dask.distributed')
    fam = lambda a, b: ltp.ltpdss([[-a]], [[1.0]], [[1.0]], 0, period=1.0,
                                  delays=[(1.0, [[b]])])
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=2,
                            dashboard_address=None):
        chart = ltp.stability_chart(fam, [0.5, 1.5], [0.0, 2.0], backend='dask', n_jobs=2)
    np.testing.assert_allclose(chart.critical(), [0.5, 1.5], rtol=1e-8)


#
# Bad input
#

@pytest.mark.parametrize("delays, match", [
    ([(-1.0, [[0.1]])], "finite positive"), ([(np.nan, [[0.1]])], "finite positive"),
    ([(0.0, [[0.1]])], "finite positive"), ([(np.inf, [[0.1]])], "finite positive"),
    ([(0.5, [[0.1, 0.2]])], "columns"), ([0.5], "pair")])
def test_bad_delays_are_refused(delays, match):
    with pytest.raises((ValueError, ct.ControlDimension, ct.ControlArgument), match=match):
        ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=delays)
    with pytest.raises(ValueError, match="finite positive"):
        ltp.delay(-0.1)


def test_history_shorter_than_the_delay_is_refused():
    sys = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(0.5, [[0.3]])])
    th = np.linspace(-0.2, 0.0, 5)
    with pytest.raises(ValueError, match="needs"):
        ltp.forced_response(sys, np.linspace(0, 1, 11), 0.0, 1.0,
                            history=(th, np.ones((1, 5))))
    with pytest.raises(TypeError, match="nsteps"):
        ltp.floquet_multipliers(sys, 10)
    with pytest.raises(ct.ControlArgument, match="LTPStateSpace"):
        ltp.lqr(sys, np.eye(1), np.eye(1))
