"""The noise share of the held-out validation of `identify_ltp`: estimated from
time records (free DFT bins) or given as `std`; independent truth: the error of
the lifted response of the noisy records against that of the noise-free ones."""

import warnings

import numpy as np
import pytest
import control as ct
from control.exception import ControlDimension

import ltpcontrol as ltp
from systems import mathieu

from examples.random_ltp_plants import design_lines, lifted_data, random_ltp

T, TS = 0.5, 0.01
FREQS = 0.1 + 0.4 * np.arange(1, 41)            # Hz, on the grid of a 10 s window


def _records(sys, sigma, seed=0, duration=20.0):
    t = np.arange(int(round(duration / TS))) * TS
    u = np.cos(2 * np.pi * FREQS[:, None] * t[None, :])
    y = ltp.forced_response(sys, t, u[None]).outputs
    noise = sigma * np.random.default_rng(seed).standard_normal(y.shape)
    return (t, u[None], y), (t, u[None], y + noise)


def _identify(data, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return ltp.identify_ltp(data, T, 2, 1, q=20, transient=10.0, return_info=True,
                                **kw)


@pytest.fixture(scope='module')
def noisy_records():
    truth = mathieu()
    y = _records(truth, 0.0)[0][2]
    sigma = np.sqrt(np.mean(y ** 2) / 10 ** 2.0)                  # 20 dB SNR
    clean, noisy = _records(truth, sigma)
    return truth, clean, noisy


def test_noise_share_estimated_from_records(noisy_records):
    truth, clean, noisy = noisy_records
    model, info = _identify(noisy)
    held = np.isin(info.data.omega, info.holdout_lines)
    # the noise of the held-out entries, measured against the noise-free records
    K = (info.data.noutputs - 1) // 2
    G0 = ltp.lifted_frequency_response(clean, T, K, transient=10.0).frdata[..., held]
    G1 = ltp.lifted_frequency_response(noisy, T, K, transient=10.0).frdata[..., held]
    measured = np.linalg.norm(G1 - G0) / np.linalg.norm(G1)
    assert 0.7 < info.holdout_noise / measured < 1.4
    assert info.holdout_error < info.holdout_nrmse
    assert np.isclose(info.holdout_error ** 2,
                      max(info.holdout_nrmse ** 2 - info.holdout_noise ** 2, 0.0))
    assert info.success and info.message.count('of which noise') == 2
    # the decision uses the model's share: a tolerance between the two passes
    tol = (info.holdout_error + info.holdout_nrmse) / 2
    _, again = _identify(noisy, validation_tol=tol)
    assert again.success
    # noise-free records: no noise share
    _, exact = _identify(clean)
    assert exact.holdout_noise < 1e-6 and exact.success


def test_known_std_of_lifted_data():
    """Lifted data with complex errors of known std: the noise share equals the
    measured error; a poor structure is still flagged (its error is the model's)."""
    plant = random_ltp(501, 3, 1)
    omega = design_lines(1.0, 60)
    exact = lifted_data(plant, 7, omega, 1 / 64)
    rng = np.random.default_rng(3)
    std = 0.02 * np.abs(exact.frdata).mean()
    err = std * (rng.standard_normal(exact.frdata.shape)
                 + 1j * rng.standard_normal(exact.frdata.shape)) / np.sqrt(2)
    data = ct.frd(exact.frdata + err, omega, exact.dt, outputs=exact.output_labels,
                  inputs=exact.input_labels)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model, info = ltp.identify_ltp(data, 1.0, 3, 2, std=std, return_info=True)
        _, blind = ltp.identify_ltp(data, 1.0, 3, 2, return_info=True)
    held = np.isin(omega, info.holdout_lines)
    measured = np.linalg.norm(err[..., held]) / np.linalg.norm(data.frdata[..., held])
    assert 0.8 < info.holdout_noise / measured < 1.25
    assert info.success and np.isnan(blind.holdout_noise)
    assert blind.holdout_error == blind.holdout_nrmse
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        _, poor = ltp.identify_ltp(data, 1.0, 1, 2, std=std, return_info=True)
    assert any('holdout_error' in str(w.message) for w in caught)
    assert not poor.success and poor.holdout_error > 0.05
    # a noise level the held-out error cannot contain is not used
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        _, wrong = ltp.identify_ltp(exact, 1.0, 3, 2, std=std, return_info=True)
    assert any('not used' in str(w.message) for w in caught)
    assert np.isnan(wrong.holdout_noise) and wrong.holdout_error == wrong.holdout_nrmse


def test_std_bad_input(noisy_records):
    plant = random_ltp(200, 2, 1, periodic='B')
    omega = design_lines(1.0, 30)
    data = lifted_data(plant, 3, omega, 1 / 64)
    with pytest.raises(ValueError, match='std'):
        ltp.identify_ltp(data, 1.0, 2, 1, std=-1.0)
    with pytest.raises(ValueError, match='std'):
        ltp.identify_ltp(data, 1.0, 2, 1, std=np.nan)
    with pytest.raises(ControlDimension, match='std'):
        ltp.identify_ltp(data, 1.0, 2, 1, std=np.ones(4))
    with pytest.raises(TypeError, match='std'):
        ltp.identify_ltp(noisy_records[2], T, 2, 1, q=20, transient=10.0, std=0.1)
    H = ltp.htf(plant, 2)
    with pytest.raises(TypeError, match='std'):
        ltp.identify_ltp(H, 1.0, 2, 1, std=0.1)


def test_noise_share_of_mimo_records():
    """Two inputs separated by least squares over phase-shifted experiments: the
    noise variance carried through the solution equals the measured error."""
    plant = random_ltp(401, 3, 2, ninputs=2)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        exc = ltp.sine_experiments(np.linspace(0.7, 15, 24), 1.0, dt=1 / 64, nperiods=20,
                                   ninputs=2, unusable='drop')
    u = np.concatenate([exc.inputs, exc.inputs], axis=-1)      # 20 periods to settle
    t = np.arange(u.shape[-1]) / 64
    y = ltp.forced_response(plant, t, u).outputs
    noisy = y + 0.05 * np.random.default_rng(0).standard_normal(y.shape)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        _, info = ltp.identify_ltp((t, u, noisy), 1.0, 3, 1, transient=20.0,
                                   return_info=True)
    held = np.isin(info.data.omega, info.holdout_lines)
    K = info.data_harmonics
    G0 = ltp.lifted_frequency_response((t, u, y), 1.0, K, transient=20.0).frdata
    G1 = info.data.frdata
    measured = np.linalg.norm((G1 - G0)[..., held]) / np.linalg.norm(G1[..., held])
    assert 0.8 < info.holdout_noise / measured < 1.25
    assert info.success
