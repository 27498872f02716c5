"""Property-based checks of the core algebra against independent truths.

* feedback of two LTP systems with periodic direct terms equals scipy's
  integration of the coupled equations with the algebraic loop solved;
* a periodic change of state ``x = Q(t) z`` leaves the Floquet multipliers and
  the input-output behaviour unchanged;
* the frequency lifting's poles are the N-th roots of the Floquet multipliers;
* exact first-order-hold sampling reproduces the simulation at the samples.
"""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

FAST = settings(derandomize=True, max_examples=5, deadline=None, database=None)
seeds = st.integers(min_value=0, max_value=2 ** 32 - 1)
T = 1.0
WP = 2 * np.pi / T


def _stable(rng, n, margin=0.5):
    A = rng.standard_normal((n, n))
    return A - (np.max(np.linalg.eigvals(A).real) + margin) * np.eye(n)


def _periodic(rng, rows, cols, scale=0.4):
    """Smooth random periodic matrix M0 + M1 cos(ωt) + M2 sin(ωt) as arrays and callable."""
    M0, M1, M2 = (rng.standard_normal((rows, cols)) * s for s in (1.0, scale, scale))
    return lambda t: M0 + M1 * np.cos(WP * t) + M2 * np.sin(WP * t)


def _random_ltp(rng, n, m, p, scale_d=1.0, functions=False):
    A0 = _stable(rng, n)
    A1 = 0.5 * rng.standard_normal((n, n))
    D = _periodic(rng, p, m, 0.1)
    mats = (lambda t: A0 + A1 * np.cos(WP * t), _periodic(rng, n, m), _periodic(rng, p, n),
            lambda t: scale_d * D(t))
    sys = ltp.ltpss(*mats, T)
    return (sys, mats) if functions else sys


@pytest.mark.slow
@FAST
@given(seed=seeds, sign=st.sampled_from([-1, 1]))
def test_feedback_matches_coupled_integration(seed, sign):
    rng = np.random.default_rng(seed)
    P1, f1 = _random_ltp(rng, 2, 1, 1, functions=True)
    # keep the algebraic loop well posed: |D1 D2| <= 0.5
    d1 = np.abs(P1.D.sample(64)).max()
    P2, f2 = _random_ltp(rng, 1, 1, 1, scale_d=min(1.0, 0.5 / (1.5 * d1 + 1e-9)),
                         functions=True)
    L = ltp.feedback(P1, P2, sign)
    t = 0.2 + 0.1 * np.arange(21)
    u = 0.5 - 0.7 * t                      # linear: exact for the first-order hold

    def loop(tau, x):
        x1, x2 = x[:2], x[2:]
        uu = 0.5 - 0.7 * tau
        A1, B1, C1, D1 = (f(tau) for f in f1)
        A2, B2, C2, D2 = (f(tau) for f in f2)
        # y1 = C1 x1 + D1 (u + s (C2 x2 + D2 y1))
        y1 = np.linalg.solve(np.eye(1) - sign * D1 @ D2,
                             C1 @ x1 + D1 @ (uu + sign * C2 @ x2))
        u1 = uu + sign * (C2 @ x2 + D2 @ y1)
        return np.concatenate([A1 @ x1 + B1 @ u1, A2 @ x2 + B2 @ y1])

    x0 = rng.standard_normal(3)
    xs = solve_ivp(loop, (t[0], t[-1]), x0, method='DOP853', t_eval=t, rtol=1e-12,
                   atol=1e-14).y
    resp = ltp.forced_response(L, t, u, x0, return_states=True)
    assert np.abs(resp.states - xs).max() < 1e-8 * (1 + np.abs(xs).max())


@pytest.mark.slow
@FAST
@given(seed=seeds, amp=st.floats(0.05, 0.4))
def test_periodic_change_of_state_is_invisible(seed, amp):
    rng = np.random.default_rng(seed)
    sys = _random_ltp(rng, 2, 1, 1)
    R = rng.standard_normal((2, 2))
    R *= amp / np.linalg.norm(R, 2)

    def Q(t):
        return np.eye(2) + R * np.sin(WP * t)       # ‖R‖ < 1: invertible

    def Qdot(t):
        return R * WP * np.cos(WP * t)

    # x = Q z:  ż = Q^{-1}(A Q - Q̇) z + Q^{-1} B u,  y = C Q z + D u
    Az = lambda t: np.linalg.solve(Q(t), sys.A(t) @ Q(t) - Qdot(t))      # noqa: E731
    Bz = lambda t: np.linalg.solve(Q(t), sys.B(t))                        # noqa: E731
    Cz = lambda t: sys.C(t) @ Q(t)                                        # noqa: E731
    z_sys = ltp.ltpss(Az, Bz, Cz, sys.D, T)
    mu, muz = ltp.floquet_multipliers(sys), ltp.floquet_multipliers(z_sys)
    assert _mismatch(mu, muz) < 1e-9
    t = np.linspace(0.0, 4.0, 201)
    u = np.cos(1.7 * t) + 0.3 * t
    y = ltp.forced_response(sys, t, u).outputs
    yz = ltp.forced_response(z_sys, t, u).outputs
    assert np.abs(y - yz).max() < 1e-9 * (1 + np.abs(y).max())


@FAST
@given(seed=seeds, N=st.sampled_from([1, 2, 3, 5, 8]))
def test_frequency_lifting_poles_are_roots_of_multipliers(seed, N):
    rng = np.random.default_rng(seed)
    n = 2
    A = rng.standard_normal((N, n, n)) * 0.6
    sysd = ltp.ltpss(A, rng.standard_normal((N, n, 1)), rng.standard_normal((N, 1, n)), 0,
                     T, dt=T / N)
    poles = np.linalg.eigvals(ltp.lift(sysd).A)
    mu = ltp.floquet_multipliers(sysd)
    # every multiplier appears N times among the poles raised to the N-th power
    tol = 1e-9 * (1 + np.abs(mu).max())
    assert _mismatch(poles ** N, np.repeat(mu, N)) < tol
    Lt = ltp.lift(sysd, method='time')
    assert _mismatch(np.linalg.eigvals(Lt.A), mu) < tol


def _mismatch(a, b):
    """Largest distance of the best one-to-one matching of two sets of numbers."""
    from scipy.optimize import linear_sum_assignment
    cost = np.abs(a[:, None] - b[None, :])
    rows, cols = linear_sum_assignment(cost)
    return cost[rows, cols].max()


@FAST
@given(seed=seeds, N=st.sampled_from([1, 2, 5]))
def test_foh_sampling_matches_simulation(seed, N):
    rng = np.random.default_rng(seed)
    sys = _random_ltp(rng, 2, 2, 1)
    sysd = ltp.sample_system(sys, T / N, 'foh')
    t = (T / N) * np.arange(3 * N + 4)
    u = rng.standard_normal((2, len(t)))
    u[:, 0] = 0.0                                   # ξ_0 = x_0 - Γ1 u_0 = x_0
    x0 = rng.standard_normal(2)
    yd = ltp.forced_response(sysd, t, u, x0).outputs
    yc = ltp.forced_response(sys, t, u, x0, input_hold='foh').outputs
    assert np.abs(yd - yc).max() < 1e-9 * (1 + np.abs(yc).max())
