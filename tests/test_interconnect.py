"""ltp.interconnect, periodic static gains in block diagrams, common periods."""

import control as ct
import numpy as np
import pytest
from control.exception import ControlArgument
from hypothesis import given, settings, strategies as st
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

T = 1.0
W = 2 * np.pi / T
A0 = np.array([[0.0, 1.0], [-4.0, -0.6]])


def _A(t):
    return A0 + np.array([[0.0, 0.0], [-1.5 * np.cos(W * t), 0.0]])


def _b(t):
    return np.array([[0.0], [1 + 0.4 * np.sin(W * t)]])


CP = np.array([[1.0, 0.0]])
KI, KP = 1.5, 0.8                    # PI controller  v = KP e + KI ∫e
GAIN_PERIOD = 1.5                    # periodic gain  u = g(t) v, g = 1 + 0.5 cos(2πt/1.5)


def _g(t):
    return 1 + 0.5 * np.cos(2 * np.pi * t / GAIN_PERIOD)


def _blocks():
    P = ltp.ltpss(_A, _b, CP, 0, period=T, name='P', inputs='u', outputs='y')
    C = ct.tf([KP, KI], [1.0, 0.0], name='C', inputs='e', outputs='v')
    G = ltp.ltpss(ltp.PeriodicMatrix([[[0.25]], [[1.0]], [[0.25]]], GAIN_PERIOD),
                  name='G', inputs='v', outputs='u')
    return P, C, G


def _loop_by_ode(t, r):
    """The loop e = r - y, v = KP e + KI z, ż = e, u = g v, ẋ = A x + b u, by solve_ivp."""
    def rhs(tau, xz):
        x, z = xz[:2], xz[2]
        e = np.interp(tau, t, r) - CP @ x
        u = _g(tau) * (KP * e + KI * z)
        return np.concatenate([_A(tau) @ x + _b(tau)[:, 0] * u, e])
    sol = solve_ivp(rhs, (t[0], t[-1]), np.zeros(3), t_eval=t, method='DOP853',
                    rtol=1e-12, atol=1e-14)
    return (CP @ sol.y[:2])[0]


def test_three_block_loop_equals_feedback_series_and_ode():
    P, C, G = _blocks()
    err = ct.summing_junction(['r', '-y'], 'e')
    loop = ltp.interconnect([P, C, G, err], inplist='r', outlist='y', inputs='r',
                            outputs='y', name='loop')
    assert isinstance(loop, ltp.LTPStateSpace)
    assert loop.period == pytest.approx(3.0)             # common period of 1 and 1.5
    assert loop.input_labels == ['r'] and loop.output_labels == ['y']
    gain = ltp.PeriodicMatrix.from_function(lambda t: np.array([[_g(t)]]), GAIN_PERIOD)
    by_blocks = ltp.feedback(ltp.series(C, gain, P), 1)
    t = np.linspace(0, 6, 601)
    r = np.ones_like(t)
    y1 = ltp.forced_response(loop, t, r).outputs
    y2 = ltp.forced_response(by_blocks, t, r).outputs
    y3 = _loop_by_ode(t, r)
    np.testing.assert_allclose(y1, y2, atol=1e-8)
    np.testing.assert_allclose(y1, y3, atol=1e-8)
    # python-control's front end gives the same system
    loop_ct = ct.interconnect([P, C, G, err], inplist='r', outlist='y')
    assert isinstance(loop_ct, ltp.LTPStateSpace)
    np.testing.assert_allclose(ltp.forced_response(loop_ct, t, r).outputs, y1, atol=1e-12)


def test_explicit_connections_and_automatic_names_agree():
    P, C, G = _blocks()
    auto = ltp.interconnect([P, C, G, ct.summing_junction(['r', '-y'], 'e')],
                            inplist='r', outlist=['y', 'u'])
    P2 = P.copy('P')
    C2 = ct.tf([KP, KI], [1.0, 0.0], name='C')
    G2 = ltp.ltpss(G.D, name='G')
    explicit = ltp.interconnect(
        [P2, C2, G2], connections=[['C.u[0]', '-P.y'], ['G.u[0]', 'C.y[0]'],
                                   ['P.u', 'G.y[0]']],
        inplist=['C.u[0]'], outlist=['P.y', 'G.y[0]'])
    t = np.linspace(0, 3, 301)
    r = np.sin(2 * t)
    np.testing.assert_allclose(ltp.forced_response(auto, t, r).outputs,
                               ltp.forced_response(explicit, t, r).outputs, atol=1e-10)


def test_lti_blocks_equal_python_control():
    rng = np.random.default_rng(1)
    A = rng.standard_normal((3, 3))
    A -= (np.max(np.linalg.eigvals(A).real) + 1.0) * np.eye(3)
    P = ct.ss(A, rng.standard_normal((3, 1)), rng.standard_normal((1, 3)), 0.0,
              name='P', inputs='u', outputs='y')
    C = ct.tf([2.0, 1.0], [1.0, 4.0], name='C', inputs='e', outputs='u')
    k = float(rng.uniform(0.5, 2.0))
    ref = ct.interconnect([P, C, ct.summing_junction(['r', '-y'], 'e'),
                           ct.ss(ct.tf([k], [1.0]), name='K', inputs='y', outputs='z')],
                          inplist='r', outlist=['y', 'z'])
    K = ltp.ltpss(ltp.PeriodicMatrix.constant([[k]], T), name='K', inputs='y', outputs='z')
    ours = ltp.interconnect([P, C, ct.summing_junction(['r', '-y'], 'e'), K],
                            inplist='r', outlist=['y', 'z'])
    t = np.linspace(0, 5, 501)
    np.testing.assert_allclose(ltp.forced_response(ours, t, np.ones_like(t)).outputs,
                               ct.forced_response(ref, t, np.ones_like(t)).outputs,
                               atol=1e-10)


