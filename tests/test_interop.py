"""python-control's entry points on LTP systems: the exact ltpcontrol answer
or a clear error naming the ltpcontrol function, never a silently different
result (the policy is stated in docs/guide_interop.rst)."""

import warnings

import control as ct
import numpy as np
import pytest
from control.exception import ControlArgument
from scipy.integrate import solve_ivp

import ltpcontrol as ltp
from ltpcontrol import interop as _interop

T = 1.0


_rng = np.random.default_rng(3)
A0 = _rng.standard_normal((3, 3)) - 2.5 * np.eye(3)
A1 = 0.5 * _rng.standard_normal((3, 3))
B0, C0, D0 = _rng.standard_normal((3, 2)), _rng.standard_normal((2, 3)), [[0.1, 0], [0, 0]]
W = 2 * np.pi / T


def _A(t):
    return A0 + A1 * np.cos(W * t)


def _B(t):
    return B0 * (1 + 0.3 * np.sin(W * t))


def _plant(dt=0.0):
    """MIMO plant with periodic A(t) and B(t) (2 inputs, 2 outputs, 3 states)."""
    sys = ltp.ltpss(_A, _B, C0, D0, period=T, name='plant')
    return sys if not dt else sys.sample(dt)


P = _plant()
t = np.linspace(0, 2, 201)
U = np.vstack([np.sin(3 * t), np.cos(1.7 * t)])


def _ode_reference(t, u, x0):
    """Independent simulation of ẋ = A(t)x + B(t)u, u linear between samples."""
    def rhs(tau, x):
        return _A(tau) @ x + _B(tau) @ np.array([np.interp(tau, t, ui) for ui in u])
    sol = solve_ivp(rhs, (t[0], t[-1]), x0, t_eval=t, method='DOP853', rtol=1e-12,
                    atol=1e-14)
    return C0 @ sol.y + np.asarray(D0) @ u


#
# Time responses: routed to the exact simulation
#

def test_forced_response_is_exact():
    x0 = np.array([1.0, -0.5, 0.2])
    ours = ltp.forced_response(P, t, U, x0)
    theirs = ct.forced_response(P, t, U, x0)
    np.testing.assert_allclose(theirs.outputs, ours.outputs, atol=1e-10)
    np.testing.assert_allclose(theirs.outputs, _ode_reference(t, U, x0), atol=1e-8)
    # python-control's aliases and legacy tuple form
    tt, yy, xx = ct.forced_response(P, T=t, U=U, X0=x0, return_x=True)
    np.testing.assert_allclose(yy, ours.outputs, atol=1e-10)
    np.testing.assert_allclose(xx, ours.states, atol=1e-10)


def test_input_output_response_is_exact():
    x0 = [0.3, 0.0, -1.0]
    ours = ltp.forced_response(P, t, U, x0)
    theirs = ct.input_output_response(P, t, U, x0, solve_ivp_kwargs={'rtol': 1e-3})
    np.testing.assert_allclose(theirs.outputs, ours.outputs, atol=1e-10)
    with pytest.raises(ControlArgument, match="evaluation_times"):
        ct.input_output_response(P, t, U, evaluation_times=t[::2])


@pytest.mark.filterwarnings("ignore:the system has direct feedthrough")
@pytest.mark.parametrize('name, args', [
    ('step_response', (t,)), ('initial_response', (t, [1.0, 0.0, 0.0])),
    ('impulse_response', (t,))])
def test_other_time_responses_are_exact(name, args):
    ours = getattr(ltp, name)(P, *args)
    theirs = getattr(ct, name)(P, *args)
    np.testing.assert_allclose(theirs.outputs, ours.outputs, atol=1e-10)
    assert theirs.time.shape == ours.time.shape


