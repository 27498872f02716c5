"""A gait-locked leg with a fast actuator identified from sine records predicts
fresh records (independent truth: simulation of the plant by forced_response).

Leg: ``m ẍ = -k(t) x - c(t) ẋ + f``, ``k = k0 (1 + 0.5 cos ω_p t)``, ``c = c0
(1 + 0.3 sin ω_p t)``, actuator ``τ ḟ = -f + u`` 40 times faster than the leg
(exponents -4 ± j6.3 and -100 1/s), period 0.5 s, output x.
"""

import warnings

import numpy as np
import pytest
import scipy.signal

import ltpcontrol as ltp

T = 0.5
WP = 2 * np.pi / T
DT = T / 64
P = 20                                     # periods of the analysis window


def leg(m=1.0, k0=400.0, c0=8.0, tau=0.01):
    A = np.zeros((3, 3, 3), complex)       # harmonics -1, 0, 1
    A[1] = [[0, 1, 0], [-k0 / m, -c0 / m, 1 / m], [0, 0, -1 / tau]]
    A[0, 1, 0] = A[2, 1, 0] = -0.25 * k0 / m
    A[0, 1, 1], A[2, 1, 1] = 0.15j * c0 / m, -0.15j * c0 / m
    return ltp.ltpss(ltp.PeriodicMatrix(A, T), [[0], [0], [1 / tau]], [[1, 0, 0]], 0,
                     period=T)


@pytest.fixture(scope='module')
def records():
    """38 single-sine experiments up to 6 ω_p: 20 periods of transient, 20 analysed."""
    bins = np.array([b for b in range(1, 9 * P) if (2 * b) % P][:114:3])
    lines = bins * 2 * np.pi / (P * T)
    t = np.arange(2 * P * 64) * DT
    u = np.cos(lines[:, None] * t)[None]
    plant = leg()
    return plant, t, u, ltp.forced_response(plant, t, u).outputs


def fresh_nrmse(model, plant, nperiods=60):
    """NRMSE on filtered noise (cut-off 2 ω_p) from rest."""
    L = int(nperiods * T / DT)
    b, a = scipy.signal.butter(4, 2 * WP * DT / np.pi)
    u = scipy.signal.lfilter(b, a, np.random.default_rng(0).standard_normal((1, L)), axis=1)
    t = np.arange(L) * DT
    y = ltp.forced_response(plant, t, u).outputs
    return np.linalg.norm(ltp.forced_response(model, t, u).outputs - y) / np.linalg.norm(y)


def _identify(t, u, y, K, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return ltp.identify_ltp((t, u, y), T, 3, K, transient=P * T, return_info=True, **kw)


@pytest.mark.slow
def test_leg_models_predict(records):
    plant, t, u, y = records
    errors = {}
    for K in (2, 3):
        model, info = _identify(t, u, y, K)
        errors[K] = fresh_nrmse(model, plant)
        assert info.success
        # the held-out figure states the accuracy the model has on fresh data
        assert errors[K] < 2 * info.holdout_error < 0.05
    assert errors[2] < 2e-2 and errors[3] < 1e-2 and errors[3] < errors[2]


@pytest.mark.slow
def test_leg_noisy_refinement(records):
    """30 dB output noise: the noise share is estimated from the records and the ML
    refinement predicts about as well as the refit."""
    plant, t, u, y = records
    sigma = np.sqrt(np.mean(y ** 2) / 1e3)
    noisy = y + sigma * np.random.default_rng(1).standard_normal(y.shape)
    plain, pinfo = _identify(t, u, noisy, 3)
    refined, rinfo = _identify(t, u, noisy, 3, refine='ml')
    assert pinfo.success and rinfo.success
    assert 0.002 < pinfo.holdout_noise < pinfo.holdout_nrmse
    assert pinfo.holdout_error < pinfo.holdout_nrmse
    assert fresh_nrmse(plain, plant) < 1e-2
    assert fresh_nrmse(refined, plant) < 1.5 * fresh_nrmse(plain, plant)


@pytest.mark.slow
def test_leg_lifted_data_path(records):
    """The lifted-data path: data of K harmonics leave the model's outer ones free
    (success=False with a warning, whatever the held-out error); data of 3K + 1
    harmonics give a model that predicts fresh records (K = 3 within 1e-2:
    examples/ident_leg_paths.py; K = 2 here, cheaper)."""
    plant, t, u, y = records
    G = ltp.lifted_frequency_response((t, u, y), T, 2, transient=P * T, input_hold='foh')
    with pytest.warns(UserWarning, match=r"harmonics 3\.\.7 are neither fitted"):
        model, info = ltp.identify_ltp(G, T, 3, 2, return_info=True)
    assert not info.success and info.holdout_nrmse < 0.05
    assert fresh_nrmse(model, plant) > 0.05                   # what the flag is for
    G = ltp.lifted_frequency_response((t, u, y), T, 7, transient=P * T, input_hold='foh')
    model, info = _identify_lifted(G, 2)
    assert info.success and info.data_harmonics == 7
    assert fresh_nrmse(model, plant) < 2e-2                   # measured 1.3e-2


def _identify_lifted(G, K):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return ltp.identify_ltp(G, T, 3, K, return_info=True)
