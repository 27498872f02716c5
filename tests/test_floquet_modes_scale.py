"""Floquet modes and monodromy of stiff and long products, checked independently.

Truths: the lag rates of lags that do not feed back (their exponents
exactly, their periodic shapes the unit lag vectors); the structural
exponents and mode shapes from `scipy.integrate.solve_ivp` (DOP853 on the
structural block, which the lags do not disturb) propagating each
Floquet vector over the period (``x(t) = e^{λt} shape(t)``); the
eigen-decomposition of A by `numpy.linalg.eig` for a time-invariant system
written in a periodic basis; the size of the allocations by tracemalloc.
"""

import tracemalloc
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ltpcontrol import (PeriodicMatrix, floquet_exponents, floquet_modes, floquet_transform,
                        ltpss, monodromy)

T = 1.0
W = 2 * np.pi / T


def _stiff_rotor(m=5, lags=(-1e2, -1e3, -5e3, -1e4), seed=3):
    """2m structural states with a periodic stiffness and lags at `lags` × Ω (no feedback)."""
    rng = np.random.default_rng(seed)
    w = W * np.linspace(0.7, 3.5, m)
    G1, G2 = (0.5 * (g + g.T) / np.sqrt(m) for g in rng.standard_normal((2, m, m)))
    drive = 0.5 * rng.standard_normal((len(lags), m)) * np.sqrt(w)
    rates = np.asarray(lags) * W
    n = 2 * m + len(lags)

    def A(t):
        t = np.atleast_1d(np.asarray(t, float))
        out = np.zeros((len(t), n, n))
        for i, s in enumerate(t):
            K = np.diag(w ** 2) + 0.15 * np.outer(w, w) * (np.cos(W * s) * G1
                                                           + np.sin(2 * W * s) * G2)
            out[i, :m, m:2 * m] = np.diag(w)
            out[i, m:2 * m, :m] = -K / w[None, :]
            out[i, m:2 * m, m:2 * m] = -np.diag(0.04 * w)
            out[i, 2 * m:, m:2 * m] = drive
            out[i, 2 * m:, 2 * m:] = np.diag(rates)
        return out
    Ap = PeriodicMatrix.from_function(A, T, (n, n), check=False)
    return ltpss(Ap, np.zeros((n, 0)), np.zeros((0, n)), np.zeros((0, 0)), period=T), \
        A, rates, 2 * m


def _propagate(A, x0, times, method, rtol):
    """Complex vectors x0 (n, k) propagated by solve_ivp to `times` (k, S, n)."""
    n, k = x0.shape
    X0 = np.concatenate([x0.real, x0.imag], axis=1).ravel()

    def f(t, x):
        return (A(t)[0] @ x.reshape(n, 2 * k)).ravel()

    def jac(t, x):
        return np.kron(A(t)[0], np.eye(2 * k))
    kw = dict(jac=jac) if method == 'Radau' else {}
    sol = solve_ivp(f, (0, T), X0, method=method, t_eval=np.append(times, T), rtol=rtol,
                    atol=rtol * 1e-3, **kw)
    Y = sol.y.T.reshape(len(times) + 1, n, 2 * k)
    return np.transpose(Y[:, :, :k] + 1j * Y[:, :, k:], (2, 0, 1))


@pytest.fixture(scope='module')
def stiff_case():
    sys, A, rates, k = _stiff_rotor()
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        modes = floquet_modes(sys)
    return sys, A, rates, k, modes


def test_stiff_modes_exponents_equal_lag_rates_and_structural_truth(stiff_case):
    sys, A, rates, k, modes = stiff_case
    lam = modes.strip_exponents
    scale = np.abs(lam.real).max()
    stiff = np.sort(lam.real)[:len(rates)]
    assert np.max(np.abs(stiff - np.sort(rates))) <= 1e-8 * scale
    # the structural block alone (the lags do not feed back), fine DOP853 monodromy
    Phi = _propagate(lambda t: A(t)[:, :k, :k], np.eye(k).astype(complex), np.zeros(0),
                     'DOP853', 1e-12)[:, -1].T
    ref = np.sort(np.log(np.abs(np.linalg.eigvals(Phi))) / T)
    assert np.max(np.abs(np.sort(lam.real)[len(rates):] - ref)) <= 1e-8 * scale
    assert np.allclose(np.sort(lam.real), np.sort(floquet_exponents(sys).real),
                       rtol=0, atol=1e-10 * scale)


