"""`success` means the same on every data path: lifted data and HTFs that lack
harmonics the model produces, noise estimates that are no noise, input holds,
designs passed as they are (independent truth: simulation of the plant)."""

import warnings

import numpy as np
import pytest
import scipy.signal

import ltpcontrol as ltp

T, DT = 0.5, 0.0125
W = np.pi / 2 * np.array([k for k in range(1, 40) if k % 4])


def plant():
    """First-order plant with a modulated input gain and a periodic A."""
    return ltp.ltpss(lambda t: np.array([[-3.0 - 1.5 * np.cos(4 * np.pi * t)]]),
                     lambda t: np.array([[1 + 0.5 * np.cos(4 * np.pi * t)]]),
                     [[1.0]], 0, period=T)


@pytest.fixture(scope='module')
def records():
    exc = ltp.sine_experiments(W, T, dt=DT, nperiods=8, settle=12)
    sys = plant()
    return sys, exc, ltp.forced_response(sys, exc.time, exc.inputs)


def fresh(model, sys, hold='foh'):
    L = 30 * 40
    b, a = scipy.signal.butter(4, 0.1)
    u = scipy.signal.lfilter(b, a, np.random.default_rng(5).standard_normal(L))
    t = np.arange(L) * DT
    y = ltp.forced_response(sys, t, u, input_hold=hold).outputs
    return float(np.linalg.norm(ltp.forced_response(model, t, u, input_hold=hold).outputs - y)
                 / np.linalg.norm(y))


def test_lifted_data_without_the_produced_harmonics_fail(records):
    sys, exc, resp = records
    G = ltp.lifted_frequency_response(resp, T, 1, transient=6.0, input_hold='foh')
    with pytest.warns(UserWarning, match=r"the harmonics 2\.\.4 are neither fitted"):
        _, info = ltp.identify_ltp(G, T, 1, 1, return_info=True)
    assert not info.success
    G = ltp.lifted_frequency_response(resp, T, 4, transient=6.0, input_hold='foh')
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        model, info = ltp.identify_ltp(G, T, 1, 1, return_info=True)
    assert info.success and info.data_harmonics == 4
    assert fresh(model, sys) < 1e-2


def test_no_silent_failure_small_study(records):
    """The study's property at a small size: 20 dB, transient left in or not, four
    ways; no model succeeds without a warning and predicts a fresh record badly."""
    sys = plant()
    # lines on the grid of the whole record: the transient can be left in the window
    exc = ltp.sine_experiments(W, T, dt=DT, nperiods=8, settle=8)
    y = np.asarray(ltp.forced_response(sys, exc.time, exc.inputs).outputs)
    count = 0
    for seed, transient in ((0, 4.0), (1, 0.0)):
        rng = np.random.default_rng(seed)
        noisy = y + np.sqrt(np.mean(y ** 2) / 100) * rng.standard_normal(y.shape)
        data = (exc.time, exc.inputs, noisy)
        ways = [(data, dict(transient=transient, input_hold='foh'))]
        for Kd in (1, 4):
            G = ltp.lifted_frequency_response(data, T, Kd, transient=transient,
                                              input_hold='foh')
            ways.append((G, {}))
        for d, kw in ways:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter('always')
                model, info = ltp.identify_ltp(d, T, 1, 1, return_info=True, **kw)
            count += 1
            if info.success and not caught:
                assert fresh(model, sys) <= 0.1
    assert count == 6


def test_noise_above_the_holdout_error_leaves_the_share_unknown():
    sys = plant()
    exc = ltp.sine_experiments(W[:12], T, dt=DT, nperiods=8, settle=12)
    y = np.asarray(ltp.forced_response(sys, exc.time, exc.inputs).outputs)
    # lifted data with a std far above their actual error
    G = ltp.lifted_frequency_response((exc.time, exc.inputs, y), T, 4, transient=6.0,
                                      input_hold='foh')
    scale = 1e-6 * np.abs(G.frdata).mean()
    _, info = ltp.identify_ltp(G, T, 1, 1, std=scale, return_info=True)
    # the noise level scales with std: choose it 1.2 times the held-out NRMSE
    std = scale * 1.2 * info.holdout_nrmse / info.holdout_noise
    with pytest.warns(UserWarning, match='unknown'):
        _, info = ltp.identify_ltp(G, T, 1, 1, std=std, return_info=True)
    assert info.holdout_noise > info.holdout_nrmse and np.isnan(info.holdout_error)
    assert 'unknown' in info.message
    assert info.success == (info.holdout_nrmse <= 0.05)


