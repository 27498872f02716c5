"""Tests of the excitation designs (chirp replicas, sines, multisines)."""

import numpy as np
import pytest
from control.exception import ControlArgument

from ltpcontrol import chirp_replicas, multisine, sine_experiments
from ltpcontrol import estimate_htf
from test_htf_estimate import ScalarLTP


def test_chirp_replicas_layout_and_samples():
    T, R, D, dt, gap = 0.5, 5, 3.0, 0.01, 1.2
    exc = chirp_replicas(T, R, D, 0.5, 6.0, dt=dt, amplitude=0.2, gap=gap)
    # record: smallest whole number of periods holding (R-1)T/R + D + gap = 4.6 s
    nrec = 10 * 50
    assert exc.segments.tolist() == [[r * nrec, (r + 1) * nrec] for r in range(R)]
    assert exc.time.size == R * nrec and exc.time[1] == pytest.approx(dt)
    assert exc.frequencies is None
    for r in range(R):
        start = r * nrec * dt + r * T / R            # phase shift r T/R in the cycle
        assert (start % T) == pytest.approx(r * T / R)
        tau = exc.time[r * nrec:(r + 1) * nrec] - start
        on = (tau >= 0) & (tau < D)
        ref = 0.2 * np.sin(2 * np.pi * (0.5 * tau + (6.0 - 0.5) * tau ** 2 / (2 * D)))
        assert np.allclose(exc.inputs[r * nrec:(r + 1) * nrec][on], ref[on], atol=1e-12)
        assert np.all(exc.inputs[r * nrec:(r + 1) * nrec][~on] == 0)
        # at least `gap` seconds of silence at the end of each record
        assert np.all(tau[on] <= (nrec * dt - gap) - r * T / R)
    assert np.array_equal(exc.signal(exc.time), exc.inputs)


def _coherence(exc, K, T, dt):
    """Normalised |Φ_UU| of the replica windows (independent DFTs)."""
    nper = int(round(T / dt))
    L = (exc.segments[0, 1] - exc.segments[0, 0]) // nper
    U = np.array([np.fft.fft(exc.inputs[a:b])
                  * np.exp(-2j * np.pi * np.fft.fftfreq(b - a, dt) * exc.time[a])
                  for a, b in exc.segments])
    m = np.arange(3 * L, 5 * L)
    reg = np.stack([U[:, (m - k * L) % U.shape[1]] for k in range(-K, K + 1)], axis=-1)
    puu = np.einsum('rfa,rfb->fab', reg.conj(), reg)
    diag = np.real(np.diagonal(puu, axis1=1, axis2=2))
    return np.abs(puu) / np.sqrt(diag[:, :, None] * diag[:, None, :])


def test_replicas_diagonalise_extended_power_spectrum():
    # Σ_r conj U_r(ω - kω_p) U_r(ω - lω_p) = 0 for k ≠ l when R >= 2K+1 (|k-l| < R);
    # T/(R dt) is an integer here, so the sampled replicas are exact delayed copies
    T = 1.2
    coh = _coherence(chirp_replicas(T, 5, 6.0, 0.0, 8.0, dt=0.02, gap=1.0), 2, T, 0.02)
    coh[:, np.arange(5), np.arange(5)] = 0
    assert np.max(coh) < 1e-10
    # with R = 3 < 2K+1, harmonics 3 apart are fully coherent (not separable)
    coh = _coherence(chirp_replicas(T, 3, 6.0, 0.0, 8.0, dt=0.02, gap=1.0), 2, T, 0.02)
    assert np.allclose(coh[:, 0, 3], 1) and np.allclose(coh[:, 1, 4], 1)
    assert np.max(coh[:, 0, 1:3]) < 1e-10


