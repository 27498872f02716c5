"""LTPStateSpace construction, conversions, interconnections and validation."""

import numpy as np
import control as ct
import pytest
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp
from systems import mathieu, damped_mathieu


def test_standard_keywords_and_attributes():
    sys = ltp.ltpss([[0, 1], [-4, -1]], [[0], [1]], [[1, 0]], 0, period=0.5, name='plant',
                    inputs='force', outputs=['pos'], states=['p', 'v'])
    assert (sys.nstates, sys.ninputs, sys.noutputs) == (2, 1, 1)
    assert sys.input_labels == ['force'] and sys.state_labels == ['p', 'v']
    assert sys.isctime() and not sys.isdtime()
    assert sys.period == 0.5 and np.isclose(sys.omega_p, 4 * np.pi)
    assert repr(sys) == "<LTPStateSpace plant: ['force'] -> ['pos'], period=0.5>"
    assert 'period = 0.5' in str(sys)
    assert sys.copy('other').name == 'other'
    assert isinstance(sys, ct.NonlinearIOSystem) and not isinstance(sys, ct.LTI)


def test_lti_round_trip_and_to_ss():
    G = ct.rss(3, 2, 2, strictly_proper=False)
    sys = ltp.ltpss(G, 1.7)
    assert sys.is_lti and sys.is_floquet_form
    back = sys.to_ss()
    for M in 'ABCD':
        np.testing.assert_array_equal(getattr(back, M), getattr(G, M))
    with pytest.raises(ValueError, match="time-varying"):
        mathieu().to_ss()


def test_frozen_and_averaged_systems():
    sys = damped_mathieu()
    np.testing.assert_allclose(sys.linearize(t=0.0).A, [[0, 1], [-1.4 * (2 * np.pi) ** 2, -0.4 * np.pi]])
    np.testing.assert_allclose(sys.average().A, [[0, 1], [-(2 * np.pi) ** 2, -0.4 * np.pi]])


def test_discrete_system_from_sequences():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(4, 2, 2)) * 0.3
    sys = ltp.ltpss(A, np.ones((2, 1)), [[1, 0]], 0, period=1.0, dt=0.25)
    assert sys.nsteps == 4 and sys.isdtime()
    np.testing.assert_array_equal(sys.A.sample(4), A)
    np.testing.assert_array_equal(sys.A(0.25 * 2 + 0.1), A[2])


def _sim(sys, t, u):
    return ltp.forced_response(sys, t, u).y


@pytest.mark.slow
def test_interconnections_match_simulated_block_diagrams():
    P = mathieu()
    K = ct.ss(ct.tf([2.0], [1.0, 3.0]), name='K', inputs='e', outputs='v')
    t = np.arange(0, 0.5, 0.005)
    u = np.sin(3 * t)
    # reference: python-control's own interconnection and ODE solver (its
    # functions as they are without ltpcontrol's dispatch)
    from ltpcontrol.interop import original
    Pn = P.copy('P')
    Pn.set_inputs(['r'])
    Pn.set_outputs(['e'])
    loop = original('interconnect')([Pn, K], inplist=['r'], outlist=['v'])
    assert not isinstance(loop, ltp.LTPStateSpace)
    ref = original('input_output_response')(loop, t, u, solve_ivp_kwargs=dict(
        method='DOP853', rtol=1e-11, atol=1e-14)).y
    yS = _sim(ltp.series(P, K), t, u)
    np.testing.assert_allclose(yS, ref, rtol=1e-7, atol=1e-9 * np.abs(ref).max())
    # operator order follows python-control: K * P means P first
    np.testing.assert_allclose(_sim(K * P, t, u), yS, rtol=1e-12, atol=1e-15)
    # parallel and negation
    yP = _sim(P, t, u)
    np.testing.assert_allclose(_sim(P + P, t, u), 2 * yP, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(_sim(-P, t, u), -yP, atol=1e-15)
    np.testing.assert_allclose(_sim(P - P, t, u), 0 * yP, atol=1e-12)


def test_feedback_equals_closed_loop_equations():
    P = damped_mathieu()
    k = 3.0
    L = ltp.feedback(P, k)
    # u_P = r - k y  =>  A_cl = A - k B C
    np.testing.assert_allclose(L.A(0.1), P.A(0.1) - k * P.B(0.1) @ P.C(0.1))
    Lp = P.feedback(ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0.5, period=P.period), sign=1)
    assert Lp.nstates == 3
    assert ct.feedback(P, k).nstates == 2       # python-control front end works too


