"""H2, L∞ and Hankel norms of LTP systems against independent truth."""

import warnings

import numpy as np
import pytest
import control as ct

import ltpcontrol as ltp
from analysis_systems import stable_rss, transformed, zhou_hagiwara_A


def cantoni_sandberg():
    """Cantoni & Sandberg (Automatica 2009) example, T = π; L∞ = 1.7639."""
    return ltp.ltpss(zhou_hagiwara_A(), [[0.0], [1.0]], [[1.0, 1.0]], [[1.0]], period=np.pi)


@pytest.mark.parametrize('T', [0.5, 3.0])
def test_norms_lti_continuous(T):
    G = stable_rss(3, 2, 2, seed=3, strictly_proper=True)
    GD = stable_rss(3, 2, 2, seed=5)
    sys, sysD = ltp.ltpss(G, period=T), ltp.ltpss(GD, period=T)
    assert abs(ltp.norm(sys, 2) - ct.norm(G, 2)) <= 1e-9 * ct.norm(G, 2)
    hsv = ct.hankel_singular_values(G)
    assert abs(ltp.norm(sys, 'hankel') - hsv.max()) <= 1e-9 * hsv.max()
    for S, L in ((sys, G), (sysD, GD)):
        ref, wref = ct.linfnorm(L, 1e-12)
        value, w = ltp.norm(S, 'inf', tol=1e-11, return_frequency=True)
        assert abs(value - ref) <= 1e-9 * ref
        # the peak frequency, folded into [0, ω_p/2]
        wp = 2 * np.pi / T
        folded = abs((wref + wp / 2) % wp - wp / 2)
        assert abs(w - folded) <= 1e-3 * wp


@pytest.mark.parametrize('N', [1, 4, 5])
def test_norms_lti_discrete(N):
    G = stable_rss(3, 2, 2, seed=N, dt=0.1)
    sys = ltp.ltpss(G, period=0.1 * N)
    assert abs(ltp.norm(sys, 2) - ct.norm(G, 2)) <= 1e-9 * ct.norm(G, 2)
    ref = ct.linfnorm(G, 1e-12)[0]
    assert abs(ltp.norm(sys, 'inf', tol=1e-11) - ref) <= 1e-9 * ref
    # ct.hankel_singular_values rejects discrete systems: gramians by ct.dlyap
    P, Q = ct.dlyap(G.A, G.B @ G.B.T), ct.dlyap(G.A.T, G.C.T @ G.C)
    hsv = np.sqrt(np.linalg.eigvals(P @ Q).real.max())
    assert abs(ltp.norm(sys, 'hankel') - hsv) <= 1e-9 * hsv


def test_norms_lyapunov_transformed():
    # HTF of the rotated system: diagonal blocks G(s + jnω_p) in a rotated basis
    G = stable_rss(3, 2, 2, seed=3, strictly_proper=True)
    sys, _ = transformed(G, 2.0)
    assert abs(ltp.norm(sys, 2) - ct.norm(G, 2)) <= 1e-9 * ct.norm(G, 2)
    hsv = ct.hankel_singular_values(G).max()
    assert abs(ltp.norm(sys, 'hankel') - hsv) <= 1e-9 * hsv
    ref = ct.linfnorm(G, 1e-12)[0]
    assert abs(ltp.norm(sys, 'inf', tol=1e-10) - ref) <= 1e-9 * ref


def test_h2_periodic_matches_controllability_form_and_discretization():
    # (1/T)∫ tr(C P Cᵀ) with the controllability gramian, by quadrature of P(t)
    sys = cantoni_sandberg()
    B = ltp.PeriodicMatrix([[[0.0], [0.25]], [[0.0], [1.0]], [[0.0], [0.25]]], np.pi)
    sys = ltp.ltpss(sys.A, B, [[1.0, 1.0]], 0, period=np.pi)
    h2 = ltp.norm(sys, 2)
    P = ltp.gram(sys, 'c')
    x, wts = np.polynomial.legendre.leggauss(40)
    ts = np.pi / 2 * (x + 1)
    C = np.array([[1.0, 1.0]])
    quad = np.sum(wts * np.einsum('ij,tjk,lk->t', C, P(ts), C)) / 2
    assert abs(h2 - np.sqrt(quad)) <= 1e-9 * h2


def test_linf_cantoni_sandberg():
    value = ltp.norm(cantoni_sandberg(), 'inf', tol=1e-8)
    assert 1.7639 <= value < 1.7640            # published to four digits


