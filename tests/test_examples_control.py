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
    """The example's namespace and its noise-free records (the documentation build
    runs the whole chain, quick mode, and checks its claims with `check`)."""
    with pytest.MonkeyPatch.context() as monkeypatch:
        monkeypatch.chdir(tmp_path_factory.mktemp('vhop'))
        monkeypatch.setattr(sys, 'path', [str(EXAMPLES)] + sys.path)
        monkeypatch.setenv('LTP_EXAMPLES_QUICK', '1')
        example = runpy.run_path(str(EXAMPLES / 'plot_vhop_control.py'))
        return example, example['records']()


def test_vhop_control_claims_can_fail(vhop):
    example, _ = vhop
    mu = np.array([0.16 + 0.833j, 0.16 - 0.833j])
    good = {'open': 0.848, 'open multipliers': mu, 'identified model': mu + 0.001,
            ('LQG', 'true linearization'): 0.19, ('LQG', 'identified'): 0.29,
            ('band-limited LQG', 'identified'): 0.13,
            ('band-limited LQG', 'identified, SNR 12.5'): 0.28,
            ('LQG', 'identified, SNR 12.5'): 1.5, 'strides closed': 3, 'strides open': 9,
            'effort': 10.0}
    example['check'](good)
    bad = [('open', 0.9), ('identified model', mu + 0.05), (('LQG', 'identified'), 0.5),
           (('LQG', 'identified, SNR 12.5'), 0.2), ('strides closed', None),
           ('strides closed', 12), ('effort', 2 * example['EFFORT_BOUND'])]
    for key, value in bad:
        with pytest.raises(AssertionError, match='VHOP control claims'):
            example['check']({**good, key: value})


@pytest.mark.slow
@pytest.mark.parametrize('seed', [2, 9])
def test_vhop_noisy_draws_restart_to_a_stable_model(vhop, seed):
    # these noise draws send the refinement from the best-fitting realization
    # to an unstable model (multiplier 7e9 and 2e5); identify_ltp restarts from
    # the other realizations and returns the stable model of the plant's multipliers
    example, (plant, orbit, (t, u, y), transient, lines) = vhop
    with warnings.catch_warnings():
        warnings.simplefilter('error', UserWarning)
        warnings.filterwarnings('ignore', message='.*misses the data')       # the noise
        # at SNR 12.5 the noise of the held-out lines alone exceeds validation_tol
        warnings.filterwarnings('ignore', message='.*held-out lines')
        warnings.filterwarnings('ignore', message='.*Fisher information')
        # the records' sampling holds fewer harmonics than the model produces
        warnings.filterwarnings('ignore', message='.*neither fitted nor validated')
        model, _ = example['identify']((t, *example['with_noise'](u, y, seed)), transient, lines)
    assert model.is_stable()
    np.testing.assert_allclose(np.sort_complex(ltp.floquet_multipliers(model)),
                               np.sort_complex(orbit.multipliers[:2]), atol=0.02)
