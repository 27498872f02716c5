"""Tests of `sample_models`: scenario models from a refined model's covariance.

Truth: every coefficient of the realized model (A, and the Fourier
coefficients of B, C, D in the real modal basis) is linear in the
parameters, so the scenarios' coefficients must have the mean and the
covariance ``J Σ Jᵀ`` of the parameters carried through that linear map
(J by differences, exact for a linear map); python-control in the LTI limit.
"""

import dataclasses
import warnings

import control as ct
import numpy as np
import pytest
from control.exception import ControlArgument

import ltpcontrol as ltp
from test_refine import data_htf, random_floquet

OMEGA = np.linspace(0.2, 15.0, 40)


def refined(seed, pair=True, KB=1, KC=1, std=0.02):
    """Refined model and info from a noisy HTF of a random Floquet-form plant."""
    true = random_floquet(seed, nx=2, KB=KB, KC=KC, complex_pair=pair)
    H, G = data_htf(true, max(KB, KC), OMEGA, std=std)
    rng = np.random.default_rng(seed)
    noise = std / np.sqrt(2) * (rng.standard_normal(G.shape) + 1j * rng.standard_normal(G.shape))
    H = ltp.HTFData(G + noise, OMEGA, true.period, std=H.std)
    return ltp.refine_ltp(true, H, return_info=True)


def coefficients(sys, K=2):
    """A and the Fourier coefficients of B, C, D as one real vector."""
    parts = [sys.A(0.0)] + [M.fourier(K) for M in (sys.B, sys.C, sys.D)]
    return np.concatenate([np.concatenate([p.real.ravel(), p.imag.ravel()]) for p in parts])


@pytest.mark.parametrize("seed, pair", [(0, True), (1, False)])
def test_scenarios_reproduce_the_covariance(seed, pair):
    model, info = refined(seed, pair)
    c0 = coefficients(info.realize(info.x))
    assert np.allclose(c0, coefficients(model))
    J = np.column_stack([coefficients(info.realize(info.x + e)) - c0
                         for e in np.eye(info.x.size)])
    n = 3000
    c = np.array([coefficients(m) for m in ltp.sample_models(info, n, seed=seed)])
    expected = J @ info.cov @ J.T
    sd = np.sqrt(np.diag(expected))
    assert np.all(np.abs(c.mean(axis=0) - c0) <= 4.5 * sd / np.sqrt(n) + 1e-12)
    live = sd > 1e-9 * sd.max()
    S = np.cov(c.T)[np.ix_(live, live)] / np.outer(sd[live], sd[live])
    E = expected[np.ix_(live, live)] / np.outer(sd[live], sd[live])
    # unit diagonal within sampling error (sd of a variance ratio: sqrt(2/n))
    assert np.all(np.abs(np.diag(S) - 1) < 4.5 * np.sqrt(2 / n))
    assert np.abs(S - E).max() < 4.5 * np.sqrt(2 / n)


def test_zero_and_singular_covariance():
    model, info = refined(2)
    still = dataclasses.replace(info, cov=np.zeros_like(info.cov))
    for m in ltp.sample_models(still, 3, seed=0):
        assert np.array_equal(coefficients(m), coefficients(model))
    # variance in the first parameter (the exponent's real part) only
    one = np.zeros_like(info.cov)
    one[0, 0] = info.cov[0, 0]
    models = ltp.sample_models(dataclasses.replace(info, cov=one), 50, seed=0)
    A = np.array([m.A(0.0) for m in models])
    assert np.ptp(A[:, 0, 0]) > 0
    assert np.allclose(A[:, 0, 1], model.A(0.0)[0, 1], rtol=0, atol=1e-14)
    for m in models:
        assert np.allclose(coefficients(m)[8:], coefficients(model)[8:], rtol=0, atol=1e-14)


def test_seeds_and_generators():
    _, info = refined(3)
    a = ltp.sample_models(info, 4, seed=7)
    b = ltp.sample_models(info, 4, seed=np.random.default_rng(7))
    c = ltp.sample_models(info, 4, seed=8)
    assert all(np.array_equal(coefficients(x), coefficients(y)) for x, y in zip(a, b))
    assert not np.allclose(coefficients(a[0]), coefficients(c[0]))
    assert all(m.period == info.realize(info.x).period and not m.isdtime() for m in a)


def test_lti_limit_matches_python_control():
    # constant B and C (no harmonics): every scenario is LTI and its G_0 is
    # python-control's frequency response of the same matrices
    _, info = refined(4, KB=0, KC=0)
    w = np.array([0.3, 2.0, 9.0])
    for m in ltp.sample_models(info, 5, seed=1):
        assert m.B.nharmonics == 0 and m.C.nharmonics == 0
        ref = ct.ss(m.A(0.0), m.B(0.0), m.C(0.0), m.D(0.0)).frequency_response(w)
        _, G = ltp.htf(m, 0).components(w)
        assert np.allclose(G[0], ref.frdata, rtol=1e-12, atol=1e-14)


def test_identify_ltp_returns_the_refinement():
    true = random_floquet(12, nx=2, KB=1, KC=1)
    # a grid on which every line Ω has its components at Ω ± ω_p
    w = 2 * np.pi / true.period * (np.arange(60) / 8 + 1 / 16)
    H, G = data_htf(true, 1, w, std=1e-3)
    noise = 1e-3 * np.random.default_rng(0).standard_normal(G.shape)
    H = ltp.HTFData(G + noise, w, true.period, std=H.std)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        # without held-out lines the refinement is always kept
        model, info = ltp.identify_ltp(H, true.period, 2, 1, refine='ml', holdout=None,
                                       return_info=True)
        _, plain = ltp.identify_ltp(H, true.period, 2, 1, return_info=True)
        _, held = ltp.identify_ltp(H, true.period, 2, 1, refine='ml', return_info=True)
    assert plain.refinement is None
    # with held-out lines it is kept unless it predicts them worse than its start
    assert (held.refinement is None) == held.refine_fallback
    ml = info.refinement
    assert isinstance(ml, ltp.RefineInfo) and ml.cov.shape == (ml.x.size,) * 2
    assert np.allclose(coefficients(ml.realize(ml.x)), coefficients(model))
    assert len(ltp.sample_models(ml, 2, seed=0)) == 2


def test_bad_input():
    _, info = refined(5)
    with pytest.raises(ControlArgument, match="info must be the RefineInfo"):
        ltp.sample_models({'x': info.x, 'cov': info.cov}, 2)
    with pytest.raises(ControlArgument, match="info must be the RefineInfo"):
        ltp.sample_models(dataclasses.replace(info, realize=None), 2)
    with pytest.raises(ValueError, match="n must be >= 1"):
        ltp.sample_models(info, 0)
    with pytest.raises(ControlArgument, match="n must be an integer"):
        ltp.sample_models(info, 2.5)
    p = info.x.size
    with pytest.raises(ValueError, match="must be 2 x 2|info.cov must be"):
        ltp.sample_models(dataclasses.replace(info, cov=np.eye(p + 1)), 2)
    asym = np.eye(p)
    asym[0, 1] = 1.0
    with pytest.raises(ValueError, match="symmetric"):
        ltp.sample_models(dataclasses.replace(info, cov=asym), 2)
    with pytest.raises(ValueError, match="positive semidefinite"):
        ltp.sample_models(dataclasses.replace(info, cov=-np.eye(p)), 2)
    bad = info.cov.copy()
    bad[0, 0] = np.nan
    with pytest.raises(ValueError, match="info.cov"):
        ltp.sample_models(dataclasses.replace(info, cov=bad), 2)
