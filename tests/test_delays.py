"""Periodic delay-differential equations: multipliers against closed forms and independent solvers."""

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
    chart = ltp.stability_chart(milling, rpms, np.linspace(1e-5, 4e-3, 17), n_jobs=1,
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
