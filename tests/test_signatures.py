"""Signatures: options are keyword-only, and no function takes ``**kwargs`` only to reject them.

python-control's own argument order wins where a function mirrors one of
its functions (``balred(sys, orders, method)``, ``place(sys, p)``); every
other option is keyword-only, and a misspelt keyword is refused by Python
itself (``TypeError: ... got an unexpected keyword argument``).
"""

import inspect

import control as ct
import pytest

import ltpcontrol as ltp

#: functions whose ``**kwargs`` mirror a python-control signature that takes
#: them, or are passed on (orbit_continuation: to the orbit solver)
MIRRORS_KWARGS = {'orbit_continuation', 'forced_response', 'step_response', 'initial_response', 'impulse_response',
                  'ltpss', 'series', 'parallel', 'feedback', 'append', 'negate',
                  'interconnect', 'sample_system', 'c2d', 'd2c', 'bode_htf', 'htf_response',
                  'htf_map_plot', 'lqr', 'dlqr', 'lqe', 'dlqe', 'lqg', 'LTPStateSpace'}


def _public_functions():
    return {name: obj for name, obj in vars(ltp).items()
            if name in ltp.__all__ and inspect.isfunction(obj)}


@pytest.mark.parametrize('name', sorted(_public_functions()))
def test_no_reject_only_kwargs(name):
    sig = inspect.signature(_public_functions()[name])
    takes_kwargs = any(p.kind is p.VAR_KEYWORD for p in sig.parameters.values())
    if name not in MIRRORS_KWARGS:
        assert not takes_kwargs, (f"{name} takes **kwargs; make its options explicit "
                                  "keyword-only parameters")


@pytest.mark.parametrize('func, positional', [
    (ltp.lift, {'sysd'}),
    (ltp.place, {'sys', 'p'}),                        # control.place(A, B, p)
    (ltp.lmi_statefbk, {'sysd', 'Q', 'R'}),           # as lqr(sys, Q, R)
    (ltp.balred, {'sys', 'orders', 'method'}),        # control.balred(sys, orders, method, ...)
])
def test_options_are_keyword_only(func, positional):
    params = inspect.signature(func).parameters.values()
    assert {p.name for p in params if p.kind is p.POSITIONAL_OR_KEYWORD} == positional


def test_python_control_order_is_kept_by_balred():
    ours = list(inspect.signature(ltp.balred).parameters)[:3]
    theirs = list(inspect.signature(ct.balred).parameters)[:3]
    assert ours == theirs


def test_a_misspelt_option_is_refused_by_python():
    sysd = ltp.ltpss(0.5, 1.0, 1.0, 0, period=1.0, dt=0.25)
    with pytest.raises(TypeError, match="unexpected keyword argument 'nharmonic'"):
        ltp.lift(sysd, nharmonic=1)
    with pytest.raises(TypeError, match="positional"):
        ltp.lift(sysd, 'time')
    with pytest.raises(TypeError, match="positional"):
        ltp.place(sysd, [0.1], 1)


def test_e_rms_is_one_hundred_times_nrmse():
    # one quantity: e_rms (the thesis's published percentage) is 100 nrmse
    y, y_hat = [1.0, -2.0, 3.0, 0.5], [1.1, -1.7, 2.6, 0.4]
    assert ltp.e_rms(y, y_hat) == pytest.approx(100 * ltp.nrmse(y, y_hat), rel=1e-15)
    assert ltp.nrmse(y, y_hat) == pytest.approx(
        sum((a - b) ** 2 for a, b in zip(y, y_hat)) ** 0.5 / sum(a * a for a in y) ** 0.5)