def test_stiff_modes_shapes_follow_an_independent_integration(stiff_case):
    sys, A, rates, k, modes = stiff_case
    n = sys.nstates
    lam = modes.exponents
    slow = np.flatnonzero(lam.real > 0.5 * rates.max())
    # x(t) = e^{λt} shape(t) of each structural mode: its structural part (the lags do
    # not feed back) propagated by DOP853 from t = 0
    x = _propagate(lambda t: A(t)[:, :k, :k], modes.vectors[:k, slow], modes.times[1:],
                   'DOP853', 1e-12)
    shapes = modes.shapes[:k, slow].transpose(1, 2, 0)                   # (mode, S, k)
    expect = np.exp(lam[slow, None, None] * modes.times[None, 1:, None]) * shapes[:, 1:]
    err = np.abs(x[:, :-1] - expect).max(axis=(1, 2)) / np.abs(shapes).max(axis=(1, 2))
    assert err.max() <= 1e-6
    # over the period: Φ v = μ v
    mu = np.exp(lam[slow] * T)
    resid = np.abs(x[:, -1] - mu[:, None] * modes.vectors[:k, slow].T).max(axis=1)
    assert resid.max() <= 1e-6
    # the lags' parts: each lag y' = r y + d x_struct has the periodic solution
    # y = e^{λt} q(t) with q' = (r - λ) q + d p(t); at quasi-steady state (|r| ≫ ω)
    # q ≈ -d p / (r - λ) to relative order ω / |r|
    m = k // 2
    drive = A(0.0)[0, k:, m:k]
    q = -(drive @ modes.shapes[m:k, slow, 0]) / (rates[:, None] - lam[None, slow])
    got = modes.shapes[k:, slow, 0]
    assert np.abs(got - q).max() <= 0.05 * np.abs(q).max()
    # stiff modes: their multipliers underflow, their shapes are the unit lag vectors
    for i in np.flatnonzero(lam.real <= 0.5 * rates.max()):
        j = k + int(np.argmin(np.abs(rates - lam[i].real)))
        unit = np.zeros(n)
        unit[j] = 1.0
        s = modes.shapes[:, i, :]
        s = s / s[j]
        assert np.abs(s - unit[:, None]).max() <= 1e-8
    assert modes.multipliers[np.argmin(lam.real)] == 0      # e^{-6e4}: underflows


@pytest.mark.parametrize('stiff', [False, True])
def test_lti_in_a_periodic_basis_gives_eig_of_A(stiff):
    rng = np.random.default_rng(11)
    n = 6
    A0 = rng.standard_normal((n, n)) - 1.5 * np.eye(n)
    N = 0.3 * rng.standard_normal((n, n)) / np.sqrt(n)
    if stiff:
        # lags at -300Ω and -10⁴Ω driven by the others; the periodic basis leaves them be
        A0[4:, :] = 0.0
        A0[4:, :4] = rng.standard_normal((2, 4))
        A0[4, 4], A0[5, 5] = -300 * W, -1e4 * W
        N[4:, :] = N[:, 4:] = 0.0

    def A(t):
        t = np.atleast_1d(np.asarray(t, float))
        P = np.eye(n) + np.sin(W * t)[:, None, None] * N
        dP = W * np.cos(W * t)[:, None, None] * N
        return (P @ A0 + dP) @ np.linalg.inv(P)
    sys = ltpss(PeriodicMatrix.from_function(A, T, (n, n), check=False), np.zeros((n, 0)),
                np.zeros((0, n)), np.zeros((0, 0)), period=T)
    modes = floquet_modes(sys)
    ev, V = np.linalg.eig(A0)
    tol = 1e-8 if stiff else 1e-12
    scale = np.abs(ev.real).max()
    for i, lam in enumerate(modes.strip_exponents):
        # the same exponent modulo jω, and the same vector at t = 0 (P(0) = I) up to scaling
        gap = (np.abs(ev.real - lam.real) + np.abs(
            np.angle(np.exp(1j * (ev.imag - lam.imag) * T))) / T) / scale
        j = int(np.argmin(gap))
        assert gap[j] <= tol
        v, u = modes.vectors[:, i], V[:, j]
        assert 1 - abs(np.vdot(u, v)) / (np.linalg.norm(u) * np.linalg.norm(v)) <= tol