def test_step_response_default_time_and_discrete_systems():
    # python-control could not choose T for a non-LTI system; ltpcontrol can
    r = ct.step_response(P)
    np.testing.assert_allclose(r.outputs, ltp.step_response(P).outputs, atol=1e-10)
    for N in (10, 11):                  # even and odd steps per period
        Pd = _plant(T / N)
        td = np.arange(0, 3 * N) * (T / N)
        ud = np.vstack([np.sin(td), np.ones_like(td)])
        np.testing.assert_allclose(ct.forced_response(Pd, td, ud).outputs,
                                   ltp.forced_response(Pd, td, ud).outputs, atol=1e-10)


def test_lti_written_as_periodic_equals_python_control():
    G = ct.rss(3, 2, 2, strictly_proper=False)
    G = ct.ss(G.A - 0.5 * np.eye(3), G.B, G.C, G.D)
    Gp = ltp.ltpss(G, T)
    for name in ('forced_response',):
        np.testing.assert_allclose(getattr(ct, name)(Gp, t, U).outputs,
                                   getattr(ct, name)(G, t, U).outputs, atol=1e-10)
    np.testing.assert_allclose(ct.step_response(Gp, t).outputs,
                               ct.step_response(G, t).outputs, atol=1e-10)


def test_lists_of_systems_mix_lti_and_ltp():
    G = ct.ss(ct.tf([1.0], [1.0, 1.0]))
    Ps = P[0, 0]
    out = ct.step_response([G, Ps], t)
    assert isinstance(out, ct.TimeResponseList)
    np.testing.assert_allclose(out[0].outputs, ct.step_response(G, t).outputs)
    np.testing.assert_allclose(out[1].outputs, ltp.step_response(Ps, t).outputs, atol=1e-10)


def test_hankel_singular_values_of_lti_written_as_periodic_equal_python_control():
    G = ct.rss(4, 2, 3, strictly_proper=True)
    hsv = ct.hankel_singular_values(ltp.ltpss(G, T))
    assert hsv.shape == (4,)
    np.testing.assert_allclose(hsv, ct.hankel_singular_values(G), rtol=1e-9)


def test_time_response_arguments_without_meaning_are_refused():
    with pytest.raises(ControlArgument, match="params"):
        ct.forced_response(P, t, U, params={'a': 1})
    with pytest.raises(ControlArgument, match="interpolate"):
        ct.forced_response(P, t, U, interpolate=True)


#
# Methods python-control calls
#

def test_sample_system_poles_and_linearize():
    for method in ('zoh', 'tustin'):
        a, b = ct.c2d(P, 0.05, method), ltp.sample_system(P, 0.05, method)
        for M in ('A', 'B', 'C', 'D'):
            np.testing.assert_allclose(getattr(a, M).sample(20), getattr(b, M).sample(20),
                                       atol=1e-10)
    np.testing.assert_allclose(ct.poles(P), ltp.floquet_exponents(P), atol=1e-10)
    lin = ct.linearize(P, np.zeros(3), np.zeros(2), t=0.3)
    np.testing.assert_allclose(lin.A, P.A(0.3), atol=1e-12)
    np.testing.assert_allclose(lin.B, P.B(0.3), atol=1e-12)
    with pytest.raises(ValueError, match="x0"):
        ct.linearize(P, np.zeros(5), 0)


def test_evaluation_is_refused():
    with pytest.raises(ControlArgument, match=r"ltp\.htf"):
        P(1j)


#
# Block diagrams: LTP results whichever operand comes first
#

def test_block_diagram_functions_return_ltp_systems():
    K = ct.ss(ct.tf([2.0], [1.0, 3.0]))
    Ps = P[0, 0]
    for got, want in ((ct.feedback(K, Ps), ltp.feedback(K, Ps)),
                      (ct.series(K, Ps, K), ltp.series(ltp.series(K, Ps), K)),
                      (ct.parallel(K, Ps, Ps), ltp.parallel(ltp.parallel(K, Ps), Ps)),
                      (ct.append(K, Ps), ltp.append(K, Ps))):
        assert isinstance(got, ltp.LTPStateSpace)
        tt = np.linspace(0, 2, 201)
        u = np.ones((got.ninputs, tt.size))
        np.testing.assert_allclose(ltp.forced_response(got, tt, u).outputs,
                                   ltp.forced_response(want, tt, u).outputs, atol=1e-10)


