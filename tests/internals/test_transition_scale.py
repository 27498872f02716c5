"""Step transitions and Floquet factors at scale: bounded memory, balancing,
exact fast forms of callables, constant detection, stiff lags.

Tests of internals: they import private names (see the Developer notes).
"""

import tracemalloc
import warnings

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.integrate import solve_ivp

import ltpcontrol as ltp
from ltpcontrol._core.fastform import constant_value, fast_form
from ltpcontrol._core.memory import check_allocation
from ltpcontrol._core.steps import floquet_grid
from ltpcontrol._core import transition
from ltpcontrol._core.transition import _balancing, step_transitions


def fast_varying(n=6, seed=0, cycles=2):
    rng = np.random.default_rng(seed)
    A0 = rng.standard_normal((n, n)) - 2 * np.eye(n)
    A1 = 3 * rng.standard_normal((n, n))
    f = lambda t: A0 + A1 * np.cos(2 * np.pi * cycles * t)     # noqa: E731
    coeffs = np.zeros((2 * cycles + 1, n, n))
    coeffs[cycles], coeffs[0], coeffs[-1] = A0, A1 / 2, A1 / 2
    return ltp.PeriodicMatrix(coeffs, 1.0), f


def ode_transition(f, t0, t1, n):
    sol = solve_ivp(lambda t, y: (f(t) @ y.reshape(n, n)).ravel(), (t0, t1),
                    np.eye(n).ravel(), method='DOP853', rtol=1e-13, atol=1e-13)
    return sol.y[:, -1].reshape(n, n)


def test_substeps_accumulate_in_bounded_memory(monkeypatch):
    # the sub-steps are multiplied into a running product block by block: with a
    # tiny block budget the memory stays below one array of all sub-steps and the
    # result equals the one-block computation and an independent ODE solution
    A, f = fast_varying()
    t0 = np.array([0.0, 0.5])
    info = {}
    Phi, _, _ = step_transitions(A, None, t0, 0.5, info=info)
    n, nsub = 6, info['substeps']
    assert nsub >= 64
    monkeypatch.setattr(transition, '_CHUNK_ENTRIES', 2 ** 10)
    tracemalloc.start()
    Phi_small, _, _ = step_transitions(A, None, t0, 0.5)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    stacked = len(t0) * nsub * 2 * n * n * 8          # node values of all sub-steps
    assert peak < stacked / 2
    assert np.abs(Phi_small - Phi).max() <= 1e-13 * np.abs(Phi).max()
    for k in range(2):
        ref = ode_transition(f, t0[k], t0[k] + 0.5, n)
        assert np.abs(Phi[k] - ref).max() <= 1e-9 * np.abs(ref).max()


def test_balancing_of_badly_scaled_states():
    # D⁻¹ A D with D spanning 8 decades: the same transitions, balanced exactly
    A, f = fast_varying(4, seed=3)
    A = ltp.PeriodicMatrix.from_function(f, 1.0)
    d = 10.0 ** np.array([4.0, 0.0, -2.0, -4.0])
    Ab = ltp.PeriodicMatrix.from_function(lambda t: f(t) * d[None, :] / d[:, None], 1.0)
    assert _balancing(A, 4, 4) is None
    assert _balancing(Ab, 4, 4) is not None
    info, info_b = {}, {}
    t0 = np.linspace(0, 1, 8, endpoint=False)
    Phi, _, _ = step_transitions(A, None, t0, 1 / 8, info=info)
    Phib, _, _ = step_transitions(Ab, None, t0, 1 / 8, info=info_b)
    back = Phib * d[None, :, None] / d[None, None, :]      # D Φ_b D⁻¹
    assert np.abs(back - Phi).max() <= 1e-10 * np.abs(Phi).max()
    assert info_b['substeps'] <= info['substeps']


def test_fast_form_of_callable_is_exact_and_keeps_results():
    w = 2 * np.pi
    f = lambda t: np.array([[0.0, 1.0], [-(1 + 0.3 * np.cos(w * t)) * 30.0,   # noqa: E731
                                          -0.4 + 0.1 * np.sin(2 * w * t)]])
    A = ltp.PeriodicMatrix.from_function(f, 1.0)
    F = fast_form(A)
    assert F.nharmonics == 2
    t = np.linspace(0, 1, 37)
    assert np.abs(F(t) - A(t)).max() <= 1e-13 * 30
    # not band-limited: left as it is
    g = ltp.PeriodicMatrix.from_function(lambda t: np.array([[np.abs(np.sin(w * t))]]), 1.0)
    assert fast_form(g) is g
    # the exponents of the callable system equal those of its Fourier form
    sys_c = ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=1.0)
    sys_f = ltp.ltpss(F, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=1.0)
    assert np.abs(ltp.floquet_exponents(sys_c) - ltp.floquet_exponents(sys_f)).max() < 1e-12


