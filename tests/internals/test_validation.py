"""The shared input checks of ``_core/validation.py`` and ``_core/coerce.py``: one per concept.

Tests of internals: they import private names (see the Developer notes).
"""

import control as ct
import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp
from ltpcontrol._core.coerce import as_ltp
from ltpcontrol._core.validation import TIME_RTOL, check_period, check_positive, time_record

SYS = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)


def test_as_ltp_returns_the_system_itself():
    assert as_ltp(SYS) is SYS


def test_as_ltp_converts_lti_given_a_period():
    lti = ct.ss([[-2.0]], [[1.0]], [[3.0]], [[0.5]])
    sys = as_ltp(lti, period=0.5)
    assert sys.period == 0.5
    for key in 'ABCD':
        np.testing.assert_array_equal(getattr(sys, key)(0.3), getattr(lti, key))


@pytest.mark.parametrize('arg, kw, exc, match', [
    (ct.tf([1], [1, 1]), {}, ControlArgument, 'sys must be an LTPStateSpace; it is an LTI system'),
    ('plant', {}, ControlArgument, 'sys must be an LTPStateSpace, got str'),
    (SYS, {'period': 1.0}, TypeError, 'do not pass period'),
    (SYS, {'discrete': True}, ValueError, 'discrete-time'),
    (ct.ss(-1, 1, 1, 0), {'period': -1.0}, ValueError, 'period'),
])
def test_as_ltp_errors_name_the_argument(arg, kw, exc, match):
    with pytest.raises(exc, match=match):
        as_ltp(arg, **kw)


def test_as_ltp_uses_the_argument_name():
    with pytest.raises(ValueError, match='sysd must be a discrete-time system'):
        as_ltp(SYS, 'sysd', discrete=True)
    sysd = ltp.sample_system(SYS, 0.25)
    assert as_ltp(sysd, 'sysd', discrete=True) is sysd


def test_check_positive_and_period():
    assert check_positive(np.float32(0.5), 'dt') == 0.5
    assert check_period(3) == 3.0
    for bad, exc in [(True, ControlArgument), ('1', ControlArgument), (0.0, ValueError),
                     (np.inf, ValueError), (-1, ValueError)]:
        with pytest.raises(exc, match='dt'):
            check_positive(bad, 'dt')
    with pytest.raises(ValueError, match=r'rtol must lie in \(0, 1\)'):
        check_positive(1.0, 'rtol', below=1)


def test_time_record_one_tolerance():
    t = 1e3 + np.arange(101) * 1e-3
    jitter = np.zeros_like(t)
    jitter[50] = 0.5 * TIME_RTOL * 1e-3
    t_out, dt, (u, y) = time_record(t + jitter, {'u': np.ones(101), 'y': np.ones((2, 101))})
    assert np.isclose(dt, 1e-3) and u.shape == (1, 101) and y.shape == (2, 101)
    jitter[50] = 2 * TIME_RTOL * 1e-3
    with pytest.raises(ValueError, match='uniformly spaced'):
        time_record(t + jitter, {'u': np.ones(101)})


def test_time_record_shapes_and_length():
    with pytest.raises(ControlDimension, match='x has 3 samples but t has 4'):
        time_record(np.arange(4.0), {'x': np.ones(3)})
    with pytest.raises(ValueError, match='at least 3 samples'):
        time_record([0.0, 1.0], {'x': [1.0, 2.0]}, min_samples=3)
    with pytest.raises(ValueError, match='uniformly spaced'):
        time_record([0.0, -1.0, -2.0], {'x': [1.0, 2.0, 3.0]})
