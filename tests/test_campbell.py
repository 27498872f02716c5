"""Campbell diagrams: tracking by mode shape, crossings, parallel sweeps."""

import numpy as np
import pytest
from scipy.optimize import brentq
from control.exception import ControlArgument

import ltpcontrol as ltp
from examples.rotor_models import hammond_A, hammond_groups
from test_rotors import mbc_by_hand


def hammond_mbc_model(Omega):
    g, r = hammond_groups()
    sys = ltp.ltpss(lambda t: hammond_A(t, Omega), np.zeros((12, 0)), np.zeros((0, 12)), 0,
                    period=2 * np.pi / Omega)
    return ltp.mbc(sys, g, 4, rates=r)[0]


def crossing_oscillators(p):
    """Two uncoupled oscillators at 1 + p and 3 - p rad/s: they cross at p = 1."""
    A = np.zeros((4, 4))
    A[:2, :2] = [[-0.01, 1 + p], [-1 - p, -0.01]]
    A[2:, 2:] = [[-0.02, 3 - p], [-3 + p, -0.02]]
    return ltp.ltpss(A, np.zeros((4, 0)), np.zeros((0, 4)), 0, period=1.0)


def test_tracks_follow_mode_shapes_through_a_crossing():
    values = np.linspace(0.0, 2.0, 31)
    cd = ltp.campbell(crossing_oscillators, values, n_jobs=1, per_rev=())
    # each track keeps its oscillator (its damping identifies it) across p = 1
    for k in range(4):
        assert np.ptp(cd.damping[:, k] * cd.frequency[:, k]) < 1e-9
    rising = [k for k in range(4) if cd.frequency[-1, k] > 2.9]
    falling = [k for k in range(4) if cd.frequency[-1, k] < 1.1]
    assert np.allclose(cd.frequency[:, rising[0]], np.hypot(0.01, 1 + values))
    assert np.allclose(cd.frequency[:, falling[0]], np.hypot(0.02, 3 - values))
    cross = cd.track_crossings(rising[0], falling[0])
    truth = brentq(lambda p: np.hypot(0.01, 1 + p) - np.hypot(0.02, 3 - p), 0.5, 1.5)
    assert len(cross) == 1 and abs(cross[0] - truth) <= values[1] - values[0]
    assert np.all(cd.mac > 0.99)


@pytest.mark.slow
def test_hammond_campbell_sweep_in_parallel():
    speeds = np.linspace(5.0, 40.0, 31)
    cd = ltp.campbell(hammond_mbc_model, speeds, n_jobs=1, per_rev=(1,))
    step = speeds[1] - speeds[0]
    for k, Omega in enumerate(speeds):
        lti = np.linalg.eigvals(mbc_by_hand(Omega, 0.0))
        for lam in cd.exponents[k]:                    # every track value is an eigenvalue
            assert np.abs(lti - lam).min() < 1e-6 * np.abs(lti).max()
    # continuous tracks: no jump larger than the frequencies' slope allows
    slope = np.abs(np.diff(cd.frequency, axis=0)) / step
    assert slope.max() < 2.0
    # crossings with the 1P line within the sweep resolution of the exact ones
    assert cd.crossings
    for track, n, value, _ in cd.crossings:
        k = int(np.clip(np.searchsorted(speeds, value) - 1, 0, len(speeds) - 2))
        start = cd.exponents[k, track]

        def g(Omega):
            # the eigenvalue continued from the track's value at speeds[k]
            lam, Om = start, speeds[k]
            for w in np.linspace(speeds[k], Omega, 8)[1:]:
                ev = np.linalg.eigvals(mbc_by_hand(w, 0.0))
                lam = ev[np.argmin(np.abs(ev - lam))]
            return np.abs(lam) - n * Omega
        exact = brentq(g, speeds[k], speeds[k + 1], xtol=1e-10)
        assert abs(exact - value) <= step
    # parallel workers (loky processes; starting them dominates the cost) give the
    # serial sweep's tracks
    parallel = ltp.campbell(hammond_mbc_model, speeds[:4], n_jobs=2, per_rev=(1,))
    assert np.allclose(parallel.frequency, cd.frequency[:4])
    assert np.array_equal(parallel.indices, cd.indices[:4])


def test_campbell_rejects_bad_input():
    with pytest.raises(ValueError, match="monotonic"):
        ltp.campbell(crossing_oscillators, [0.0, 1.0, 0.5], n_jobs=1)
    with pytest.raises(ControlArgument, match="factory"):
        ltp.campbell(42, [0.0, 1.0])
    with pytest.raises(ValueError, match="one value per sweep value"):
        ltp.campbell(crossing_oscillators, [0.0, 1.0], rotor_speed=[1.0], n_jobs=1)


def test_threaded_sweep_equals_serial_sweep():
    values = np.linspace(0.0, 2.0, 6)
    serial = ltp.campbell(crossing_oscillators, values, n_jobs=1)
    threaded = ltp.campbell(crossing_oscillators, values, n_jobs=2, backend='threading')
    assert np.allclose(serial.exponents, threaded.exponents)
    assert serial.crossings == threaded.crossings


def test_dask_sweep_equals_serial_sweep():
    distributed = pytest.importorskip('distributed')
    values = np.linspace(0.0, 2.0, 6)
    serial = ltp.campbell(crossing_oscillators, values, n_jobs=1)
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=2,
                            dashboard_address=None):
        dask = ltp.campbell(crossing_oscillators, values, n_jobs=2, backend='dask')
    assert np.allclose(serial.exponents, dask.exponents)