def test_discrete_time_loop():
    P, C, G = _blocks()
    Pd = P.sample(0.05)
    Cd = ct.c2d(ct.ss(C), 0.05)
    Cd.name = 'C'
    k = ltp.PeriodicMatrix.constant([[0.5]], T)
    loop = ltp.interconnect([Pd, Cd, ltp.ltpss(k, name='G', inputs='v', outputs='u'),
                             ct.summing_junction(['r', '-y'], 'e')],
                            inplist='r', outlist='y')
    ref = ltp.feedback(ltp.series(Cd, k, Pd), 1)
    td = np.arange(100) * 0.05
    np.testing.assert_allclose(ltp.forced_response(loop, td, np.ones(100)).outputs,
                               ltp.forced_response(ref, td, np.ones(100)).outputs, atol=1e-10)
    assert loop.dt == 0.05


def test_feedback_with_periodic_gain_is_pointwise():
    P, _, _ = _blocks()
    K = ltp.PeriodicMatrix.from_function(lambda t: np.array([[2 + np.sin(W * t)]]), T)
    L = ltp.feedback(P, K)
    for tk in (0.1, 0.37, 0.8):
        np.testing.assert_allclose(L.A(tk), _A(tk) - _b(tk) @ K(tk) @ CP, atol=1e-12)
    S = ltp.series(P, K)
    np.testing.assert_allclose(S.C(0.3), K(0.3) @ CP, atol=1e-12)
    Pa = ltp.parallel(P, K)
    np.testing.assert_allclose(Pa.D(0.3), K(0.3), atol=1e-12)


def test_interconnect_errors():
    P, C, G = _blocks()
    with pytest.raises(ControlArgument, match="at least one system must be an LTPStateSpace"):
        ltp.interconnect([ct.ss(C)], inplist='e', outlist='v')
    nl = ct.nlsys(lambda t, x, u, p: -x + u, lambda t, x, u, p: x ** 2, states=1,
                  inputs='y', outputs='w', name='nl')
    with pytest.raises(ControlArgument, match="control.interconnect"):
        ltp.interconnect([P, nl], inplist='u', outlist='w')
    # u = y and y = u through a unit feedthrough: singular algebraic loop
    one = ltp.ltpss(ltp.PeriodicMatrix.constant([[1.0]], T), name='F', inputs='a', outputs='a')
    with pytest.raises(ValueError, match="algebraic loop"):
        ltp.interconnect([one], inplist=[], outlist='a', check_unused=False)
    Q = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=np.sqrt(2), name='Q',
                  inputs='y', outputs='q')
    with pytest.raises(ValueError, match="incommensurate"):
        ltp.interconnect([P, Q], inplist='u', outlist='q')


def _common_period(p, q):
    """The period of a block diagram of two blocks of periods p and q."""
    return ltp.parallel(ltp.PeriodicMatrix.constant([[1.0]], p),
                        ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=q)).period


def test_commensurate_periods():
    assert _common_period(1.0, 1.5) == pytest.approx(3.0)
    assert _common_period(0.5, 1.5) == 1.5
    with pytest.raises(ValueError, match="incommensurate"):
        _common_period(1.0, np.sqrt(2))
    with ltp.config.defaults_context({'period.max_multiple': 2}):
        assert _common_period(1.0, 2.0) == 2.0
        with pytest.raises(ValueError, match="incommensurate periods 2.0 and 3.0"):
            _common_period(2.0, 3.0)
    # series of periods 1 and 1.5 simulates over the common period 3
    a = ltp.ltpss([[-1.0]], lambda t: np.array([[1 + 0.5 * np.cos(W * t)]]), [[1.0]], 0,
                  period=1.0)
    b = ltp.ltpss([[-2.0]], [[1.0]], lambda t: np.array([[1 + np.sin(4 * np.pi * t / 3)]]),
                  0, period=1.5)
    s = ltp.series(a, b)
    assert s.period == pytest.approx(3.0)
    t = np.linspace(0, 4, 401)
    y = ltp.forced_response(s, t, np.ones_like(t)).outputs

    def rhs(tau, x):
        return [-x[0] + (1 + 0.5 * np.cos(W * tau)),
                -2 * x[1] + x[0]]
    sol = solve_ivp(rhs, (0, 4), [0.0, 0.0], t_eval=t, rtol=1e-12, atol=1e-14,
                    method='DOP853')
    np.testing.assert_allclose(y, (1 + np.sin(4 * np.pi * t / 3)) * sol.y[1], atol=1e-8)


@settings(max_examples=40, deadline=None)
@given(p=st.integers(1, 30), q=st.integers(1, 30), tau=st.floats(1e-3, 1e3))
def test_common_period_is_the_least_common_multiple(p, q, tau):
    from math import gcd
    lcm = p * q // gcd(p, q)
    assert _common_period(p * tau, q * tau) == pytest.approx(lcm * tau, rel=1e-12)
