"""The data-to-controller example on the simplified hopper, in quick mode."""

import os
import runpy
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / 'examples'


@pytest.mark.slow
def test_hopper_control_chain(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, 'path', [str(EXAMPLES)] + sys.path)
    monkeypatch.setenv('LTP_EXAMPLES_QUICK', '1')
    example = runpy.run_path(str(EXAMPLES / 'plot_hopper_control.py'))
    out, *_ = example['run']()
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