def test_nonlinear_blocks_keep_python_control_behaviour():
    nl = ct.nlsys(lambda t, x, u, p: -x + u ** 3, lambda t, x, u, p: x, states=1,
                  inputs=1, outputs=1)
    assert not isinstance(ct.series(P[0, 0], nl), ltp.LTPStateSpace)


#
# Analysis and synthesis: same-named ltpcontrol function, or a clear error
#

HOOK_CALLS = {
    'zeros': lambda m: m.zeros(P),
    'norm': lambda m: m.norm(P[1, 1], 2),
    'lqr': lambda m: m.lqr(P, np.eye(3), np.eye(2)),
    'lqe': lambda m: m.lqe(P, np.eye(2), np.eye(2)),
    'gram': lambda m: m.gram(P, 'c'),
    'lyap': lambda m: m.lyap(P, np.eye(3)),
    'minreal': lambda m: m.minreal(P),
    'hsvd': lambda m: (m.hsvd if m is ltp else m.hankel_singular_values)(P),
    'balred': lambda m: (m.balred if m is ltp else m.balanced_reduction)(P, 2),
}


@pytest.mark.parametrize('name', sorted(HOOK_CALLS))
def test_analysis_entry_points_dispatch_or_name_the_ltp_function(name):
    call = HOOK_CALLS[name]
    if getattr(ltp, name, None) is None:
        with pytest.raises(ControlArgument, match=rf"ltp\.{name}\b"):
            call(ct)
        return
    try:
        ours = call(ltp)
    except Exception as exc:            # the same refusal through python-control's name
        with pytest.raises(type(exc)):
            call(ct)
        return
    _assert_same(call(ct), ours)


def _assert_same(got, want):
    if isinstance(want, (tuple, list)):
        assert len(got) == len(want)
        for g, w in zip(got, want):
            _assert_same(g, w)
        return
    if isinstance(want, ltp.LTPStateSpace):
        _assert_same([got.A, got.B, got.C, got.D], [want.A, want.B, want.C, want.D])
        return
    if isinstance(want, ltp.PeriodicMatrix):
        tk = np.linspace(0, want.period, 7, endpoint=False)
        got, want = got(tk), want(tk)
    np.testing.assert_allclose(np.asarray(got, complex), np.asarray(want, complex), atol=1e-10)


