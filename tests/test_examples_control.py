"""The data-to-controller examples (simplified hopper, VHOP), in quick mode."""

import os
import runpy
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import ltpcontrol as ltp

EXAMPLES = Path(__file__).resolve().parents[1] / 'examples'


def _quick_run(script, tmp_path, monkeypatch):
    """The example's module namespace and the figures of its quick `run`."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, 'path', [str(EXAMPLES)] + sys.path)
    monkeypatch.setenv('LTP_EXAMPLES_QUICK', '1')
    example = runpy.run_path(str(EXAMPLES / script))
    return example, example['run']()[0]


@pytest.mark.slow
def test_hopper_control_chain(tmp_path, monkeypatch, capsys):
    example, out = _quick_run('plot_hopper_control.py', tmp_path, monkeypatch)
    # the identified design verified on the hybrid plant
    assert out['open'] == pytest.approx(0.599, abs=1e-3)
    assert out['identified'] <= 0.3
    true_reduction = out['open'] - out['true linearization']
    assert out['open'] - out['identified'] >= 0.8 * true_reduction
    # push recovery is faster in closed loop, with bounded effort
    assert out['strides closed'] is not None and out['strides open'] is not None
    assert out['strides closed'] < out['strides open']
    assert out['effort'] <= example['EFFORT_BOUND']
    assert os.environ.get('LTP_EXAMPLES_QUICK') == '1'


@pytest.fixture(scope='module')
def vhop(tmp_path_factory):
    with pytest.MonkeyPatch.context() as monkeypatch:
        return _quick_run('plot_vhop_control.py', tmp_path_factory.mktemp('vhop'), monkeypatch)


@pytest.mark.slow
def test_vhop_control_chain(vhop):
    example, out = vhop
    # open loop: the exact return map of the hybrid limit cycle
    assert out['open'] == pytest.approx(0.848, abs=1e-3)
    # the model identified from data has the plant's open-loop multipliers
    np.testing.assert_allclose(np.sort_complex(out['identified model']),
                               np.sort_complex(out['open multipliers']), atol=0.01)
    # verified on the hybrid plant: LQG on the noise-free model and the
    # band-limited LQG on both models meet the target and reach at least 80 %
    # of the reduction of LQG on the true linearization
    best = out['open'] - out['LQG', 'true linearization']
    for key in (('LQG', 'identified'), ('band-limited LQG', 'identified'),
                ('band-limited LQG', 'identified, SNR 12.5')):
        assert out[key] <= 0.3, key
        assert out['open'] - out[key] >= 0.8 * best, key
    # without the band limit the noisy model's design is far from the target
    assert out['LQG', 'identified, SNR 12.5'] > 0.5
    # push recovery is faster in closed loop, with the stated effort bound
    assert out['strides closed'] is not None and out['strides open'] is not None
    assert out['strides closed'] < out['strides open']
    assert out['effort'] <= example['EFFORT_BOUND']


@pytest.mark.slow
@pytest.mark.parametrize('seed', [2, 9])
def test_vhop_noisy_draws_restart_to_a_stable_model(vhop, seed):
    # these noise draws send the refinement from the best-fitting realization
    # to an unstable model (multiplier 7e9 and 2e5); identify_ltp restarts from
    # the other realizations and returns the stable model of the plant's multipliers
    example, out = vhop
    t, u, y = out['records']['data']
    with warnings.catch_warnings():
        warnings.simplefilter('error', UserWarning)
        warnings.filterwarnings('ignore', message='.*misses the data')       # the noise
        # at SNR 12.5 the noise of the held-out lines alone exceeds validation_tol
        warnings.filterwarnings('ignore', message='.*held-out lines')
        warnings.filterwarnings('ignore', message='.*Fisher information')
        # the records' sampling holds fewer harmonics than the model produces
        warnings.filterwarnings('ignore', message='.*neither fitted nor validated')
        model, _ = example['identify']((t, *example['with_noise'](u, y, seed)),
                                       out['records']['transient'], out['records']['lines'])
    assert model.is_stable()
    np.testing.assert_allclose(np.sort_complex(ltp.floquet_multipliers(model)),
                               np.sort_complex(out['open multipliers']), atol=0.02)
