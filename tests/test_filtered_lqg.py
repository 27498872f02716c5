"""Frequency-weighted LQG: ``lqg(..., input_filter=F)``.

Truths: python-control's lqr/lqe (dlqr/dlqe) on the augmented LTI plant
``series(F, P)`` in the LTI limit, and the separation principle on random
periodic plants (the loop's multipliers are those of the augmented
regulator and estimator).
"""

import control as ct
import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp
from systems import random_periodic_plant, switching_mathieu


def _augmented(P, F):
    """``series(F, P)`` written out, states ``[x_F; x_P]``."""
    nf, n = F.nstates, P.nstates
    A = np.block([[F.A, np.zeros((nf, n))], [P.B @ F.C, P.A]])
    B = np.vstack([F.B, P.B @ F.D])
    C = np.hstack([P.D @ F.C, P.C])
    return A, B, C, P.D @ F.D


def _frequency_response(sys, z, k=0):
    """``C (zI - A)⁻¹ B + D`` of the matrices at step/time k of an LTP system."""
    t = k * (sys.dt or 0.0)
    A, B, C, D = (np.asarray(M(t)) for M in (sys.A, sys.B, sys.C, sys.D))
    return C @ np.linalg.solve(z * np.eye(A.shape[0]) - A, B) + D


@pytest.mark.parametrize('dt', [0.0, 0.1])
def test_lti_limit_equals_python_control(dt):
    """LTI plant written as periodic: the controller is python-control's LQG
    of the augmented plant followed by F (same transfer function)."""
    rng = np.random.default_rng(4)
    P = ct.drss(3, 2, 2, dt=dt) if dt else ct.rss(3, 2, 2)
    P = ct.ss(P.A, P.B, P.C, np.zeros((2, 2)), dt)
    wc = 3.0
    F = ct.ss(ct.tf([[[wc], [0]], [[0], [wc]]], [[[1, wc], [1]], [[1], [1, wc]]]))
    if dt:
        F = ct.sample_system(F, dt, method='tustin')
    Q = np.diag([1.0, 2.0, 0.5])
    R, QN, RN = np.diag([0.3, 1.0]), np.diag([1.0, 0.2]), np.diag([0.05, 0.1])
    ctrl = ltp.lqg(ltp.ltpss(P, period=1.0), Q, R, QN, RN, input_filter=F, name='c')

    A, B, C, D = _augmented(P, F)
    Qa = np.zeros((5, 5))
    Qa[2:, 2:] = Q
    if dt:
        K = ct.dlqr(A, B, Qa, R)[0]
        L = ct.dlqe(A, B, C, QN, RN)[0]
    else:
        K = ct.lqr(A, B, Qa, R)[0]
        L = ct.lqe(A, B, C, QN, RN)[0]
    lqg_aug = ct.ss(A - B @ K - L @ C + L @ D @ K, L, -K, 0, dt)
    expected = ct.series(lqg_aug, F)
    for w in (0.05, 0.7, 3.0, 9.0):
        z = np.exp(1j * w * dt) if dt else 1j * w
        np.testing.assert_allclose(_frequency_response(ctrl, z), expected(z),
                                   rtol=1e-7, atol=1e-10)
    assert ctrl.nstates == 2 + 3 + 2 and ctrl.name == 'c'
    assert ctrl.input_labels == ['y[0]', 'y[1]'] and ctrl.output_labels == ['u[0]', 'u[1]']
    assert (ctrl.ninputs, ctrl.noutputs) == (2, 2)