def test_indexing_and_append():
    P = ltp.append(mathieu(), damped_mathieu())
    assert P.shape == (2, 2) and P.nstates == 4
    sub = P[1, 0]
    assert sub.shape == (1, 1)
    np.testing.assert_allclose(sub.C(0.1), [[0, 0, 1, 0]])
    np.testing.assert_allclose(sub.B(0.125), [[0], [1], [0], [0]], atol=1e-15)
    named = P[['y[1]'], ['u[1]']]
    np.testing.assert_allclose(named.B(0.0)[2:], [[0], [1]])


def test_periods_combine_or_fail():
    a = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=0.5)
    b = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.5)
    assert ltp.series(a, b).period == 1.5
    c = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=np.sqrt(2))
    with pytest.raises(ValueError, match="incommensurate"):
        ltp.parallel(a, c)
    d = ltp.ltpss([[0.5]], [[1.0]], [[1.0]], 0, period=1.0, dt=0.1)
    with pytest.raises(ValueError, match="timebase"):
        ltp.series(a, d)


@pytest.mark.parametrize("call, exc, match", [
    (lambda: ltp.ltpss([[1, 2]], [[1]], [[1]], 0, period=1.0), ControlDimension, "A"),
    (lambda: ltp.ltpss([[1.0]], [[1], [2]], [[1]], 0, period=1.0), ControlDimension, "B"),
    (lambda: ltp.ltpss([[1.0]], [[1]], [[1, 2]], 0, period=1.0), ControlDimension, "C"),
    (lambda: ltp.ltpss([[1.0]], [[1]], [[1]], [[1, 2]], period=1.0), ControlDimension, "D"),
    (lambda: ltp.ltpss([[1j]], [[1]], [[1]], 0, period=1.0), ControlArgument, "A"),
    (lambda: ltp.ltpss([[np.inf]], [[1]], [[1]], 0, period=1.0), ValueError, "A"),
    (lambda: ltp.ltpss([[1.0]], [[1]], [[1]], 0, period=0), ValueError, "period"),
    (lambda: ltp.ltpss([[1.0]], [[1]], [[1]], 0, period=-2.0), ValueError, "period"),
    (lambda: ltp.ltpss([[1.0]], [[1]], [[1]], 0, period=1.0, dt=0.3), ValueError, "dt"),
    (lambda: ltp.ltpss([[1.0]], [[1]], [[1]], 0, period=1.0, dt=-0.1), ValueError, "dt"),
    (lambda: ltp.ltpss(lambda t: np.array([[t]]), [[1]], [[1]], 0, period=1.0),
     ValueError, "not periodic"),
    (lambda: ltp.ltpss(ltp.PeriodicMatrix.constant([[1.0]], 0.7), [[1]], [[1]], 0,
                       period=1.0), ValueError, "A has period"),
    (lambda: ltp.ltpss(np.ones((3, 1, 1)), [[1]], [[1]], 0, period=1.0, dt=0.25),
     ControlDimension, "A has 3 matrices"),
    (lambda: ltp.ltpss(np.ones((3, 1, 1)), [[1]], [[1]], 0, period=1.0),
     ControlDimension, "discrete-time"),
    (lambda: ltp.ltpss([[1.0]], [[1]], [[1]], 0, period=1.0, inputs=['a', 'b']),
     ControlDimension, "inputs"),
    (lambda: ltp.ltpss([[1.0]], [[1]], [[1]], 0, period=1.0, color='red'),
     TypeError, "unrecognized"),
    (lambda: ltp.ltpss([[1.0]], [[1]], [[1]], 0), ControlArgument, "ltpss expects"),
    (lambda: ltp.feedback(mathieu(), mathieu(), sign=2), ValueError, "sign"),
    (lambda: ltp.series(ct.tf([1], [1, 1]), ct.tf([1], [1, 2])), ControlArgument,
     "LTPStateSpace"),
    (lambda: ltp.series(mathieu(), ltp.append(mathieu(), mathieu())), ControlDimension,
     "series"),
    (lambda: mathieu()['nope', 0], ValueError, "output name"),
])
def test_bad_input(call, exc, match):
    with pytest.raises(exc, match=match):
        call()


def test_feedback_of_a_system_sampled_at_one_second_with_a_periodic_gain():
    # dt = 1.0 equals True in Python: the timebase must still be taken as 1.0
    A = np.array([[[1.2, 0.3], [0.0, 0.5]], [[0.8, 0.0], [0.4, 1.1]]])
    B = np.array([[[0.0], [1.0]], [[1.0], [0.0]]])
    sysd = ltp.ltpss(A, B, np.eye(2), 0, period=2.0, dt=1.0)
    K = ltp.place(sysd, [0.5, -0.2])
    loop = ltp.feedback(sysd, K)
    assert loop.dt == 1.0
    np.testing.assert_allclose(np.sort_complex(ltp.floquet_multipliers(loop)),
                               np.sort_complex(np.array([-0.2, 0.5], complex)), atol=1e-10)