REFUSED_CALLS = {
    'bode_plot': lambda: ct.bode_plot(P),
    'nyquist_plot': lambda: ct.nyquist_plot(P[0, 0]),
    'nyquist_response': lambda: ct.nyquist_response(P[0, 0]),
    'nichols_plot': lambda: ct.nichols_plot(P[0, 0]),
    'singular_values_plot': lambda: ct.singular_values_plot(P),
    'margin': lambda: ct.margin(P[0, 0]),
    'stability_margins': lambda: ct.stability_margins(P[0, 0]),
    'disk_margins': lambda: ct.disk_margins(P[0, 0], [1.0]),
    'bandwidth': lambda: ct.bandwidth(P[0, 0]),
    'damp': lambda: ct.damp(P),
    'root_locus_map': lambda: ct.root_locus_map(P[0, 0]),
    'root_locus_plot': lambda: ct.root_locus_plot(P[0, 0]),
    'step_info': lambda: ct.step_info(P),
    'similarity_transform': lambda: ct.similarity_transform(P, np.eye(3)),
    'canonical_form': lambda: ct.canonical_form(P),
    'reachable_form': lambda: ct.reachable_form(P[0, 0]),
    'observable_form': lambda: ct.observable_form(P[0, 0]),
    'modal_form': lambda: ct.modal_form(P),
    'ss': lambda: ct.ss(P),
    'tf': lambda: ct.tf(P),
    'ss2tf': lambda: ct.ss2tf(P),
    'tf2ss': lambda: ct.tf2ss(P),
    'mixsyn': lambda: ct.mixsyn(P),
    'h2syn': lambda: ct.h2syn(P, 1, 1),
    'hinfsyn': lambda: ct.hinfsyn(P, 1, 1),
    'augw': lambda: ct.augw(P),
    'find_operating_point': lambda: ct.find_operating_point(P, np.zeros(3)),
    'create_statefbk_iosystem': lambda: ct.create_statefbk_iosystem(P, np.ones((2, 3))),
    'create_estimator_iosystem': lambda: ct.create_estimator_iosystem(P, np.eye(2),
                                                                      np.eye(2)),
    'describing_function_response': lambda: ct.describing_function_response(
        P[0, 0], ct.saturation_nonlinearity(1), [1.0]),
    'lyap': lambda: ct.lyap(P, np.eye(3)),
    'dlyap': lambda: ct.dlyap(P, np.eye(3)),
    'care': lambda: ct.care(P, np.eye(3), np.eye(3)),
    'dare': lambda: ct.dare(P, np.eye(3), np.eye(3), np.eye(2)),
    'ctrb': lambda: ct.ctrb(P, np.eye(3)),
    'pole_zero_plot': lambda: ct.pole_zero_plot(P),
    'phase_crossover_frequencies': lambda: ct.phase_crossover_frequencies(P[0, 0]),
    'phase_plane_plot': lambda: ct.phase_plane_plot(P[:2, :2]),
    'phase_plot': lambda: ct.phase_plot(P),
    'frd': lambda: ct.frd(P, [1.0]),
    'ssdata': lambda: ct.ssdata(P),
    'disk_margins': lambda: ct.disk_margins(P[0, 0], [1.0]),
    'nlsys': lambda: ct.nlsys(P),
    'tfdata': lambda: ct.tfdata(P),
    'split_tf': lambda: ct.split_tf(P),
    'bdschur': lambda: ct.bdschur(P),
    'model_reduction': lambda: ct.model_reduction(P, [0]),
    'ispassive': lambda: ct.ispassive(P),
    'solve_passivity_LMI': lambda: ct.solve_passivity_LMI(P),
    'get_input_ff_index': lambda: ct.get_input_ff_index(P),
    'get_output_fb_index': lambda: ct.get_output_fb_index(P),
    'obsv': lambda: ct.obsv(P, np.eye(3)),
}


def test_every_refused_entry_point_is_tested():
    assert set(REFUSED_CALLS) == set(_interop._REFUSED_SYS)


def test_every_refusal_text_is_used():
    used = (set(_interop._REFUSED_SYS) | set(_interop._MATRIX_REFUSED)
            | {'frequency_response', 'dcgain', 'evaluation'})    # methods of the system
    assert set(_interop.REFUSALS) == used


@pytest.mark.parametrize('name', sorted(REFUSED_CALLS))
def test_refused_entry_points_name_the_ltp_way(name):
    with pytest.raises(ControlArgument, match=rf"^{name} does not apply.*: use \S"):
        REFUSED_CALLS[name]()


@pytest.mark.parametrize('name, target', [('nyquist_plot', 'nyquist_htf'),
                                          ('nyquist_response', 'nyquist_htf'),
                                          ('margin', 'stability_margins'),
                                          ('stability_margins', 'harmonic_margins'),
                                          ('disk_margins', 'harmonic_margins')])
def test_loop_refusals_name_the_harmonic_stability_functions(name, target):
    with pytest.raises(ControlArgument, match=rf"ltp\.{target}\(L"):
        REFUSED_CALLS[name]()
    assert callable(getattr(ltp, target))


def test_aliases_are_refused_under_their_function_name():
    with pytest.raises(ControlArgument, match="find_operating_point does not apply"):
        ct.find_eqpt(P, np.zeros(3))


