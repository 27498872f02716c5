"""Designs verified in the hybrid loop: periodic LQG in the LTI limit equals python-control."""

import numpy as np
import control as ct
import pytest
from scipy.linalg import expm

import ltpcontrol as ltp

T = 1.0


@pytest.mark.slow
@pytest.mark.parametrize('seed', [3])
def test_lqg_on_lti_plant_matches_python_control(seed):
    """A forced LTI plant with an LQG controller from ltp.lqg on its periodic form.

    The closed-loop return map of the (one-mode hybrid) plant must be
    ``expm(A_cl T)`` of python-control's lqr/lqe loop.
    """
    rng = np.random.default_rng(seed)
    lti = ct.rss(3, 2, 2, strictly_proper=True)
    shift = 0.3 - np.linalg.eigvals(lti.A).real.max()
    lti = ct.ss(lti.A + shift * np.eye(3), lti.B, lti.C, 0)      # open loop unstable
    A, B, C = lti.A, lti.B, lti.C
    forcing = rng.standard_normal(3)
    Q, R = np.diag([1.0, 2.0, 0.5]), np.diag([0.3, 1.0])
    QN, RN = np.diag([1.0, 0.2]), np.diag([0.05, 0.1])

    ctrl = ltp.lqg(ltp.ltpss(lti, period=T), Q, R, QN, RN)
    Kc, _, _ = ct.lqr(lti, Q, R)
    Lc, _, _ = ct.lqe(lti.A, lti.B, lti.C, QN, RN)
    A_cl = np.block([[A, -B @ Kc], [Lc @ C, A - B @ Kc - Lc @ C]])

    # the plant as a hybrid plant forced along a periodic orbit
    mode = ltp.HybridMode(lambda t, x, u, p: A @ x + B @ u + forcing * np.cos(2 * np.pi * t),
                          jacobian=lambda t, x, u, p: A, input_jacobian=lambda t, x, u, p: B)
    plant = ltp.HybridPlant([mode], lambda t, x, u, p: C @ x, states=3, inputs=2, outputs=2)
    orbit = ltp.periodic_orbit(plant, T, np.zeros(3))
    cl = ltp.closed_loop_orbit(plant, ctrl, orbit)
    expected = np.linalg.eigvals(expm(A_cl * T))
    np.testing.assert_allclose(np.sort(np.abs(cl.multipliers)), np.sort(np.abs(expected)),
                               rtol=1e-6, atol=1e-12)
    assert cl.is_stable and not orbit.is_stable
    # and the monodromy itself (the controller's coordinates are python-control's)
    np.testing.assert_allclose(cl.monodromy, expm(A_cl * T), atol=1e-8)
