"""identify_ltp simulates its held-out model on the held-out time records: the
time-domain figure answers the prediction question where the analysed harmonics
cannot (output beyond them), and agrees with them where they can."""

import warnings

import numpy as np
import pytest
import scipy.signal

import ltpcontrol as ltp

T = 0.5
WP = 2 * np.pi / T
N = 32
DT = T / N


def plant(high=0.0):
    """``ẋ = -4x + u``, ``y = (1 + 0.5 cos ω_p t + high cos 7ω_p t) x``: the harmonic 7
    lies beyond the |n| <= 3K + 1 = 4 that K = 1 analyses."""
    return ltp.ltpss([[-4.0]], [[1.0]], lambda t: np.array(
        [[1 + 0.5 * np.cos(WP * t) + high * np.cos(7 * WP * t)]]), 0, period=T)


@pytest.fixture(scope='module')
def design():
    bins = np.array([b for b in range(1, 48) if (2 * b) % 8][::2])[:12]
    return ltp.sine_experiments(bins * WP / 8, T, dt=DT, nperiods=8, settle=8)


def fresh_nrmse(model, sys):
    """NRMSE of `model` next to `sys` on a fresh record of filtered noise."""
    b, a = scipy.signal.butter(4, 2 * WP * DT / np.pi)
    u = scipy.signal.lfilter(b, a, np.random.default_rng(7).standard_normal(40 * N))
    t = np.arange(u.size) * DT
    y = ltp.forced_response(sys, t, u).outputs
    return float(np.linalg.norm(ltp.forced_response(model, t, u).outputs - y)
                 / np.linalg.norm(y))


def identify(sys, exc, noise=0.0):
    resp = ltp.forced_response(sys, exc.time, exc.inputs)
    y = np.asarray(resp.outputs)
    y = y + noise * np.random.default_rng(1).standard_normal(y.shape)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        model, info = ltp.identify_ltp((exc.time, exc.inputs, y), T, 1, 1, excitation=exc,
                                       input_hold='foh', return_info=True)
    return model, info, [str(w.message) for w in caught], y


def test_output_beyond_the_analysed_harmonics_is_caught(design):
    sys = plant(high=0.15)
    model, info, caught, _ = identify(sys, design)
    assert info.data_harmonics == 4
    # the harmonics |n| <= 4 are predicted; the records are not
    assert info.holdout_error < 0.01
    fresh = fresh_nrmse(model, sys)
    assert fresh > 0.05
    assert info.record_error == pytest.approx(fresh, rel=0.3)
    assert not info.success
    assert any('held-out records' in w for w in caught)
    assert 'held-out records' in info.message


def test_records_agree_with_the_harmonics_and_noise_is_removed(design):
    sys = plant()
    model, info, caught, _ = identify(sys, design)
    assert info.success and not caught
    assert info.record_nrmse < 1e-3 and info.record_nrmse == pytest.approx(
        info.holdout_nrmse, rel=0.5)
    # white output noise: its share over the held-out windows is estimated
    noise = 0.004                         # NRMSE about 0.05 (26 dB)
    model, info, caught, y = identify(sys, design, noise)
    assert info.success and not any('held-out records' in w for w in caught)
    a = design.segments[0, 0]
    held = np.isin(np.round(design.frequencies, 9), np.round(info.holdout_lines, 9))
    true = noise * np.sqrt(held.sum() * (y.shape[-1] - a)) / np.linalg.norm(
        ltp.forced_response(sys, design.time, design.inputs).outputs[:, held, a:])
    assert info.record_noise == pytest.approx(true, rel=0.1)
    assert info.record_nrmse > 0.03
    # the share left is the model's, within the spread of the noise estimate
    assert info.record_error == pytest.approx(fresh_nrmse(model, sys), abs=0.015)
