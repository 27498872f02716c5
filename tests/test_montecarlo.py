"""Tests of `monte_carlo`: reproducibility across workers and backends, bad draws."""

import os
import time

import numpy as np
import pytest

import ltpcontrol as ltp


def _normal_pair(rng, scale=1.0):
    return scale * rng.standard_normal(2)


def _ragged(rng):
    return np.zeros(2 if rng.random() < 0.5 else 3)


def _fails_on_negative(rng):
    x = rng.standard_normal()
    if x < -0.5:
        raise np.linalg.LinAlgError("singular matrix")
    return x


def _sleeps(rng):
    time.sleep(3)
    return 0.0


@pytest.mark.slow
def test_statistics_and_reproducibility():
    serial = ltp.monte_carlo(_normal_pair, 64, seed=5, kwargs={'scale': 2.0})
    parallel = ltp.monte_carlo(_normal_pair, 64, seed=5, n_jobs=2, kwargs={'scale': 2.0})
    assert np.array_equal(serial.samples, parallel.samples)
    assert serial.samples.shape == (64, 2)
    assert np.allclose(serial.mean, serial.samples.mean(axis=0))
    assert np.allclose(serial.cov, np.cov(serial.samples.T))
    assert np.allclose(serial.sem, serial.samples.std(axis=0, ddof=1) / 8)
    other = ltp.monte_carlo(_normal_pair, 64, seed=6)
    assert not np.array_equal(serial.samples, other.samples)


def test_complex_samples():
    res = ltp.monte_carlo(lambda rng: rng.standard_normal(3) + 1j * rng.standard_normal(3),
                          200, seed=1)
    assert res.cov.dtype.kind == 'c'
    assert np.allclose(np.diag(res.cov).real, 2, rtol=0.3)


def test_inconsistent_and_failing_draws_raise_clearly():
    with pytest.raises(ValueError, match=r"draw \d+ returned shape \(\d,\), draw 0"):
        ltp.monte_carlo(_ragged, 20, seed=0)
    with pytest.raises(ValueError, match="non-finite"):
        ltp.monte_carlo(lambda rng: np.nan, 3)
    with pytest.raises(ValueError, match="numbers"):
        ltp.monte_carlo(lambda rng: 'x', 3)
    with pytest.raises(RuntimeError, match=r"draw \d+ raised LinAlgError: singular"):
        ltp.monte_carlo(_fails_on_negative, 40, seed=0)
    with pytest.raises(TypeError, match="callable"):
        ltp.monte_carlo(3, 10)
    with pytest.raises(ValueError):
        ltp.monte_carlo(_normal_pair, 0)


def test_stuck_draw_times_out():
    import joblib
    start = time.perf_counter()
    with joblib.parallel_config(backend='threading'), \
            pytest.raises(TimeoutError, match="did not finish within timeout=0.5"):
        ltp.monte_carlo(_sleeps, 2, n_jobs=2, timeout=0.5)
    assert time.perf_counter() - start < 2.5


def test_dask_backend_gives_the_same_samples():
    if os.environ.get('CI', '').lower() in ('true', '1'):
        import dask.distributed as distributed     # CI installs the cluster extra: never skipped
    else:
        distributed = pytest.importorskip("dask.distributed")
    import joblib
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster):
        with joblib.parallel_config(backend='dask'):
            res = ltp.monte_carlo(_normal_pair, 16, seed=3)
    assert np.array_equal(res.samples, ltp.monte_carlo(_normal_pair, 16, seed=3).samples)


def test_unseeded_study_can_be_repeated():
    first = ltp.monte_carlo(_normal_pair, 5)
    again = ltp.monte_carlo(_normal_pair, 5, seed=first.seed)
    assert np.array_equal(first.samples, again.samples)