def test_nonstiff_modes_agree_with_a_formed_product():
    rng = np.random.default_rng(5)
    n = 5
    A0, A1, A2 = rng.standard_normal((3, n, n))
    A0 -= 0.5 * np.eye(n)

    def A(t):
        t = np.atleast_1d(np.asarray(t, float))[:, None, None]
        return A0 + np.cos(W * t) * A1 + 0.5 * np.sin(2 * W * t) * A2
    sys = ltpss(PeriodicMatrix.from_function(A, T, (n, n), check=False), np.zeros((n, 0)),
                np.zeros((0, n)), np.zeros((0, 0)), period=T)
    modes = floquet_modes(sys)
    # the formed product of an independent integration, its eigen-decomposition
    Phi = _propagate(A, np.eye(n).astype(complex), np.zeros(0), 'DOP853', 1e-13)[:, -1].T
    mu, V = np.linalg.eig(Phi)
    for i, m in enumerate(modes.multipliers):
        j = int(np.argmin(np.abs(mu - m)))
        assert abs(mu[j] - m) <= 1e-12 * np.abs(mu).max()
        v = modes.vectors[:, i]
        assert 1 - abs(np.vdot(V[:, j], v)) / np.linalg.norm(v) <= 1e-12
    # the shapes at every sample instant: x(t) = e^{λt} shape(t)
    x = _propagate(A, modes.vectors, modes.times[1:], 'DOP853', 1e-13)
    expect = np.exp(modes.exponents[:, None, None] * modes.times[None, 1:, None]) \
        * modes.shapes.transpose(1, 2, 0)[:, 1:]
    assert np.abs(x[:, :-1] - expect).max() <= 1e-11


def _autonomous(n, seed):
    """A random autonomous system with A(t) = A0 + cos(ωt) A1."""
    rng = np.random.default_rng(seed)
    A0, A1 = rng.standard_normal((2, n, n))
    Ap = PeriodicMatrix.from_function(
        lambda t: A0 + np.cos(W * np.atleast_1d(t))[:, None, None] * A1, T, (n, n),
        check=False)
    return ltpss(Ap, np.zeros((n, 0)), np.zeros((0, n)), np.zeros((0, 0)), period=T)


def test_monodromy_memory_does_not_grow_with_the_steps():
    sys = _autonomous(8, seed=2)
    peaks, results = [], []
    for steps in (2048, 8192):
        tracemalloc.start()
        results.append(monodromy(sys, nsteps=steps))
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    # four times the steps, not more memory (stacked factors would grow 4-fold)
    assert peaks[1] <= 1.25 * peaks[0]
    assert np.allclose(results[0], results[1], rtol=0, atol=1e-10 * np.abs(results[1]).max())


def test_stiff_monodromy_warns_and_points_to_the_exponents(stiff_case):
    sys = stiff_case[0]
    # the warning comes before the product is formed (raised here: nothing else runs)
    with warnings.catch_warnings():
        warnings.simplefilter('error', UserWarning)
        with pytest.raises(UserWarning, match='floquet_exponents'):
            monodromy(sys)


def test_floquet_transform_refuses_a_table_that_cannot_fit_before_any_work():
    sys = _autonomous(20, seed=4)
    with pytest.raises(MemoryError, match='GB'):
        floquet_transform(sys, nsteps=2 * 10 ** 6)


def test_floquet_transform_warns_when_its_factors_cannot_hold_the_stiff_modes(stiff_case):
    sys = stiff_case[0]
    # 64 steps: h max‖A‖ ~ 1e3, far beyond what a plain factor holds; the warning
    # comes before any work (raised here, so that nothing else runs)
    with warnings.catch_warnings():
        warnings.simplefilter('error', UserWarning)
        with pytest.raises(UserWarning, match='floquet_modes keep them'):
            floquet_transform(sys, nsteps=64)