@pytest.mark.parametrize("args, kwargs, exc_type, match", [
    ((1.0, 3, 5.0, 2.0, 1.0), {"dt": 0.01}, ValueError, "f1"),
    ((1.0, 3, 5.0, 0.0, 60.0), {"dt": 0.01}, ValueError, "Nyquist"),
    ((1.0, 3, 5.0, 0.0, 4.0), {"dt": 0.03}, ValueError, "dt"),
    ((1.0, 0, 5.0, 0.0, 4.0), {"dt": 0.01}, ValueError, "nreplicas"),
    ((1.0, 2.5, 5.0, 0.0, 4.0), {"dt": 0.01}, ControlArgument, "nreplicas"),
    ((1.0, 3, -5.0, 0.0, 4.0), {"dt": 0.01}, ValueError, "duration"),
    ((1.0, 3, 5.0, -1.0, 4.0), {"dt": 0.01}, ValueError, "f0"),
    ((1.0, 3, 5.0, 0.0, 4.0), {"dt": 0.01, "gap": -1}, ValueError, "gap"),
    ((1.0, 3, 5.0, 0.0, 4.0), {"dt": 0.01, "taper": 1}, TypeError, "taper"),
    ((-1.0, 3, 5.0, 0.0, 4.0), {"dt": 0.01}, ValueError, "period"),
])
def test_chirp_replicas_errors(args, kwargs, exc_type, match):
    with pytest.raises(exc_type, match=match):
        chirp_replicas(*args, **kwargs)


def test_sine_experiments_whole_cycles_in_window():
    T, dt = 2.0, 0.02
    exc = sine_experiments([1.0, 2.2, 5.0], T, dt=dt, nperiods=5, settle=1, amplitude=0.3)
    step = 2 * np.pi / (5 * T)
    assert np.allclose(exc.frequencies, np.round(np.array([1.0, 2.2, 5.0]) / step) * step)
    a, b = exc.segments[0]
    assert (a, b) == (100, 600) and exc.inputs.shape == (1, 3, 600)
    for e, w in enumerate(exc.frequencies):
        spec = np.abs(np.fft.rfft(exc.inputs[0, e, a:b])) / (b - a)
        line = int(round(w / step))
        assert spec[line] == pytest.approx(0.15)       # amplitude/2: a single line
        spec[line] = 0
        assert np.max(spec) < 1e-12


def test_sine_experiments_warn_at_half_multiples():
    with pytest.warns(UserWarning, match="omega_p/2"):
        exc = sine_experiments([np.pi, 1.3], 2.0, dt=0.02, nperiods=4)
    assert exc.frequencies[1] == pytest.approx(np.pi)


@pytest.mark.parametrize("freqs, kwargs, exc_type, match", [
    ([0.0], {}, ValueError, "frequencies"),
    ([], {}, ValueError, "frequencies"),
    ([0.01], {}, ValueError, "resolution"),
    ([200.0], {}, ValueError, "Nyquist"),
    ([1.0], {"nperiods": 0}, ValueError, "nperiods"),
    ([1.0], {"settle": -1}, ValueError, "settle"),
    ([1.0], {"bogus": 1}, TypeError, "bogus"),
    ([[1.0]], {}, Exception, "frequencies"),
])
def test_sine_experiments_errors(freqs, kwargs, exc_type, match):
    opts = {"dt": 0.02, "nperiods": 4, **kwargs}
    with pytest.raises(exc_type, match=match):
        sine_experiments(freqs, 2.0, **opts)


def test_multisine_band_shifts_and_phases():
    T, dt, R = 1.0, 0.01, 3
    exc = multisine(('band', 1.0, 12.0), T, dt=dt, nperiods=4, nexperiments=R,
                    settle=1, amplitude=0.1)
    step = 2 * np.pi / 4
    bins = np.round(exc.frequencies / step).astype(int)
    assert np.all(bins % 2 == 1)                       # multiples of ω_p/2 skipped
    assert exc.inputs.shape == (1, R, 500)
    # experiment r is experiment 0 delayed by r T / R
    t = np.linspace(0, 4, 37)
    for r in range(R):
        assert np.allclose(exc.signal(t)[0, r], exc.signal(t - r * T / R)[0, 0], atol=1e-12)
    # window spectrum: lines only at the requested frequencies
    a, b = exc.segments[0]
    spec = np.abs(np.fft.rfft(exc.inputs[0, 0, a:b])) / (b - a)
    assert np.allclose(spec[bins], 0.05)
    spec[bins] = 0
    assert np.max(spec) < 1e-12
    # Schroeder phases give a lower crest factor than zero phases
    flat = multisine(exc.frequencies, T, dt=dt, nperiods=4, phases=np.zeros(bins.size))
    crest = lambda u: np.max(np.abs(u)) / np.sqrt(np.mean(u ** 2))
    assert crest(exc.inputs[0, 0, a:b]) < 0.7 * crest(flat.inputs[0, 0])
    rnd = multisine(exc.frequencies, T, dt=dt, nperiods=4, phases='random', seed=3)
    assert np.allclose(np.abs(np.fft.rfft(rnd.inputs[0, 0]))[bins] / 400, 0.5)


