"""The documented data paths request by default every harmonic the data hold, so that
`identify_ltp` fits and validates every harmonic its model produces."""

import warnings

import numpy as np
import pytest

import ltpcontrol as ltp

T = 0.5
WP = 2 * np.pi / T
N = 16
DT = T / N


def plant():
    return ltp.ltpss([[-4.0]], lambda t: np.array([[1 + 0.5 * np.cos(WP * t)]]),
                     [[1.0]], 0, period=T)


def test_lifted_response_defaults_to_every_harmonic_of_the_sampling():
    bins = np.array([b for b in range(1, 40) if (2 * b) % 8][::2])[:12]
    exc = ltp.sine_experiments(bins * WP / 8, T, dt=DT, nperiods=8, settle=8)
    resp = ltp.forced_response(plant(), exc.time, exc.inputs)
    G = ltp.lifted_frequency_response(resp, T, transient=4.0, input_hold='foh')
    assert G.noutputs == 2 * ((N - 1) // 2) + 1
    explicit = ltp.lifted_frequency_response(resp, T, (N - 1) // 2, transient=4.0,
                                             input_hold='foh')
    np.testing.assert_array_equal(G.frdata, explicit.frdata)
    # the documented path, without harmonics given: fitted and validated
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        model, info = ltp.identify_ltp(G, T, 1, 1, return_info=True)
    assert info.success and info.data_harmonics == (N - 1) // 2
    assert info.holdout_nrmse < 5e-3


def test_estimate_htf_defaults_to_the_harmonics_the_replicas_hold():
    # 2 K_h + 4 replicas hold K_h harmonics with the test for unmodelled ones
    Kh = 4
    exc = ltp.chirp_replicas(1.0, 2 * Kh + 4, 8.0, 0.1, 5.0, dt=0.01)
    y = (1 + np.cos(2 * np.pi * exc.time)) * exc.inputs
    H = ltp.estimate_htf((exc.time, exc.inputs, y), 1.0, segments=exc.segments)
    assert H.nharmonics == Kh
    # the band reaches the highest excited input frequency shifted by K_h harmonics
    top = H.omega.max()
    assert 2 * np.pi * (5.0 + Kh) <= top <= 2 * np.pi * (5.0 + Kh) * 1.2
    explicit = ltp.estimate_htf((exc.time, exc.inputs, y), 1.0, Kh, segments=exc.segments,
                                omega_limits=(0.0, top))
    np.testing.assert_allclose(H.components()[1], explicit.components()[1], equal_nan=True)
    _, comps = H.components()
    k = np.nanargmin(np.abs(H.omega - 2 * np.pi * 3.0))
    np.testing.assert_allclose(comps[Kh - 1:Kh + 2, 0, 0, k].real, [0.5, 1.0, 0.5],
                               atol=1e-6)
    # an HTF lifted with the defaults keeps every harmonic it knows together
    G = ltp.lifted_frequency_response(H, 1.0)
    assert 1 <= (G.noutputs - 1) // 2 <= Kh
    with pytest.raises(ValueError, match='exceeds'):
        ltp.lifted_frequency_response(H, 1.0, Kh + 1)