def test_linf_is_certified_upper_bound_of_htf():
    sys = cantoni_sandberg()
    value = ltp.norm(sys, 'inf', tol=1e-8)
    H = ltp.htf(sys, 6)
    w = np.linspace(0, sys.omega_p / 2, 400)
    sig = np.linalg.norm(H(1j * w), ord=2, axis=(0, 1))
    assert sig.max() <= value * (1 + 1e-8)
    assert sig.max() >= value * (1 - 1e-4)


def test_hankel_is_max_over_start_times():
    sys = cantoni_sandberg()
    # B = [0; 1 + 0.8 sin 2t]
    B = ltp.PeriodicMatrix([[[0.0], [0.4j]], [[0.0], [1.0]], [[0.0], [-0.4j]]], np.pi)
    sys = ltp.ltpss(sys.A, B, [[1.0, 1.0]], 0, period=np.pi)
    P, Q = ltp.gram(sys, 'c'), ltp.gram(sys, 'o')
    ts = np.linspace(0, np.pi, 201)
    lam = np.array([np.linalg.eigvals(p @ q).real.max() for p, q in zip(P(ts), Q(ts))])
    hank = ltp.norm(sys, 'hankel')
    # independent maximisation around the best point of the coarse scan
    from scipy.optimize import minimize_scalar
    k = int(np.argmax(lam))
    f = lambda t: -np.linalg.eigvals(P(t) @ Q(t)).real.max()
    res = minimize_scalar(f, bounds=(ts[k] - 0.02, ts[k] + 0.02), method='bounded',
                          options={'xatol': 1e-9})
    assert np.sqrt(-res.fun) <= hank * (1 + 1e-9)
    assert np.sqrt(-res.fun) >= hank * (1 - 1e-9)
    # a single start time at t = 0 is not the Hankel norm
    assert np.sqrt(lam[0]) < 0.99 * hank


def test_norm_bad_input():
    unstable = ltp.ltpss([[0.2]], [[1.0]], [[1.0]], 0, period=1.0)
    with pytest.warns(UserWarning, match="unstable"):
        assert ltp.norm(unstable, 2) == np.inf     # as ct.norm
    with pytest.raises(ValueError, match="unstable"):
        ltp.norm(unstable, 'hankel')
    # L∞ of an unstable system: finite, as ct.norm (1/(s - 0.2) peaks at ω = 0)
    assert np.isclose(ltp.norm(unstable, 'inf', tol=1e-9),
                      ct.norm(ct.ss(0.2, 1, 1, 0), 'inf'), rtol=1e-8)
    integrator = ltp.ltpss([[0.0]], [[1.0]], [[1.0]], 0, period=1.0)
    with pytest.warns(UserWarning, match="imaginary axis"):
        assert ltp.norm(integrator, 'inf') == np.inf
    stable = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0.5, period=1.0)
    with pytest.warns(UserWarning, match="feedthrough"):
        assert ltp.norm(stable, 2) == np.inf
    for p in (1, np.inf, 'fro', 2.5, True):
        with pytest.raises(ValueError, match="p must be"):
            ltp.norm(stable, p)
    with pytest.raises(ValueError, match="tol"):
        ltp.norm(stable, 'inf', tol=0)
    with pytest.raises(ValueError, match="return_frequency"):
        ltp.norm(stable, 2, return_frequency=True)
    with pytest.raises(TypeError, match="LTPStateSpace"):
        ltp.norm(ct.tf([1], [1, 1]), 2)


@pytest.mark.parametrize('N', [3, 4])
def test_norms_periodic_discrete_against_brute_force(N):
    rng = np.random.default_rng(40 + N)
    A = 0.45 * rng.standard_normal((N, 3, 3))
    B, C = rng.standard_normal((N, 3, 2)), rng.standard_normal((N, 2, 3))
    D = rng.standard_normal((N, 2, 2))
    sys = ltp.ltpss(A, B, C, D, period=0.1 * N, dt=0.1)
    # H2: impulse-response energy from every start step, averaged over the period
    total = 0.0
    for k in range(N):
        total += np.sum(D[k] ** 2)
        X = B[k]
        for j in range(k + 1, k + 400):
            total += np.sum((C[j % N] @ X) ** 2)
            X = A[j % N] @ X
    assert abs(ltp.norm(sys, 2) - np.sqrt(total / N)) <= 1e-9 * np.sqrt(total / N)
    # L∞: the lifted frequency response on a fine grid stays below the norm
    L = ltp.lift(sys, method='time')
    w = np.linspace(0, np.pi / L.dt, 4001)
    sig = np.linalg.norm(np.moveaxis(L.frequency_response(w).complex, -1, 0), ord=2,
                         axis=(1, 2))
    value = ltp.norm(sys, 'inf', tol=1e-10)
    assert sig.max() <= value * (1 + 1e-9)
    assert sig.max() >= value * (1 - 1e-3)
