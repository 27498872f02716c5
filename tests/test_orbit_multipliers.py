"""Multipliers of stiff orbits to relative accuracy, against independent references."""

import numpy as np
import pytest
import control as ct
from scipy.integrate import solve_ivp
from scipy.linalg import expm
from scipy.optimize import fsolve

import ltpcontrol as ltp


def vdp(t, x, u, p):
    return [x[1], p['mu'] * (1 - x[0] ** 2) * x[1] - x[0]]


def vdp_jac(t, x, u, p):
    return [[0, 1], [-2 * p['mu'] * x[0] * x[1] - 1, p['mu'] * (1 - x[0] ** 2)]]


def liouville_integral(mu, x0, period):
    """∮ div f dt along the orbit through x0, integrated independently."""
    def rhs(t, z):
        return [z[1], mu * (1 - z[0] ** 2) * z[1] - z[0], mu * (1 - z[0] ** 2)]
    sol = solve_ivp(rhs, (0, period), [*x0, 0.0], method='DOP853', rtol=1e-13, atol=1e-14)
    return sol.y[2, -1]


@pytest.mark.parametrize('mu', [0.7, 2.5, 5.0, 10.0])
def test_van_der_pol_multiplier_relative_accuracy(mu):
    sys = ct.nlsys(vdp, None, states=2, inputs=0, params={'mu': mu})
    orbit = ltp.limit_cycle(sys, None, [2.0, 0.0], section=lambda x: x[1], direction=-1,
                            jacobian=vdp_jac)
    # phase multiplier 1: the other one is exp ∮ div f (Liouville)
    ref = liouville_integral(mu, orbit.x0, orbit.period)
    (lam,) = orbit.stability_multipliers
    assert abs(orbit.phase_multiplier - 1) < 1e-7
    assert abs(lam / np.exp(ref) - 1) < 1e-6                    # 7.7e-38 at mu = 5
    assert abs(orbit.log_multipliers[1] - ref) < 1e-6
    # the error estimate is honest and small
    assert abs(orbit.log_multipliers[1] - ref) <= 10 * orbit.multiplier_error
    assert orbit.multiplier_error < 1e-6
    assert orbit.is_stable


def test_van_der_pol_finite_difference_jacobian():
    mu = 5.0
    sys = ct.nlsys(vdp, None, states=2, inputs=0, params={'mu': mu})
    orbit = ltp.limit_cycle(sys, None, [2.0, 0.0], section=lambda x: x[1], direction=-1)
    ref = liouville_integral(mu, orbit.x0, orbit.period)
    assert abs(orbit.stability_multipliers[0] / np.exp(ref) - 1) < 1e-6


# relay feedback with hysteresis on a stiff plant (poles -1 and -100): a
# piecewise-linear hybrid orbit with closed-form flows and saltations
K, C_DAMP, EPS = 100.0, 101.0, 0.005
A = np.array([[0.0, 1.0], [-K, -C_DAMP]])
B, C = np.array([0.0, 1.0]), np.array([1.0, 0.02])


def relay_plant():
    def field(u):
        return lambda t, x, _, p: A @ x + B * u
    plus = ltp.HybridMode(field(1.0), guard=lambda t, x, u, p: EPS - C @ x, target='minus',
                          name='plus', jacobian=lambda t, x, u, p: A)
    minus = ltp.HybridMode(field(-1.0), guard=lambda t, x, u, p: C @ x + EPS, target='plus',
                           name='minus', jacobian=lambda t, x, u, p: A)
    return ltp.HybridPlant([plus, minus], states=2)


def relay_reference(period_guess):
    """Symmetric cycle in closed form: switch point x_s and log of the multiplier."""
    eq_minus = np.linalg.solve(A, B)        # equilibrium of ẋ = A x − B

    def equations(z):
        xs, tau = z[:2], z[2]
        # half a period in mode minus from x_s ends at −x_s
        return np.r_[expm(A * tau) @ (xs - eq_minus) + eq_minus + xs, C @ xs - EPS]
    z = fsolve(equations, [EPS, 0.0, period_guess / 2], xtol=1e-14)
    assert np.max(np.abs(equations(z))) < 1e-14
    xs, tau = z[:2], z[2]
    # det e^{Aτ} = e^{τ tr A}; det S = (∇g·f⁺)/(∇g·f⁻) for an identity reset
    before, after = A @ xs + B, A @ xs - B
    return 2 * tau, 2 * tau * np.trace(A) + 2 * np.log(abs((C @ after) / (C @ before)))


def test_stiff_hybrid_orbit_multiplier_relative_accuracy():
    orbit = ltp.limit_cycle(relay_plant(), 2.2, [0.0, 0.01], 'plus', section=lambda x: x[0],
                            direction=1)
    period, logmu = relay_reference(orbit.period)
    assert abs(orbit.period - period) < 1e-8
    assert len(orbit.saltation_matrices) == 2
    assert logmu < -200                                     # multiplier about 1e-94
    (lam,) = orbit.stability_multipliers
    assert abs(lam / np.exp(logmu) - 1) < 1e-6
    assert abs(orbit.log_multipliers[1] - logmu) <= 10 * orbit.multiplier_error
    assert orbit.multiplier_error < 1e-6
    # the formed monodromy cannot resolve it
    formed = np.abs(np.linalg.eigvals(orbit.monodromy)).min()
    assert not abs(formed / np.exp(logmu) - 1) < 0.5


def test_forced_stiff_orbit():
    # ẋ = diag(-1, -60) x + forcing: multipliers e^{-2π}, e^{-120π} (1e-164)
    def f(t, x, u, p):
        return [-x[0] + np.cos(t), -60 * x[1] + x[0] ** 2]
    sys = ct.nlsys(f, None, states=2, inputs=0)
    orbit = ltp.periodic_orbit(sys, 2 * np.pi, [0.5, 0.0])
    assert np.allclose(orbit.log_multipliers, [-2 * np.pi, -120 * np.pi], rtol=1e-9)