def test_periodic_matrices_are_refused_by_matrix_functions():
    A = ltp.PeriodicMatrix([[[0.25]], [[-1.0]], [[0.25]]], T)
    for call in (lambda: ct.lyap(A, np.eye(1)), lambda: ct.care(A, [[1.0]], [[1.0]]),
                 lambda: ct.ctrb(A, [[1.0]]),
                 lambda: ct.create_statefbk_iosystem(ct.ss(-1, 1, 1, 0), A)):
        with pytest.raises(ControlArgument, match=r"PeriodicMatrix\): use ltp\."):
            call()


def test_methods_python_control_calls_give_the_same_errors():
    for name in ('frequency_response', 'dcgain'):
        with pytest.raises(ControlArgument, match=rf"^{name} does not apply.*ltp\.htf"):
            getattr(P, name)()


def test_bode_alias_and_lti_calls_untouched():
    with pytest.raises(ControlArgument, match="bode_htf"):
        ct.bode(P)
    G = ct.tf([1.0], [1.0, 1.0])
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        np.testing.assert_allclose(ct.dcgain(G), 1.0)
        resp = ct.frequency_response(G, [1.0])
    np.testing.assert_allclose(resp.frdata[0, 0, 0], 1 / (1j + 1))


def test_every_bridged_entry_point_exists_and_is_wrapped():
    for name in _interop.BRIDGED:
        fn = getattr(ct, name)
        assert fn.__wrapped__ is _interop.original(fn._ltp_bridge)   # aliases share one
    # the defining module holds the same dispatcher (internal calls see it)
    import control.timeresp
    assert control.timeresp.forced_response is ct.forced_response
    _interop.enable()                                   # idempotent
    assert not hasattr(ct.forced_response.__wrapped__, '_ltp_bridge')


def test_footprint_is_narrow():
    # only entry points python-control cannot reach through the system's methods
    reached_by_methods = {'series', 'parallel', 'negate', 'zeros', 'poles', 'dcgain',
                          'evalfr', 'frequency_response', 'sample_system', 'c2d',
                          'linearize', 'singular_values_response', 'pole_zero_map'}
    assert not reached_by_methods & set(_interop.BRIDGED)


def _control_attributes():
    import sys
    return {(n, a): v for n, m in list(sys.modules.items())
            if m is not None and (n == 'control' or n.startswith('control.'))
            for a, v in vars(m).items() if callable(v)}


def test_disable_restores_python_control_and_enable_reinstalls():
    before = _control_attributes()
    with _interop.disable():
        assert not _interop.is_enabled()
        now = _control_attributes()
        bridged = {k for k, v in before.items() if hasattr(v, '_ltp_bridge')}
        assert bridged and all(not hasattr(now[k], '_ltp_bridge') for k in bridged)
        assert all(now[k] is before[k] for k in before if k not in bridged)
        assert all(now[k] is _interop.original(before[k]._ltp_bridge) for k in bridged)
        # python-control alone: its ODE solver, with a warning saying so
        with pytest.warns(UserWarning, match="not by ltpcontrol's exact simulation"):
            ct.forced_response(P, t, U)
    assert _interop.is_enabled()
    assert all(_control_attributes()[k] is v for k, v in before.items())


def test_config_switch_turns_dispatchers_into_pass_throughs():
    with ltp.config.defaults_context({'interop.enabled': False}):
        assert not _interop.is_enabled()
        with pytest.raises(TypeError, match="Can't convert"):
            ct.append(ct.ss(-1, 1, 1, 0), P)             # python-control's own error
    np.testing.assert_allclose(ct.append(ct.ss(-1, 1, 1, 0), P).nstates, 4)


def test_enable_inside_disabled_block_restores_disabled_state():
    with _interop.disable():
        with _interop.enable():
            assert _interop.is_enabled()
        assert not _interop.is_enabled()
    assert _interop.is_enabled()


def test_exact_simulation_does_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        resp = ct.forced_response(P, t, U)
    np.testing.assert_array_equal(resp.outputs, ltp.forced_response(P, t, U).outputs)