def test_multisine_errors_and_warning():
    with pytest.warns(UserWarning, match="omega_p/2"):
        multisine([np.pi, 2.5], 1.0, dt=0.01, nperiods=4)
    with pytest.raises(ValueError, match="phases"):
        multisine([2.5], 1.0, dt=0.01, nperiods=4, phases='zero')
    with pytest.raises(ValueError, match="phases"):
        multisine([2.5, 4.0], 1.0, dt=0.01, nperiods=4, phases=[0.0])
    with pytest.raises(ValueError, match="no grid line"):
        multisine(('band', 3.1, 3.12), 1.0, dt=0.01, nperiods=4)
    with pytest.raises(ValueError, match="unknown"):
        multisine(('range', 1.0, 3.0), 1.0, dt=0.01, nperiods=4)
    with pytest.raises(ValueError, match="nexperiments"):
        multisine([2.5], 1.0, dt=0.01, nperiods=4, nexperiments=0)


def test_multisine_experiments_identify_htf():
    # five multisine experiments shifted by T/5 in steady state identify G_{-1..1}
    system = ScalarLTP()
    exc = multisine(('band', 0.5, 2 * np.pi * 3.0), 1.0, dt=0.01, nperiods=8,
                    nexperiments=5, settle=10, amplitude=0.05)
    records = [(exc.time, exc.inputs[0, r], system.simulate(lambda s: exc.signal(s)[0, r],
                                                          exc.time)[0])
               for r in range(5)]
    est = estimate_htf(records, 1.0, 1, segments=exc.segments)
    bins = np.round(est.omega / (2 * np.pi / 8)).astype(int)
    assert np.all(bins % 4 != 0) and est.omega.size >= 12
    true = system.htf(est.omega, 1)
    assert np.max(np.abs(est.components()[1] - true) / np.abs(true)) < 0.02


def test_designs_in_channel_experiment_time_order():
    import ltpcontrol as ltp
    from control.exception import ControlDimension
    sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=2.0)
    exc = sine_experiments([1.0, 2.2], 2.0, dt=0.02, nperiods=4)
    assert exc.inputs.shape == (1, 2, 400) and exc.signal(0.3).shape == (1, 2)
    # forced_response takes the design as it is: one trace per experiment
    y = ltp.forced_response(sys, exc.time, exc.inputs).outputs
    assert np.shape(y) == (1, 2, 400)
    # the former (experiments, samples) order is refused with the shape to give
    old = exc.inputs[0]
    with pytest.raises(ControlDimension, match=r"shape \(1, 2, L\)"):
        ltp.lifted_frequency_response((exc.time, old, y[0]), 2.0, 1)


def test_multisine_signal_at_single_instants_equals_the_record():
    # a variable-step simulator asks for one instant at a time: same values
    # (same bits) as the whole record, for one and several experiments and inputs
    for kw in ({}, {'nexperiments': 3}, {'nexperiments': 2, 'ninputs': 2}):
        exc = multisine(('band', 3.0, 40.0), 0.33, dt=0.01, nperiods=30, settle=2, **kw)
        for k in (0, 7, 1000, exc.time.size - 1):
            np.testing.assert_array_equal(exc.signal(exc.time[k]), exc.inputs[..., k])
