"""Gain and phase of a disk margin at the edge α = 2 (strictly proper loop, |S - 1/2|
peaking at infinity): an infinite upper gain, not a division error."""

import numpy as np
import pytest

from ltpcontrol._frequency.margins import _disk_gain_phase


def test_alpha_two_gives_infinite_gain():
    (gmin, gmax), phase = _disk_gain_phase(2.0, 0.0)
    assert gmin == 0.0 and gmax == np.inf and phase == 90.0


@pytest.mark.parametrize('alpha', [0.3, 1.0, 1.9])
def test_balanced_disk_closed_form(alpha):
    # skew 0: gains (2 - α)/(2 + α), (2 + α)/(2 - α); phase 2 atan(α/2)
    (gmin, gmax), phase = _disk_gain_phase(alpha, 0.0)
    assert gmin == pytest.approx((2 - alpha) / (2 + alpha), rel=1e-14)
    assert gmax == pytest.approx((2 + alpha) / (2 - alpha), rel=1e-14)
    assert phase == pytest.approx(np.degrees(2 * np.arctan(alpha / 2)), rel=1e-12)