def test_transient_in_the_window_is_not_noise(records):
    """Records from rest analysed from their start: the free bins hold the start-up
    transient, which is not subtracted as noise."""
    sys = plant()
    exc = ltp.sine_experiments(W, T, dt=DT, nperiods=8, settle=8)
    x0 = np.full((1, exc.inputs.shape[1]), 40.0)
    resp = ltp.forced_response(sys, exc.time, exc.inputs, initial_state=x0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        _, info = ltp.identify_ltp(resp, T, 1, 1, transient=0.0, input_hold='foh',
                                   return_info=True)
    assert np.isnan(info.holdout_noise)
    assert info.holdout_error == info.holdout_nrmse
    assert any('transient' in str(w.message) for w in caught)


def test_zoh_records_with_default_settings_warn():
    sys = plant()
    exc = ltp.sine_experiments(W[:16], T, dt=DT, nperiods=8, settle=12)
    resp = ltp.forced_response(sys, exc.time, exc.inputs, input_hold='zoh')
    with pytest.warns(UserWarning, match="input_hold not given"):
        model, info = ltp.identify_ltp(resp, T, 1, 1, transient=6.0, return_info=True)
    assert info.input_hold == 'foh'
    right = ltp.identify_ltp(resp, T, 1, 1, transient=6.0, input_hold='zoh')
    assert fresh(right, sys, 'zoh') < 2e-2 < fresh(model, sys, 'zoh')
    # the fresh-record check tells the holds apart
    L = 400
    u = np.random.default_rng(0).standard_normal(L)
    t = np.arange(L) * DT
    y = ltp.forced_response(sys, t, u, input_hold='zoh').outputs
    with pytest.warns(UserWarning, match="input_hold='zoh'"):
        res = ltp.validate_ltp(sys, (t, u, y))
    assert res.hold_nrmse['zoh'] < 1e-9 < res.nrmse
    assert ltp.validate_ltp(sys, (t, u, y), input_hold='check').input_hold == 'zoh'


def test_validate_ltp_bad_input():
    sys = plant()
    t = np.arange(10) * DT
    with pytest.raises(ValueError, match='input_hold'):
        ltp.validate_ltp(sys, (t, np.ones(10), np.ones(10)), input_hold='cubic')
    with pytest.raises(ltp.ControlDimension if hasattr(ltp, 'ControlDimension')
                       else Exception, match='inputs'):
        ltp.validate_ltp(sys, (t, np.ones((2, 10)), np.ones(10)))
    with pytest.raises(ValueError, match='transient'):
        ltp.validate_ltp(sys, (t, np.ones(10), np.ones(10)), transient=-1.0)
    with pytest.raises(ValueError, match='no sample'):
        ltp.validate_ltp(sys, (t, np.ones(10), np.ones(10)), transient=5.0)
    with pytest.raises(Exception, match='LTPStateSpace'):
        ltp.validate_ltp("model", (t, np.ones(10), np.ones(10)))


def test_excitation_passed_as_it_is(records):
    sys, exc, resp = records
    model, info = ltp.identify_ltp(resp, T, 1, 1, excitation=exc, input_hold='foh',
                                   return_info=True)
    same = ltp.identify_ltp(resp, T, 1, 1, transient=6.0, input_hold='foh')
    assert info.success
    np.testing.assert_allclose(model.A(0.0), same.A(0.0), rtol=1e-8)
    # band multisines of one experiment hold separable lines
    ms = ltp.multisine(('band', 0.5, 30.0), T, dt=DT, nperiods=40, settle=20)
    r = ltp.forced_response(sys, ms.time, ms.inputs)
    _, info = ltp.identify_ltp(r, T, 1, 1, excitation=ms, input_hold='foh', return_info=True)
    assert info.success
    # scalar time for variable-step simulators
    assert np.shape(exc.signal(0.3)) == exc.inputs.shape[:2]
    assert np.shape(ms.signal(0.3)) == ms.inputs.shape[:2] == (1, 1)
    np.testing.assert_allclose(exc.signal(exc.time[5]), exc.inputs[..., 5])
    chirp = ltp.chirp_replicas(T, 3, 2.0, 0.0, 5.0, dt=DT)
    with pytest.raises(ValueError, match='estimate_htf'):
        ltp.identify_ltp(resp, T, 1, 1, excitation=chirp)
    G = ltp.lifted_frequency_response(resp, T, 4, transient=6.0)
    with pytest.raises(TypeError, match='excitation'):
        ltp.identify_ltp(G, T, 1, 1, excitation=exc)
    with pytest.raises(ValueError, match='input_hold'):
        ltp.identify_ltp(resp, T, 1, 1, input_hold='cubic')


def test_closed_loop_records_get_advice_that_applies(records):
    sys, exc, _ = records
    # the input of the records depends on the output (and its noise)
    t = exc.time
    u = exc.inputs.copy()
    u = u + 0.1 * np.random.default_rng(0).standard_normal(u.shape)
    y = ltp.forced_response(sys, t, u).outputs
    with pytest.raises(ValueError, match='Closed-loop records.*joint_io_htf'):
        ltp.identify_ltp((t, u, y), T, 1, 1, transient=6.0, input_hold='foh')
