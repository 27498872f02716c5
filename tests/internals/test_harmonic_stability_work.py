"""Work done by one call of the harmonic stability functions: every system's
Floquet exponents computed once, and the Floquet check of the gain margins
(``ltpcontrol._frequency.margins._verify``) able to fail.  Truth for the
check: the margins themselves, moved off by 2 % (a crossing missed or
invented) or to another frequency."""

import warnings

import numpy as np
import pytest

import ltpcontrol as ltp
from ltpcontrol._frequency import loop as loop_module
from ltpcontrol._frequency import margins as mg
from ltpcontrol._frequency.loop import LoopHTF

T = 2 * np.pi


def _mathieu_loop():
    # damped Mathieu plant in its first tongue (P = 1) with the stabilizing gain 0.55
    A = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 1.0], [-(0.2 + 0.8 * np.cos(t)), -0.05]]), T)
    return ltp.ltpss(A, [[0.0], [1.0]], [[0.55, 0.0]], 0, period=T, name='mathieu')


@pytest.fixture(scope='module')
def margins():
    L = _mathieu_loop()
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        m = ltp.harmonic_margins(L, 6)
    return L, LoopHTF(L, 6), m


@pytest.fixture
def floquet_calls(monkeypatch):
    calls = []
    orig = loop_module.floquet_exponents

    def counted(sys, nsteps=None):
        calls.append(sys.nstates)
        return orig(sys, nsteps)
    monkeypatch.setattr(loop_module, 'floquet_exponents', counted)
    return calls


def test_nyquist_computes_each_systems_exponents_once(floquet_calls):
    L = _mathieu_loop()
    resp = ltp.nyquist_htf(L, 4)
    assert resp.floquet_unstable == resp.closed_loop_unstable == 0
    assert len(floquet_calls) == 2                   # open loop and closed loop
    floquet_calls.clear()
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        ltp.nyquist_htf(L, 4, check=False)
    assert len(floquet_calls) == 1


def test_margin_check_costs_one_floquet_computation_per_margin(floquet_calls):
    m = ltp.harmonic_margins(_mathieu_loop(), 6)
    finite = sum(0 < g.value < np.inf for g in (m.gain_lower, m.gain_upper))
    assert finite == 2
    assert len(floquet_calls) == 1 + finite          # open loop, then one per margin


def test_true_margins_pass_the_check(margins):
    L, loop, m = margins
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        mg._verify(L, loop, m.gain_upper, m.gain_lower)
    assert not caught, [str(w.message) for w in caught]


@pytest.mark.parametrize('which, change', [
    ('upper', dict(factor=1.02)),      # a crossing below it missed
    ('upper', dict(factor=0.98)),      # no crossing at it
    ('lower', dict(factor=0.98)),
    ('lower', dict(shift=0.3)),        # the crossing at another frequency
])
def test_wrong_margins_fail_the_check(margins, which, change):
    L, loop, m = margins
    up, lo = m.gain_upper, m.gain_lower
    p = up if which == 'upper' else lo
    p = p._replace(value=p.value * change.get('factor', 1.0),
                   omega=p.omega + change.get('shift', 0.0))
    up, lo = (p, lo) if which == 'upper' else (up, p)
    with pytest.warns(UserWarning, match="crossing was missed"):
        mg._verify(L, loop, up, lo)