@pytest.mark.parametrize('case', ['continuous', 'even', 'odd'])
def test_separation_on_random_periodic_plants(case):
    """Closed loop = regulator and estimator of series(F, sys), and the command is F's output."""
    sys = random_periodic_plant(3, ninputs=2, seed=7)
    F = ct.ss(ct.tf([[[2.0], [0]], [[0], [5.0]]], [[[1, 2.0], [1]], [[1], [1, 5.0]]]))
    if case != 'continuous':
        N = 8 if case == 'even' else 7
        sys = ltp.sample_system(sys, 1.0 / N)
        F = ct.sample_system(F, 1.0 / N)
    Q = lambda t: np.diag([1.0 + 0.5 * np.sin(2 * np.pi * t), 1.0, 2.0])   # noqa: E731
    R, QN, RN = np.diag([0.5, 1.0]), np.diag([1.0, 0.3]), [[0.2]]
    ctrl = ltp.lqg(sys, Q, R, QN, RN, input_filter=F)
    aug = ltp.series(F, sys)
    Qa = lambda t: np.pad(Q(t), ((2, 0), (2, 0)))                       # noqa: E731
    _, _, EK = ltp.lqr(aug, Qa, R)
    _, _, EL = ltp.lqe(aug, QN, RN)
    loop = ltp.feedback(sys, ctrl, sign=1)
    expected = np.concatenate([EK, EL])
    if case == 'continuous':
        got = ltp.floquet_exponents(loop)
        np.testing.assert_allclose(np.sort_complex(got.real + 0j).real,
                                   np.sort(expected.real), atol=1e-6)
    else:
        got = np.abs(ltp.floquet_multipliers(loop))
        np.testing.assert_allclose(np.sort(got), np.sort(np.abs(expected) ** sys.nsteps),
                                   atol=1e-9)
    # the controller ends in F: its last states are F's, driven by the LQG's output
    nf = F.nstates
    assert ctrl.nstates == nf + sys.nstates + nf
    np.testing.assert_allclose(np.asarray(ctrl.A(0.0))[-nf:, -nf:], F.A, atol=1e-12)
    np.testing.assert_allclose(np.asarray(ctrl.C(0.0))[:, -nf:], F.C, atol=1e-12)


def test_bad_input_filter():
    sys = random_periodic_plant(2, ninputs=1, seed=1)
    args = (np.eye(2), [[1.0]], [[1.0]], [[0.1]])
    with pytest.raises(ControlArgument, match='input_filter'):
        ltp.lqg(sys, *args, input_filter=np.eye(1))
    with pytest.raises(ControlDimension, match='input_filter'):
        ltp.lqg(sys, *args, input_filter=ct.ss(-np.eye(2), np.eye(2), np.eye(2), 0))
    with pytest.raises(ControlDimension, match='Q must have shape'):
        ltp.lqg(sys, np.eye(3), *args[1:], input_filter=ct.tf([1], [1, 1]))
    with pytest.raises(ValueError, match='input_filter has the time base'):
        ltp.lqg(sys, *args, input_filter=ct.tf([1], [1, 0.5], 0.1))


@pytest.mark.parametrize('dt', [0.0, 0.5 / 10])
def test_separation_on_a_switching_plant(dt):
    """Switching A(t) (thesis eq. 4.25): the loop's exponents are those of the
    augmented regulator and estimator, continuous and sampled (N = 10)."""
    sys = switching_mathieu()
    F = ct.ss(ct.tf([8.0], [1, 8.0]))
    if dt:
        sys, F = ltp.sample_system(sys, dt), ct.sample_system(F, dt, method='tustin')
    Q, R, QN, RN = np.diag([10.0, 1.0]), [[0.1]], [[1.0]], [[0.01]]
    ctrl = ltp.lqg(sys, Q, R, QN, RN, input_filter=F)
    aug = ltp.series(F, sys)
    _, _, EK = ltp.lqr(aug, np.pad(Q, ((1, 0), (1, 0))), R)
    _, _, EL = ltp.lqe(aug, QN, RN)
    got = np.abs(ltp.floquet_multipliers(ltp.feedback(sys, ctrl, sign=1)))
    expected = np.abs(np.exp(np.concatenate([EK, EL]) * sys.period)) if not dt else \
        np.abs(np.concatenate([EK, EL])) ** sys.nsteps
    np.testing.assert_allclose(np.sort(got), np.sort(expected), rtol=1e-6, atol=1e-12)
    assert np.all(got < 1)
