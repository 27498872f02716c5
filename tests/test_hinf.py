"""H∞ norm: infinite for unstable systems; the peak frequency located and unfolded."""

import control as ct
import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import ltpcontrol as ltp


def _rotated(A0, B0, C0, w=2.0, T=np.pi):
    # an LTI plant in rotating state coordinates x_r = P(t) x (same input/output map),
    # vectorised over t
    def P(t):
        c, s = np.cos(w * np.asarray(t, float)), np.sin(w * np.asarray(t, float))
        return np.stack([np.stack([c, s], -1), np.stack([-s, c], -1)], -2)

    def Pd(t):
        c, s = np.cos(w * np.asarray(t, float)), np.sin(w * np.asarray(t, float))
        return w * np.stack([np.stack([-s, c], -1), np.stack([-c, -s], -1)], -2)
    tr = lambda M: np.swapaxes(M, -1, -2)  # noqa: E731
    A = ltp.PeriodicMatrix.from_function(lambda t: Pd(t) @ tr(P(t)) + P(t) @ A0 @ tr(P(t)), T)
    B = ltp.PeriodicMatrix.from_function(lambda t: P(t) @ B0, T)
    C = ltp.PeriodicMatrix.from_function(lambda t: C0 @ tr(P(t)), T)
    return ltp.ltpss(A, B, C, 0, period=T)


def _lti_peak(G, lo, hi):
    res = minimize_scalar(lambda w: -abs(np.squeeze(G(1j * w))), bounds=(lo, hi),
                          method='bounded', options={'xatol': 1e-14})
    return -res.fun, res.x


def test_rotated_lti_case_peak_equals_the_lti_peak_unfolded():
    # the reference toolbox's rotated LTI case (period π, rotation 2 rad/s)
    A0, B0 = np.array([[-1, -0.5], [-3, -5.0]]), np.array([[3.0], [1.0]])
    C0 = np.array([[1.0, 2.0]])
    sys = _rotated(A0, B0, C0)
    g0, w0 = _lti_peak(ct.ss(A0, B0, C0, 0), 0.5, 3.0)
    g, w = ltp.hinfnorm(sys, tol=1e-8, unfolded=True)
    assert abs(g - g0) <= 1e-7 * g0
    assert abs(w - w0) <= 1e-6 * w0
    # folded into [0, ω_p/2]: the same frequency modulo ω_p (up to sign)
    folded = np.mod(w, sys.omega_p)
    folded = min(folded, sys.omega_p - folded)
    gf, wf = ltp.hinfnorm(sys, tol=1e-3)
    assert 0 <= wf <= sys.omega_p / 2 and abs(wf - folded) <= 1e-6 * sys.omega_p


def test_unstable_system_has_infinite_hinf_norm_with_a_warning():
    sys = ltp.ltpss(ct.tf([1.0], [1.0, -1.0, 4.0]), period=1.0)
    with pytest.warns(UserWarning, match="unstable"):
        g, w = ltp.hinfnorm(sys)
    assert g == np.inf and np.isnan(w)
    assert np.isfinite(ltp.norm(sys, 'inf'))       # the L∞ norm stays finite
    with pytest.raises(TypeError, match="unfolded"):
        ltp.hinfnorm(sys, unfolded=1)


def test_lmi_hinf_state_feedback_bound_covers_the_independent_closed_loop_norm():
    rng = np.random.default_rng(3)
    N, n = 3, 2
    A = 0.9 * rng.normal(size=(N, n, n))
    B = rng.normal(size=(N, n, 1))
    sysd = ltp.ltpss(A, B, np.eye(n), 0, period=0.3, dt=0.1)
    res = ltp.lmi_statefbk(sysd, objective='hinf')
    K = res.K.sample(N)
    # closed loop w -> z = [x; -K x] (Q = I, R = I, G = I), built by hand
    Acl = A - B @ K
    Ccl = np.concatenate([np.broadcast_to(np.eye(n), (N, n, n)), -K], axis=1)
    cl = ltp.ltpss(Acl, np.broadcast_to(np.eye(n), (N, n, n)), Ccl, np.zeros((N, n + 1, n)),
                   period=0.3, dt=0.1)
    gamma = ltp.norm(cl, 'inf', tol=1e-8)
    assert gamma <= res.bound * (1 + 1e-6)
    assert gamma >= 0.9 * res.bound           # the certificate is not loose
