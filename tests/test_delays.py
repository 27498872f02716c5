"""Periodic delay-differential equations: multipliers against closed forms and independent solvers."""

import numpy as np
import pytest

import ltpcontrol as ltp
from delay_systems import (delayed_mathieu, milling, milling_h, mos_multipliers, turning,
                           turning_critical, MILL)


def test_turning_critical_depth_equals_closed_form_lobes():
    # five spindle speeds on four lobes; three written with the delay as period, two with an
    # unrelated period (the history then spans several periods)
    taus = np.array([3.0, 5.0, 8.0, 13.0, 21.0])
    periods = {3.0: 3.0, 5.0: 2.0, 8.0: 8.0, 13.0: 13.0, 21.0: 7.3}
    chart = ltp.stability_chart(lambda tau, w: turning(tau, w, period=periods[tau]), taus,
                                [0.0, 0.45], n_jobs=1, tol=1e-9)
    crit = chart.critical()
    ref = np.array([turning_critical(t) for t in taus])
    np.testing.assert_allclose(crit, ref, rtol=1e-6)