def test_constant_to_data_precision_gives_eigenvalues():
    # an isotropic model written through a transform whose data carry 1e-12 noise
    rng = np.random.default_rng(5)
    A0 = rng.standard_normal((5, 5)) - 3 * np.eye(5)
    E = rng.standard_normal((5, 5))
    A = ltp.PeriodicMatrix.from_function(lambda t: A0 + 1e-12 * np.cos(2 * np.pi * t) * E, 1.0)
    assert constant_value(A) is not None
    sys = ltp.ltpss(A, np.zeros((5, 1)), np.zeros((1, 5)), 0, period=1.0)
    lam = ltp.floquet_exponents(sys)
    ev = np.linalg.eigvals(A0)
    assert np.abs(np.sort_complex(lam) - np.sort_complex(ev)).max() < 1e-10
    mu = ltp.floquet_multipliers(sys)
    assert np.abs(np.sort_complex(mu) - np.sort_complex(np.exp(ev))).max() < 1e-10
    # a genuine variation is kept
    B = ltp.PeriodicMatrix.from_function(lambda t: A0 + 1e-6 * np.cos(2 * np.pi * t) * E, 1.0)
    assert constant_value(B) is None


def stiff_lag_rotor(m=3, s=2, stiff=300.0, seed=0):
    """m periodic structural DOFs (Mathieu-type) driving s stiff lags (no feedback)."""
    rng = np.random.default_rng(seed)
    w = 2 * np.pi * np.sort(rng.uniform(0.5, 3.0, m))
    G = rng.standard_normal((m, m))
    G = 0.2 * (G + G.T)
    lag = -stiff * 2 * np.pi * (1 + rng.random(s))
    drive = rng.standard_normal((s, m))

    def A(t):
        K = np.diag(w ** 2) + np.cos(2 * np.pi * t) * G * np.outer(w, w)
        out = np.zeros((2 * m + s, 2 * m + s))
        out[:m, m:2 * m] = np.eye(m)
        out[m:2 * m, :m] = -K
        out[m:2 * m, m:2 * m] = -0.1 * np.diag(w)
        out[2 * m:, m:2 * m] = drive
        out[2 * m:, 2 * m:] = np.diag(lag)
        return out
    return A, lag, 2 * m


def test_stiff_lags_exponents_equal_independent_truth():
    # structural exponents from a tight ODE monodromy of the structural block;
    # stiff exponents exactly the lag rates (multipliers e^{-1800} and below)
    f, lag, k = stiff_lag_rotor()
    n = len(lag) + k
    sys = ltp.ltpss(f, np.zeros((n, 0)), np.zeros((0, n)), np.zeros((0, 0)), period=1.0)
    lam = ltp.floquet_exponents(sys)
    M = ode_transition(lambda t: f(t)[:k, :k], 0.0, 1.0, k)
    mu = np.linalg.eigvals(M)
    ref = np.concatenate([np.log(np.abs(mu)), lag])
    got = np.sort(lam.real)
    assert np.abs(got - np.sort(ref)).max() <= 1e-8 * np.abs(ref).max()
    # the structural ones to their own scale
    assert np.abs(got[-k:] - np.sort(ref)[-k:]).max() <= 1e-8 * np.abs(ref[:k]).max() + 1e-9


def test_floquet_grid_budget_and_clear_memory_error():
    A = ltp.PeriodicMatrix.constant(-1e5 * np.eye(200), 1.0)
    with pytest.warns(UserWarning, match="capped at 533 steps"):
        grid = floquet_grid(A)
    assert len(grid) - 1 <= 512e6 / (24 * 200 ** 2) + 1
    sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    with pytest.raises(MemoryError, match=r"step grid of nsteps=1000000000000 .* shape \(1000000000001"):
        ltp.monodromy(sys, nsteps=10 ** 12)
    with pytest.raises(MemoryError, match="GB"):
        check_allocation((10 ** 8, 1000, 1000), 'test arrays')
