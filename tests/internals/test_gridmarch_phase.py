"""Uniform grids whose phases never repeat: step data interpolated in the phase.

Tests of internals: they import private names (see the Developer notes).
"""

import numpy as np

import ltpcontrol as ltp
from ltpcontrol._core import gridmarch
from ltpcontrol._core.transition import step_transitions


def mathieu(callable_form):
    w = 2 * np.pi
    if callable_form:
        A = lambda t: np.array([[0.0, 1.0], [-(1 + 0.2 * np.cos(w * t)) * w ** 2,   # noqa: E731
                                             -0.6 * w]])
    else:
        c = np.zeros((3, 2, 2), complex)
        c[1] = [[0, 1], [-w ** 2, -0.6 * w]]
        c[0] = c[2] = [[0, 0], [-0.1 * w ** 2, 0]]
        A = ltp.PeriodicMatrix(c, 1.0)
    return ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=1.0)


def step_by_step(sys, t, u):
    Phi, G0, G1 = step_transitions(sys.A, sys.B, t[:-1], np.diff(t))
    x, ys = np.zeros(2), [0.0]
    for j in range(len(t) - 1):
        x = Phi[j] @ x + G0[j][:, 0] * u[j] + G1[j][:, 0] * (u[j + 1] - u[j])
        ys.append(x[0])
    return np.array(ys)


def test_fine_unaligned_grid_equals_the_same_discretization():
    for form in (False, True):
        sys = mathieu(form)
        t = np.linspace(0, 5.0, 1801)              # 360 steps per period, not dividing T
        u = np.sin(3.1 * t) + 0.2 * np.cos(17.0 * t)
        y = np.asarray(ltp.forced_response(sys, t, u).outputs).ravel()
        ref = step_by_step(sys, t[:700], u[:700])
        assert np.abs(y[:700] - ref).max() <= 1e-11 * np.abs(ref).max()


def test_phase_interpolant_reproduces_step_data_and_refuses_switching():
    sys = mathieu(False)
    h = 1.0 / 357.3
    table = gridmarch._phase_table(sys.A, sys.B, h, 1.0, 1e-12)
    assert table is not None
    tk = np.array([0.01234, 0.5, 0.98765, 3.3])
    got = table(tk, np.full(4, h))
    ref = step_transitions(sys.A, sys.B, tk, h)
    for g, r in zip(got, ref):
        assert np.abs(g - r).max() <= 1e-12 * max(1.0, np.abs(r).max())
    S = ltp.PeriodicMatrix.switching([[[-1.0]], [[-2.0]]], [0, 0.3], 1.0)
    assert gridmarch._phase_table(S, ltp.PeriodicMatrix.constant([[1.0]], 1.0), h, 1.0,
                                  1e-12) is None
