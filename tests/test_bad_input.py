"""Catalogue of malformed calls across the public API.

Every entry is a call that a user could plausibly get wrong: wrong shapes and
dimensions, wrong types, complex data where real data are required, NaN/inf,
non-positive or incommensurate periods, non-periodic callables, sampling
times that do not divide the period, too little data for the requested
order, unknown keywords, and so on.  Each must raise one of the documented
exceptions (python-control's `ControlDimension` (a ValueError) and
`ControlArgument` (a TypeError), or `ValueError`, `TypeError`,
`numpy.linalg.LinAlgError`) with a message naming the offending argument.
No bare `IndexError`/`KeyError`, numpy broadcast error or NaN-valued result
may escape instead.

A second, shorter table lists inputs that are accepted but deserve a
`UserWarning` (unstable systems where the HTF has no steady-state meaning,
excitation frequencies at multiples of ω_p/2).
"""

import re
import warnings

import control as ct
import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp

# exception types a malformed call may raise
_DOCUMENTED = (ValueError, TypeError, np.linalg.LinAlgError)
# ... and those that must never escape to the user
_FORBIDDEN = (IndexError, KeyError, AttributeError, ZeroDivisionError)


def check_raises(func, exc, match):
    """Call `func` and check it raises `exc` with a message matching `match`."""
    try:
        result = func()
    except Exception as err:        # noqa: BLE001 -- we inspect the type below
        text = f"{type(err).__name__}: {err}"
        assert not isinstance(err, _FORBIDDEN), f"bare {text} escaped"
        assert "could not be broadcast" not in str(err), f"broadcast error escaped: {text}"
        assert isinstance(err, _DOCUMENTED), f"undocumented exception {text}"
        assert isinstance(err, exc), f"expected {exc.__name__}, got {text}"
        assert re.search(match, str(err)), f"message does not name {match!r}: {text}"
        return err
    values = np.asarray(result, dtype=object) if not isinstance(result, np.ndarray) else result
    has_nan = values.dtype.kind in 'fc' and not np.all(np.isfinite(values))
    pytest.fail(f"no exception raised; returned {'a NaN result ' if has_nan else ''}"
                f"{type(result).__name__}")


#
# Well-formed objects the malformed calls start from
#

T = 1.0
BP = ltp.PeriodicMatrix([[[0.25]], [[1.0]], [[0.25]]], T)
SYS = ltp.ltpss([[-1.0]], BP, [[1.0]], 0, period=T, name='plant')
SYS2 = ltp.ltpss([[-1.0, 0.0], [0.0, -2.0]], np.eye(2), np.eye(2), 0, period=T)
SYSD = SYS.sample(0.1)                                  # N = 10 steps per period
SYSD_FLIP = ltp.ltpss(np.array([[[-0.5]], [[0.5]]]), [[1.0]], [[1.0]], 0,
                      period=T, dt=0.5)                 # multiplier -0.25
SYSD_SINGULAR = ltp.ltpss(np.array([[[0.0]], [[0.5]]]), [[1.0]], [[1.0]], 0,
                          period=T, dt=0.5)
SYSD_MINUS_ONE = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=T, dt=0.5)
SYS_D1 = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 1.0, period=T)
SYS_OTHER_PERIOD = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=np.sqrt(2))
H = ltp.htf(SYS, 1)
with warnings.catch_warnings():
    warnings.simplefilter('ignore')
    H_POLE = ltp.htf(ltp.ltpss([[0.0]], [[1.0]], [[1.0]], 0, period=T), 1)  # pole at s=0
OMEGA = np.linspace(0.5, 10.0, 20)
G_DATA = np.zeros((3, 1, 1, OMEGA.size), complex)
G_DATA[1, 0, 0] = 1 / (1j * OMEGA + 1)
G_DATA[0, 0, 0] = G_DATA[2, 0, 0] = 0.1 / (1j * OMEGA + 2)
H_DATA = ltp.HTFData(G_DATA, OMEGA, T, name='data')


def _pm(coeffs, period=T):
    return ltp.PeriodicMatrix(coeffs, period)


def _model(p, w):
    return np.broadcast_to((p[0] / (1j * w + 1)), (3, 1, 1, w.size)).copy()


# hybrid plants: a bouncing ball and a smooth forced system
AIR = ltp.HybridMode(lambda t, x, u, p: [x[1], -9.81], guard=lambda t, x, u, p: x[0],
                     reset=lambda t, x, u, p: [x[0], -0.8 * x[1]], target=0, name='air')
BALL = ltp.HybridPlant([AIR], states=['h', 'v'])
FREE = ltp.HybridMode(lambda t, x, u, p: -np.asarray(x), name='free')
FORCED = ct.nlsys(lambda t, x, u, p: -x + np.cos(2 * np.pi * t) + u, None,
                  states=1, inputs=1, name='forced')
DRIFTING = ct.nlsys(lambda t, x, u, p: -x + t, None, states=1, inputs=1)
FORCED_NO_INPUT = ct.nlsys(lambda t, x, u, p: -x + np.cos(2 * np.pi * t), None,
                           states=1, inputs=0)
ORBIT = ltp.periodic_orbit(FORCED, T, [0.0], npoints=16)
ORBIT_NO_INPUT = ltp.periodic_orbit(FORCED_NO_INPUT, T, [0.0], npoints=16)

# identification data: a memoryless periodic gain driven by chirp replicas
EXC = ltp.chirp_replicas(T, 3, 4.0, 0.1, 10.0, dt=0.02)
Y_EXC = (1 + np.cos(2 * np.pi * EXC.time / T)) * EXC.inputs
DATA = (EXC.time, EXC.inputs, Y_EXC)
FRD = ct.frd(ct.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], 0.1), np.linspace(0.1, 3, 20))
W_FD = np.logspace(-1, 1, 12)
G_FD = 1 / (1j * W_FD + 1)

# full-state records for hybrid_ls: one period of a sine at 1 kHz
T_LS = np.arange(1000) * 1e-3
X_LS = np.sin(2 * np.pi * 3 * T_LS)
U_LS = np.cos(2 * np.pi * 3 * T_LS)

_NAN = float('nan')


def _call(func, *args, **kwargs):
    """Deferred call, so that the catalogue reads like the user's code."""
    return lambda: func(*args, **kwargs)


CD, CA, VE, TE = ControlDimension, ControlArgument, ValueError, TypeError

CATALOGUE = [
    # -- PeriodicMatrix and its constructors ---------------------------------
    ('pm-even-harmonics', _call(_pm, np.ones((2, 1, 1))), VE, 'coeffs'),
    ('pm-not-conjugate-symmetric', _call(_pm, [[[1j]], [[1.0]], [[1j]]]), VE,
     'coeffs must be conjugate-symmetric'),
    ('pm-coeffs-4d', _call(_pm, np.ones((3, 1, 1, 1))), CD, 'coeffs'),
    ('pm-coeffs-nan', _call(_pm, [[[_NAN]]]), VE, 'coeffs'),
    ('pm-coeffs-str', _call(_pm, 'abc'), CA, 'coeffs'),
    ('pm-coeffs-ragged', _call(_pm, [[[1.0]], [[1.0, 2.0]]]), CA, 'coeffs'),
    ('pm-period-zero', _call(_pm, [[[1.0]]], 0.0), VE, 'period'),
    ('pm-period-negative', _call(_pm, [[[1.0]]], -1.0), VE, 'period'),
    ('pm-period-inf', _call(_pm, [[[1.0]]], np.inf), VE, 'period'),
    ('pm-period-nan', _call(_pm, [[[1.0]]], _NAN), VE, 'period'),
    ('pm-period-str', _call(_pm, [[[1.0]]], '1'), CA, 'period'),
    ('pm-period-complex', _call(_pm, [[[1.0]]], 1j), CA, 'period'),
    ('pm-period-bool', _call(_pm, [[[1.0]]], True), CA, 'period'),
    ('constant-complex', _call(ltp.PeriodicMatrix.constant, [[1j]], T), CA, 'M must be real'),
    ('constant-3d', _call(ltp.PeriodicMatrix.constant, np.ones((2, 2, 2)), T), CD, 'M'),
    ('constant-inf', _call(ltp.PeriodicMatrix.constant, [[np.inf]], T), VE, 'M'),
    ('from-function-not-callable', _call(ltp.PeriodicMatrix.from_function, [[1.0]], T),
     TE, 'func'),
    ('from-function-not-periodic',
     _call(ltp.PeriodicMatrix.from_function, lambda t: np.array([[t]]), T), VE,
     'func is not periodic'),
    ('from-function-wrong-period',
     _call(ltp.PeriodicMatrix.from_function, lambda t: np.array([[np.cos(t)]]), 1.0), VE,
     'func is not periodic'),
    ('from-function-shape',
     _call(ltp.PeriodicMatrix.from_function, lambda t: np.eye(2), T, shape=(3, 3)), VE,
     'func returns shape'),
    ('from-function-complex',
     _call(ltp.PeriodicMatrix.from_function,
           lambda t: np.array([[np.exp(2j * np.pi * t)]]), T), CA, 'func'),
    ('from-samples-4d', _call(ltp.PeriodicMatrix.from_samples, np.ones((4, 1, 1, 1)), T),
     CD, 'samples'),
    ('from-samples-kind', _call(ltp.PeriodicMatrix.from_samples, np.ones(4), T, kind='zoh'),
     VE, 'kind'),
    ('from-samples-nan', _call(ltp.PeriodicMatrix.from_samples, [1.0, _NAN], T), VE,
     'samples'),
    ('from-samples-empty', _call(ltp.PeriodicMatrix.from_samples, np.zeros((0, 1, 1)), T),
     VE, 'samples'),
    ('switching-times-not-from-zero',
     _call(ltp.PeriodicMatrix.switching, [[[1.0]], [[0.0]]], [0.1, 0.5], T), VE, 'times'),
    ('switching-length-mismatch',
     _call(ltp.PeriodicMatrix.switching, [[[1.0]], [[0.0]]], [0.0], T), VE, 'pieces'),
    ('switching-times-decreasing',
     _call(ltp.PeriodicMatrix.switching, [[[1.0]], [[0.0]], [[2.0]]], [0.0, 0.6, 0.3], T),
     VE, 'times'),
    ('switching-time-beyond-period',
     _call(ltp.PeriodicMatrix.switching, [[[1.0]], [[0.0]]], [0.0, 1.5], T), VE, 'times'),
    ('switching-piece-shapes',
     _call(ltp.PeriodicMatrix.switching, [[[1.0]], np.eye(2)], [0.0, 0.5], T), VE,
     r'pieces\[1\]'),
    ('switching-pieces-not-a-sequence', _call(ltp.PeriodicMatrix.switching, 3, [0.0], T), TE,
     'pieces'),
    ('switching-piece-period-not-dividing',
     _call(ltp.PeriodicMatrix.switching, [_pm([[[0.5]], [[0.0]], [[0.5]]], 2.0), [[0.0]]],
           [0.0, 0.5], T), VE, 'period'),
    ('block-ragged-rows', _call(ltp.PeriodicMatrix.block, [[BP, np.zeros((2, 2))]]), VE,
     'rows|block'),
    ('fourier-negative', _call(BP.fourier, -1), VE, 'nharmonics'),
    ('fourier-float', _call(BP.fourier, 1.5), CA, 'nharmonics'),
    ('sample-zero', _call(BP.sample, 0), VE, 'nsamples'),
    ('with-period-not-multiple', _call(BP.with_period, 1.5), VE, 'period'),
    ('pm-add-incommensurate', lambda: BP + _pm([[[1.0]]], np.sqrt(2)), VE, 'commensurate'),
    ('pm-add-shapes', lambda: BP + np.ones((2, 2)), VE, 'shapes'),
    ('pm-matmul-shapes', lambda: BP @ np.ones((2, 2)), VE, 'shapes'),
    ('pm-call-nan', lambda: BP(_NAN), VE, 't'),

    # -- ltpss / LTPStateSpace ------------------------------------------------
    ('ltpss-A-not-square', _call(ltp.ltpss, np.ones((2, 3)), np.ones((2, 1)),
                                 np.ones((1, 2)), 0, period=T), CD, 'A must be square'),
    ('ltpss-B-rows', _call(ltp.ltpss, [[-1.0]], np.ones((2, 1)), [[1.0]], 0, period=T),
     CD, 'B must have 1 rows'),
    ('ltpss-C-cols', _call(ltp.ltpss, [[-1.0]], [[1.0]], [[1.0, 2.0]], 0, period=T),
     CD, 'C must have 1 columns'),
    ('ltpss-D-shape', _call(ltp.ltpss, [[-1.0]], [[1.0]], [[1.0]], np.ones((2, 2)),
                            period=T), CD, 'D must have'),
    ('ltpss-A-complex', _call(ltp.ltpss, [[-1.0 + 1j]], [[1.0]], [[1.0]], 0, period=T),
     CA, 'A must be real'),
    ('ltpss-B-nan', _call(ltp.ltpss, [[-1.0]], [[_NAN]], [[1.0]], 0, period=T),
     VE, 'B contains NaN'),
    ('ltpss-C-str', _call(ltp.ltpss, [[-1.0]], [[1.0]], 'c', 0, period=T), CA, 'C'),
    ('ltpss-period-zero', _call(ltp.ltpss, [[-1.0]], [[1.0]], [[1.0]], 0, period=0),
     VE, 'period'),
    ('ltpss-period-negative', _call(ltp.ltpss, [[-1.0]], [[1.0]], [[1.0]], 0, period=-2.0),
     VE, 'period'),
    ('ltpss-period-str', _call(ltp.ltpss, [[-1.0]], [[1.0]], [[1.0]], 0, period='T'),
     CA, 'period'),
    ('ltpss-dt-not-dividing', _call(ltp.ltpss, [[0.5]], [[1.0]], [[1.0]], 0, period=T,
                                    dt=0.3), VE, 'dt'),
    ('ltpss-dt-negative', _call(ltp.ltpss, [[0.5]], [[1.0]], [[1.0]], 0, period=T,
                                dt=-0.1), VE, 'dt'),
    ('ltpss-dt-str', _call(ltp.ltpss, [[0.5]], [[1.0]], [[1.0]], 0, period=T, dt='x'),
     VE, 'dt'),
    ('ltpss-callable-not-periodic',
     _call(ltp.ltpss, lambda t: np.array([[-1.0 - t]]), [[1.0]], [[1.0]], 0, period=T),
     VE, r'\bA\b'),
    ('ltpss-callable-complex',
     _call(ltp.ltpss, [[-1.0]], lambda t: np.array([[1j]]), [[1.0]], 0, period=T), CA, r'\bB\b'),
    ('ltpss-matrix-incommensurate-period',
     _call(ltp.ltpss, [[-1.0]], _pm([[[0.1]], [[1.0]], [[0.1]]], np.sqrt(2)), [[1.0]], 0,
           period=T), VE, 'B has period'),
    ('ltpss-3d-continuous', _call(ltp.ltpss, np.ones((2, 1, 1)), [[1.0]], [[1.0]], 0,
                                  period=T), CD, 'A: a 3D array'),
    ('ltpss-3d-wrong-count', _call(ltp.ltpss, np.ones((3, 1, 1)), [[1.0]], [[1.0]], 0,
                                   period=T, dt=0.5), CD, 'A has 3 matrices'),
    ('ltpss-positional-count', _call(ltp.ltpss, [[-1.0]], [[1.0]], [[1.0]]), CA,
     'ltpss expects'),
    ('ltpss-unknown-keyword', _call(ltp.ltpss, [[-1.0]], [[1.0]], [[1.0]], 0, period=T,
                                    perod=2.0), TE, 'perod'),
    ('ltpss-label-count', _call(ltp.ltpss, [[-1.0]], [[1.0]], [[1.0]], 0, period=T,
                                inputs=['a', 'b']), CD, 'inputs'),
    ('ltpss-from-lti-period', _call(ltp.ltpss, ct.rss(2, 1, 1), -1.0), VE, 'period'),
    ('ltp-getitem-unknown-name', lambda: SYS2['nope', :], VE, 'output name'),
    ('ltp-getitem-out-of-range', lambda: SYS2[5, 0], VE, 'output index'),
    ('ltp-getitem-single-index', lambda: SYS2[0], TE, 'ind'),

    # -- interconnections -----------------------------------------------------
    ('series-dimensions', _call(ltp.series, SYS, SYS2), CD, 'series'),
    ('series-no-ltp', _call(ltp.series, ct.tf([1], [1, 1]), ct.tf([1], [1, 2])), CA,
     'LTPStateSpace'),
    ('series-incommensurate', _call(ltp.series, SYS, SYS_OTHER_PERIOD), VE,
     'incommensurate'),
    ('series-timebase', _call(ltp.series, SYS, SYSD), VE, 'timebases'),
    ('series-nonlinear', _call(ltp.series, SYS, FORCED), CA, 'NonlinearIOSystem'),
    ('series-complex-gain', _call(ltp.series, SYS, 1j), CA, 'gain'),
    ('series-unknown-keyword', _call(ltp.series, SYS, SYS, nmae='x'), TE, 'nmae'),
    ('parallel-shapes', _call(ltp.parallel, SYS, SYS2), CD, 'parallel'),
    ('parallel-lti-timebase', _call(ltp.parallel, SYS, ct.ss([[0.5]], [[1]], [[1]], 0, 0.1)),
     VE, 'timebases'),
    ('feedback-sign', _call(ltp.feedback, SYS, 1, sign=0), VE, 'sign'),
    ('feedback-dimensions', _call(ltp.feedback, SYS, SYS2), CD, 'feedback'),
    ('feedback-algebraic-loop', _call(ltp.feedback, SYS_D1, -1.0), VE, 'algebraic loop'),
    ('append-empty', _call(ltp.append), VE, 'at least one'),
    ('append-no-ltp', _call(ltp.append, ct.tf([1], [1, 1])), CA, 'LTPStateSpace'),
    ('append-incommensurate', _call(ltp.append, SYS, SYS_OTHER_PERIOD), VE,
     'incommensurate'),
    ('negate-lti', _call(ltp.negate, ct.rss(1, 1, 1)), CA, 'sys must be an LTPStateSpace'),
    ('negate-unknown-keyword', _call(ltp.negate, SYS, bogus=1), TE, 'bogus'),

    # -- time responses -------------------------------------------------------
    ('forced-lti', _call(ltp.forced_response, ct.rss(1, 1, 1), [0, 1]), CA, 'LTI'),
    ('forced-not-a-system', _call(ltp.forced_response, 'sys', [0, 1]), CA, 'sys'),
    ('forced-inputs-length', _call(ltp.forced_response, SYS, np.linspace(0, 1, 11),
                                   np.ones(7)), CD, 'inputs'),
    ('forced-inputs-mimo-1d', _call(ltp.forced_response, SYS2, np.linspace(0, 1, 11),
                                    np.ones(11)), CD, 'inputs'),
    ('forced-inputs-complex', _call(ltp.forced_response, SYS, [0, 0.5, 1],
                                    [1j, 0, 0]), CA, 'inputs'),
    ('forced-timepts-decreasing', _call(ltp.forced_response, SYS, [0, 1, 0.5]), VE,
     'timepts'),
    ('forced-timepts-2d', _call(ltp.forced_response, SYS, np.ones((2, 2))), CD, 'timepts'),
    ('forced-timepts-nan', _call(ltp.forced_response, SYS, [0, _NAN]), VE, 'timepts'),
    ('forced-timepts-empty', _call(ltp.forced_response, SYS, []), VE, 'timepts'),
    ('forced-final-time-negative', _call(ltp.forced_response, SYS, -1.0), VE, 'timepts'),
    ('forced-initial-state-size', _call(ltp.forced_response, SYS2, [0, 1], 0.0, [1, 2, 3]),
     CD, 'initial_state'),
    ('forced-initial-state-nan', _call(ltp.forced_response, SYS, [0, 1], 0.0, _NAN),
     VE, 'initial_state'),
    ('forced-method', _call(ltp.forced_response, SYS, [0, 1], method='euler'), VE, 'method'),
    ('forced-input-hold', _call(ltp.forced_response, SYS, [0, 1], input_hold='cubic'), VE,
     'input_hold'),
    ('forced-unknown-keyword', _call(ltp.forced_response, SYS, [0, 1], V=1.0), TE, 'V'),
    ('forced-rtol-negative', _call(ltp.forced_response, SYS, [0, 0.5, 1], rtol=-1.0), VE,
     'rtol'),
    ('forced-rtol-str', _call(ltp.forced_response, SYS, [0, 0.5, 1], rtol='tight'), TE, 'rtol'),
    ('forced-dt-grid', _call(ltp.forced_response, SYSD, [0, 0.15, 0.3]), VE, 'timepts'),
    ('step-input-index', _call(ltp.step_response, SYS, 1.0, input_indices=3), VE,
     'input_indices'),
    ('step-output-index-type', _call(ltp.step_response, SYS, 1.0, output_indices='y'), VE,
     'output_indices'),
    ('step-unknown-keyword', _call(ltp.step_response, SYS, 1.0, methd='solve_ivp'), TE,
     'methd'),
    ('initial-state-shape', _call(ltp.initial_response, SYS2, 1.0, np.ones((3, 3))), CD,
     'initial_state'),
    ('initial-output-index', _call(ltp.initial_response, SYS, 1.0, 1.0, output_indices=-1),
     VE, 'output_indices'),
    ('impulse-method', _call(ltp.impulse_response, SYS, 1.0, method='rk4'), VE, 'method'),
    ('impulse-unknown-keyword', _call(ltp.impulse_response, SYS, 1.0, foo=1), TE, 'foo'),

    # -- Floquet theory -------------------------------------------------------
    ('monodromy-lti', _call(ltp.monodromy, ct.rss(2, 1, 1)), CA, 'sys'),
    ('monodromy-nsteps-zero', _call(ltp.monodromy, SYS, nsteps=0), VE, 'nsteps'),
    ('monodromy-nsteps-float', _call(ltp.monodromy, SYS, nsteps=2.5), CA, 'nsteps'),
    ('monodromy-nsteps-discrete', _call(ltp.monodromy, SYSD, nsteps=5), CA, 'nsteps'),
    ('multipliers-none', _call(ltp.floquet_multipliers, None), CA, 'sys'),
    ('exponents-nsteps-negative', _call(ltp.floquet_exponents, SYS, -3), VE, 'nsteps'),
    ('is-stable-tol', _call(ltp.is_stable, SYS, tol=-1.0), VE, 'tol'),
    ('is-stable-tol-str', _call(ltp.is_stable, SYS, tol='small'), VE, 'tol'),
    ('floquet-transform-real', _call(ltp.floquet_transform, SYS, real='yes'), CA, 'real'),
    ('floquet-transform-keyword', _call(ltp.floquet_transform, SYS, rael=True), TE, 'rael'),
    ('floquet-transform-negative-multiplier',
     _call(ltp.floquet_transform, SYSD_FLIP, real=False), VE, 'negative real'),
    ('floquet-transform-no-states', _call(ltp.floquet_transform, ltp.ltpss(
        np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), 1.0, period=T)), VE, 'states'),
    ('floquet-transform-singular', _call(ltp.floquet_transform, SYSD_SINGULAR), VE,
     'singular'),

    # -- harmonic transfer functions -------------------------------------------
    ('htf-nharmonics-negative', _call(ltp.htf, SYS, -1), VE, 'nharmonics'),
    ('htf-nharmonics-float', _call(ltp.htf, SYS, 1.5), CA, 'nharmonics'),
    ('htf-lti-without-period', _call(ltp.htf, ct.rss(2, 1, 1), 1), CA, 'period'),
    ('htf-period-given-twice', _call(ltp.htf, SYS, 1, period=2.0), TE, 'period'),
    ('htf-method', _call(ltp.htf, SYS, 1, method='lu'), VE, 'method'),
    ('htf-internal-below-K', _call(ltp.htf, SYS, 2, internal_harmonics=1), VE,
     'internal_harmonics'),
    ('htf-discrete-too-many', _call(ltp.htf, SYSD, 5), VE, 'nharmonics'),
    ('htf-not-a-system', _call(ltp.htf, 'sys', 1), CA, 'sys'),
    ('htf-unknown-keyword', _call(ltp.htf, SYS, 1, omega=[1.0]), TE, 'omega'),
    ('htf-eval-nan', lambda: H(_NAN), VE, 's'),
    ('htf-eval-2d', lambda: H(np.ones((2, 2))), CD, 's'),
    ('htf-eval-at-pole', lambda: H_POLE(0.0), VE, 'pole'),
    ('htf-component-out-of-range', lambda: H.component(5), VE, 'harmonic index k'),
    ('htf-component-float', lambda: H.component(0.5), CA, 'k must be an integer'),
    ('htf-predict-shape', lambda: H.predict(np.arange(100) * 0.01, np.ones((2, 100))),
     CD, 'inputs must have shape'),
    ('htf-predict-fractional-periods',
     lambda: H.predict(np.arange(150) * 0.01, np.ones(150)), VE, 'integer number of periods'),
    ('htf-predict-nonuniform', lambda: H.predict([0.0, 0.1, 1.0], np.ones(3)), VE,
     'timepts must'),
    ('htf-predict-old-order', lambda: H.predict(np.sin(np.arange(100) * 0.01),
                                                np.arange(100) * 0.01), VE, 'order'),
    ('HTF-is-an-interface', _call(ltp.HTF, np.ones((3, 1, 1, 3)), [1.0, 2.0, 3.0], T), TE,
     'HTF'),
    ('HTF-components-3d', _call(ltp.HTFData, np.ones((3, 1, 4)), np.arange(1, 5.0), T), CD,
     'components'),
    ('HTF-even-harmonics', _call(ltp.HTFData, np.ones((2, 1, 1, 4)), np.arange(1, 5.0), T), CD,
     'components'),
    ('HTF-omega-length', _call(ltp.HTFData, np.ones((3, 1, 1, 4)), np.arange(1, 4.0), T), CD,
     'omega'),
    ('HTF-omega-decreasing', _call(ltp.HTFData, np.ones((3, 1, 1, 3)), [3.0, 2.0, 1.0], T), VE,
     'omega'),
    ('HTF-period-zero', _call(ltp.HTFData, np.ones((3, 1, 1, 3)), [1.0, 2.0, 3.0], 0.0), VE,
     'period'),
    ('HTF-std-shape', _call(ltp.HTFData, np.ones((3, 1, 1, 3)), [1.0, 2.0, 3.0], T,
                            std=np.ones((3, 1, 1, 2))), CD, 'std'),
    ('HTF-input-names', _call(ltp.HTFData, np.ones((3, 1, 1, 3)), [1.0, 2.0, 3.0], T,
                              inputs=['a', 'b']), CD, 'inputs'),
    ('data-htf-off-axis', lambda: H_DATA(1.0 + 1.0j), VE, 'imaginary axis'),
    ('data-htf-off-grid', lambda: H_DATA.component(0, [0.123]), VE, 'omega'),
    ('htf-response-omega-2d', _call(ltp.htf_response, H, np.ones((2, 2))), CD, 'omega'),
    ('bode-htf-not-htf', _call(ltp.bode_htf, SYS), CA, 'htfs'),
    ('bode-htf-harmonic', _call(ltp.bode_htf, H, harmonics=(5,)), VE, 'harmonic index'),
    ('bode-htf-harmonics-scalar', _call(ltp.bode_htf, H, harmonics=0), TE, 'harmonics'),
    ('htf-response-harmonics-scalar', _call(ltp.htf_response, H, [1.0], harmonics=1), TE,
     'harmonics'),
    ('bode-htf-omega-limits', _call(ltp.bode_htf, H, omega_limits=(10.0, 1.0)), VE,
     'omega_limits'),
    ('bode-htf-omega-num', _call(ltp.bode_htf, H, omega_num=1), VE, 'omega_num'),
    ('bode-htf-label', _call(ltp.bode_htf, H, omega_num=5, label=['one']), VE, 'label'),
    ('htf-map-not-htf', _call(ltp.htf_map_plot, SYS, 1.0), CA, 'htf'),
    ('htf-map-omega-vector', _call(ltp.htf_map_plot, H, [1.0, 2.0]), CD, 'omega'),
    ('htf-map-at-pole', _call(ltp.htf_map_plot, H_POLE, 0.0), VE, 'pole'),
    ('htf-map-ax-str', _call(ltp.htf_map_plot, H, 1.0, ax='left'), TE, 'ax'),
    ('htf-map-omega-nan', _call(ltp.htf_map_plot, H, _NAN), VE, 'omega'),

    # -- sampling, inverse sampling and lifting -------------------------------
    ('sample-Ts-not-dividing', _call(ltp.sample_system, SYS, 0.3), VE, 'Ts'),
    ('sample-Ts-negative', _call(ltp.sample_system, SYS, -0.1), VE, 'Ts'),
    ('sample-Ts-str', _call(ltp.sample_system, SYS, 'fast'), CA, 'Ts'),
    ('sample-method', _call(ltp.sample_system, SYS, 0.1, method='gbt'), VE, 'method'),
    ('sample-discrete', _call(ltp.sample_system, SYSD, 0.1), VE, 'continuous-time'),
    ('sample-lti', _call(ltp.sample_system, ct.rss(1, 1, 1), 0.1), CA, 'sys'),
    ('sample-unknown-keyword', _call(ltp.sample_system, SYS, 0.1, metod='zoh'), TE, 'metod'),
    ('sample-prewarp-above-nyquist',
     _call(ltp.sample_system, SYS, 0.1, 'tustin', prewarp_frequency=40.0), VE,
     'prewarp_frequency'),
    ('sample-prewarp-negative',
     _call(ltp.sample_system, SYS, 0.1, 'tustin', prewarp_frequency=-1.0), VE,
     'prewarp_frequency'),
    ('sample-tustin-pole-at-infinity',
     _call(ltp.sample_system, ltp.ltpss([[20.0]], [[1.0]], [[1.0]], 0, period=T), 0.1,
           'tustin'), VE, 'cI - A'),
    ('d2c-continuous', _call(ltp.d2c, SYS), VE, 'discrete-time'),
    ('d2c-method', _call(ltp.d2c, SYSD, method='zoh'), VE, 'method'),
    ('d2c-interpolation', _call(ltp.d2c, SYSD, interpolation='linear'), VE, 'interpolation'),
    ('d2c-eigenvalue-minus-one', _call(ltp.d2c, SYSD_MINUS_ONE), VE, 'I \\+ A_d'),
    ('d2c-log-periodic-A', _call(ltp.d2c, SYSD_FLIP, method='log'), VE, 'constant'),
    ('d2c-log-negative-eigenvalue', _call(ltp.d2c, SYSD_MINUS_ONE, method='log'), VE,
     'negative real axis'),
    ('d2c-unknown-keyword', _call(ltp.d2c, SYSD, Ts=0.1), TE, 'Ts'),
    ('lift-continuous', _call(ltp.lift, SYS), VE, 'discrete-time'),
    ('lift-method', _call(ltp.lift, SYSD, method='polyphase'), VE, 'method'),
    ('lift-real', _call(ltp.lift, SYSD, real='no'), CA, 'real'),
    ('lift-nharmonics-too-large', _call(ltp.lift, SYSD, nharmonics=5), VE, 'nharmonics'),
    ('lift-nharmonics-time', _call(ltp.lift, SYSD, method='time', nharmonics=1), VE,
     'nharmonics'),
    ('lift-lti', _call(ltp.lift, ct.rss(1, 1, 1, dt=0.1)), CA, 'sysd'),
    ('lift-unknown-keyword', _call(ltp.lift, SYSD, nharmonic=1), TE, 'nharmonic'),

    # -- hybrid plants, simulation and orbits -----------------------------------
    ('mode-updfcn-none', _call(ltp.HybridMode, None), CA, 'updfcn'),
    ('mode-guard-not-callable', _call(ltp.HybridMode, lambda t, x, u, p: x, guard=0.0,
                                      target=0), CA, 'guard'),
    ('mode-guard-without-target', _call(ltp.HybridMode, lambda t, x, u, p: x,
                                        guard=lambda t, x, u, p: x[0]), VE, 'target'),
    ('mode-reset-without-guard', _call(ltp.HybridMode, lambda t, x, u, p: x,
                                       reset=lambda t, x, u, p: x), VE, 'reset'),
    ('mode-target-float', _call(ltp.HybridMode, lambda t, x, u, p: x,
                                guard=lambda t, x, u, p: x[0], target=1.5), CA, 'target'),
    ('plant-no-modes', _call(ltp.HybridPlant, [], states=1), CA, 'modes'),
    ('plant-modes-wrong-type', _call(ltp.HybridPlant, [lambda t, x, u, p: x], states=1), CA,
     'modes'),
    ('plant-states-zero', _call(ltp.HybridPlant, [FREE], states=0), VE, 'states'),
    ('plant-states-missing', _call(ltp.HybridPlant, [FREE]), TE, 'states'),
    ('plant-params-list', _call(ltp.HybridPlant, [FREE], states=1, params=[1.0]), CA,
     'params'),
    ('plant-unknown-target', _call(ltp.HybridPlant, [ltp.HybridMode(
        lambda t, x, u, p: x, guard=lambda t, x, u, p: x[0], target='ground')], states=1),
     VE, 'target'),
    ('plant-duplicate-names', _call(ltp.HybridPlant, [FREE, FREE], states=1), VE,
     'mode names'),
    ('plant-outputs-count', _call(ltp.HybridPlant, [FREE], states=2, outputs=3), CD,
     'outputs'),
    ('simulate-not-plant', _call(ltp.simulate_hybrid, FORCED, [0, 1], [0.0]), CA, 'plant'),
    ('simulate-timepts-decreasing', _call(ltp.simulate_hybrid, BALL, [1.0, 0.0], [1, 0]), VE,
     'timepts'),
    ('simulate-timepts-single', _call(ltp.simulate_hybrid, BALL, [0.0], [1, 0]), VE,
     'timepts'),
    ('simulate-initial-state-size', _call(ltp.simulate_hybrid, BALL, [0, 1], [1, 0, 0]), CD,
     'initial_state'),
    ('simulate-initial-state-nan', _call(ltp.simulate_hybrid, BALL, [0, 1], [_NAN, 0]), VE,
     'initial_state'),
    ('simulate-mode-index', _call(ltp.simulate_hybrid, BALL, [0, 1], [1, 0], mode0=3), VE,
     'mode0'),
    ('simulate-mode-name', _call(ltp.simulate_hybrid, BALL, [0, 1], [1, 0], mode0='ground'),
     VE, 'mode0'),
    ('simulate-mode-float', _call(ltp.simulate_hybrid, BALL, [0, 1], [1, 0], mode0=0.5), CA,
     'mode0'),
    ('simulate-inputs-shape', _call(ltp.simulate_hybrid, ltp.HybridPlant(
        [FREE], states=1, inputs=2), [0, 0.5, 1], [1.0], inputs=np.ones((3, 3))), CD,
     'inputs'),
    ('simulate-rtol', _call(ltp.simulate_hybrid, BALL, [0, 1], [1, 0], rtol=-1.0), VE,
     'rtol'),
    ('simulate-max-events', _call(ltp.simulate_hybrid, BALL, [0, 1], [1, 0], max_events=0),
     VE, 'max_events'),
    ('simulate-guard-vector', _call(ltp.simulate_hybrid, ltp.HybridPlant([ltp.HybridMode(
        lambda t, x, u, p: [x[1], -9.81], guard=lambda t, x, u, p: x, target=0)], states=2),
        [0, 1], [1.0, 0.0]), TE, 'guard'),
    ('simulate-unknown-keyword', _call(ltp.simulate_hybrid, BALL, [0, 1], [1, 0], rtoll=1e-6),
     TE, 'rtoll'),
    ('saltation-no-guard', _call(ltp.saltation_matrix, ltp.HybridPlant([FREE], states=1),
                                 0, 0.0, [1.0]), VE, 'guard'),
    ('saltation-state-size', _call(ltp.saltation_matrix, BALL, 0, 0.0, [0.0]), CD, 'x'),
    ('orbit-not-periodic', _call(ltp.periodic_orbit, DRIFTING, T, [0.0]), VE,
     'not periodic'),
    ('orbit-period-zero', _call(ltp.periodic_orbit, FORCED, 0.0, [0.0]), VE, 'period'),
    ('orbit-x0-size', _call(ltp.periodic_orbit, FORCED, T, [0.0, 1.0]), CD, 'x0'),
    ('orbit-tol', _call(ltp.periodic_orbit, FORCED, T, [0.0], tol=2.0), VE, 'tol'),
    ('orbit-max-iter', _call(ltp.periodic_orbit, FORCED, T, [0.0], max_iter=0), VE,
     'max_iter'),
    ('orbit-npoints', _call(ltp.periodic_orbit, FORCED, T, [0.0], npoints=1), VE, 'npoints'),
    ('orbit-discrete-plant', _call(ltp.periodic_orbit, ct.nlsys(
        lambda t, x, u, p: 0.5 * x, None, states=1, inputs=0, dt=0.1), T, [0.0]), VE,
     'continuous-time'),
    ('orbit-jacobian-not-callable', _call(ltp.periodic_orbit, FORCED, T, [0.0],
                                          jacobian=[[1.0]]), CA, 'jacobian'),
    ('orbit-not-a-plant', _call(ltp.periodic_orbit, 'plant', T,
                                [0.0]), CA, 'plant'),
    ('orbit-unknown-keyword', _call(ltp.periodic_orbit, FORCED, T, [0.0], maxiter=5), TE,
     'maxiter'),
    ('period-map-jacobian-flag', _call(ltp.period_map, FORCED, T, [0.0], jacobian='yes'), CA,
     'jacobian'),
    ('linearize-orbit-type', _call(ltp.linearize_orbit, FORCED, 'orbit'), CA, 'orbit'),
    ('linearize-orbit-no-inputs', _call(ltp.linearize_orbit, FORCED_NO_INPUT, ORBIT_NO_INPUT), VE,
     'inputs'),
    ('linearize-orbit-flag', _call(ltp.linearize_orbit, FORCED, ORBIT,
                                   piecewise_constant='x'), CA, 'piecewise_constant'),
    ('linearize-orbit-other-plant', _call(ltp.linearize_orbit, BALL, ORBIT), VE, 'orbit'),

    # -- experiment design ----------------------------------------------------
    ('chirp-dt-not-dividing', _call(ltp.chirp_replicas, T, 3, 2.0, 0.0, 5.0, dt=0.03), VE,
     'dt'),
    ('chirp-f1-below-f0', _call(ltp.chirp_replicas, T, 3, 2.0, 5.0, 1.0, dt=0.01), VE, 'f1'),
    ('chirp-f1-nyquist', _call(ltp.chirp_replicas, T, 3, 2.0, 0.0, 60.0, dt=0.01), VE, 'f1'),
    ('chirp-nreplicas-zero', _call(ltp.chirp_replicas, T, 0, 2.0, 0.0, 5.0, dt=0.01), VE,
     'nreplicas'),
    ('chirp-nreplicas-float', _call(ltp.chirp_replicas, T, 2.5, 2.0, 0.0, 5.0, dt=0.01), CA,
     'nreplicas'),
    ('chirp-gap-negative', _call(ltp.chirp_replicas, T, 3, 2.0, 0.0, 5.0, dt=0.01,
                                 gap=-1.0), VE, 'gap'),
    ('chirp-duration-zero', _call(ltp.chirp_replicas, T, 3, 0.0, 0.0, 5.0, dt=0.01), VE,
     'duration'),
    ('chirp-f0-complex', _call(ltp.chirp_replicas, T, 3, 2.0, 1j, 5.0, dt=0.01), CA, 'f0'),
    ('chirp-dt-missing', _call(ltp.chirp_replicas, T, 3, 2.0, 0.0, 5.0), TE, 'dt'),
    ('chirp-unknown-keyword', _call(ltp.chirp_replicas, T, 3, 2.0, 0.0, 5.0, dt=0.01,
                                    amplitud=2.0), TE, 'amplitud'),
    ('multisine-empty', _call(ltp.multisine, [], T, dt=0.01, nperiods=4), VE, 'frequencies'),
    ('multisine-negative', _call(ltp.multisine, [-1.0], T, dt=0.01, nperiods=4), VE,
     'frequencies'),
    ('multisine-nyquist', _call(ltp.multisine, [400.0], T, dt=0.01, nperiods=4), VE,
     'Nyquist'),
    ('multisine-phases-size', _call(ltp.multisine, [1.5, 4.5], T, dt=0.01, nperiods=4,
                                    phases=[0.0]), VE, 'phases'),
    ('multisine-phases-name', _call(ltp.multisine, [1.5, 4.5], T, dt=0.01, nperiods=4,
                                    phases='zero'), VE, 'phases'),
    ('multisine-empty-band', _call(ltp.multisine, ('band', 0.1, 0.2), T, dt=0.01,
                                   nperiods=4), VE, 'frequencies'),
    ('multisine-band-spec', _call(ltp.multisine, ('bnd', 1.0, 5.0), T, dt=0.01, nperiods=4),
     VE, 'frequencies'),
    ('multisine-nperiods-zero', _call(ltp.multisine, [1.5], T, dt=0.01, nperiods=0), VE,
     'nperiods'),
    ('multisine-nexperiments-float', _call(ltp.multisine, [1.5], T, dt=0.01, nperiods=4,
                                           nexperiments=1.5), CA, 'nexperiments'),
    ('multisine-seed-str', _call(ltp.multisine, [1.5], T, dt=0.01, nperiods=4,
                                 phases='random', seed='abc'), TE, 'seed'),
    ('multisine-unknown-keyword', _call(ltp.multisine, [1.5], T, dt=0.01, nperiods=4,
                                        sed=1), TE, 'sed'),
    ('sines-below-resolution', _call(ltp.sine_experiments, [0.01], T, dt=0.01, nperiods=4),
     VE, 'frequencies'),
    ('sines-settle-negative', _call(ltp.sine_experiments, [1.5], T, dt=0.01, nperiods=4,
                                    settle=-1), VE, 'settle'),
    ('sines-dt-zero', _call(ltp.sine_experiments, [1.5], T, dt=0.0, nperiods=4), VE, 'dt'),
    ('sines-frequencies-nan', _call(ltp.sine_experiments, [_NAN], T, dt=0.01, nperiods=4),
     VE, 'frequencies'),

    # -- nonparametric and parametric identification --------------------------
    ('estimate-data-type', _call(ltp.estimate_htf, np.ones(10), T, 1), CA, 'data'),
    ('estimate-dt-not-dividing', _call(ltp.estimate_htf, (np.arange(100) * 0.03,
                                                          np.ones(100), np.ones(100)), T, 0),
     VE, 'dt'),
    ('estimate-nharmonics-negative', _call(ltp.estimate_htf, DATA, T, -1), VE, 'nharmonics'),
    ('estimate-period-zero', _call(ltp.estimate_htf, DATA, 0.0, 1), VE, 'period'),
    ('estimate-segments-shape', _call(ltp.estimate_htf, DATA, T, 1, segments=[0, 100]), CD,
     'segments'),
    ('estimate-segments-float', _call(ltp.estimate_htf, DATA, T, 1,
                                      segments=[[0.0, 100.0]]), CD, 'segments'),
    ('estimate-segments-range', _call(ltp.estimate_htf, DATA, T, 1,
                                      segments=[[0, 10 ** 6]]), VE, 'segments'),
    ('estimate-threshold', _call(ltp.estimate_htf, DATA, T, 1, threshold=2.0), VE,
     'threshold'),
    ('estimate-alpha-negative', _call(ltp.estimate_htf, DATA, T, 1, alpha=-1.0), VE, 'alpha'),
    ('estimate-alpha-name', _call(ltp.estimate_htf, DATA, T, 1, alpha='loo'), VE, 'alpha'),
    ('estimate-too-few-records', _call(ltp.estimate_htf, DATA, T, 1), VE, 'records'),
    ('estimate-nharmonics-too-large', _call(ltp.estimate_htf, DATA, T, 24,
                                            segments=EXC.segments), VE, 'nharmonics'),
    ('estimate-length-mismatch', _call(ltp.estimate_htf, (EXC.time, EXC.inputs,
                                                          Y_EXC[:-1]), T, 1), CD, r'data: inputs'),
    ('estimate-nonuniform-time', _call(ltp.estimate_htf, (EXC.time ** 1.01, EXC.inputs,
                                                          Y_EXC), T, 1), VE, 'time'),
    ('estimate-shorter-than-period', _call(ltp.estimate_htf, (EXC.time[:20], EXC.inputs[:20],
                                                              Y_EXC[:20]), T, 0), VE, 'period'),
    ('estimate-zero-input', _call(ltp.estimate_htf, (EXC.time, 0 * EXC.inputs, Y_EXC), T, 0),
     VE, 'input'),
    ('estimate-nan-output', _call(ltp.estimate_htf, (EXC.time, EXC.inputs,
                                                     np.full_like(Y_EXC, _NAN)), T, 0),
     VE, 'outputs'),
    ('estimate-omega-limits', _call(ltp.estimate_htf, DATA, T, 1, segments=EXC.segments,
                                    omega_limits=(5.0, 1.0)), VE, 'omega_limits'),
    ('estimate-unknown-keyword', _call(ltp.estimate_htf, DATA, T, 1, segment=None), TE,
     'segment'),
    ('fit-model-not-callable', _call(ltp.fit_htf, 'model', H_DATA, [1.0]), CA, 'model'),
    ('fit-model-htf', _call(ltp.fit_htf, _model, H, [1.0]), CA, 'estimate'),
    ('fit-harmonics-too-large', _call(ltp.fit_htf, _model, H_DATA, [1.0], harmonics=[2]), VE,
     'harmonics'),
    ('fit-harmonics-float', _call(ltp.fit_htf, _model, H_DATA, [1.0], harmonics=[0.5]), CA,
     'harmonics'),
    ('fit-omega-limits-empty', _call(ltp.fit_htf, _model, H_DATA, [1.0],
                                     omega_limits=(100.0, 200.0)), VE, 'omega_limits'),
    ('fit-weights-name', _call(ltp.fit_htf, _model, H_DATA, [1.0], weights='var'), VE,
     'weights'),
    ('fit-weights-std-missing', _call(ltp.fit_htf, _model, H_DATA, [1.0], weights='std'), VE,
     'std'),
    ('fit-model-shape', _call(ltp.fit_htf, lambda p, w: np.ones((2, 1, 1, w.size)), H_DATA,
                              [1.0]), CD, 'model'),
    ('fit-p0-2d', _call(ltp.fit_htf, _model, H_DATA, [[1.0]]), CD, 'p0'),
    ('fit-p0-nan', _call(ltp.fit_htf, _model, H_DATA, [_NAN]), VE, 'p0'),
    ('fit-weights-shape', _call(ltp.fit_htf, _model, H_DATA, [1.0], weights=np.ones(7)), CD,
     'weights'),
    ('fit-p0-empty', _call(ltp.fit_htf, _model, H_DATA, []), VE, 'p0'),
    ('fit-p0-outside-bounds', _call(ltp.fit_htf, _model, H_DATA, [5.0], bounds=([0], [1])), VE,
     'bounds'),
    ('fit-unknown-keyword', _call(ltp.fit_htf, _model, H_DATA, [1.0], method='lm'), TE,
     'method'),
    ('delays-estimate-type', _call(ltp.estimate_delays, G_DATA, G_DATA), CA, 'estimate'),
    ('delays-input-index', _call(ltp.estimate_delays, H_DATA, G_DATA, input=1), VE, 'input'),
    ('delays-output-index', _call(ltp.estimate_delays, H_DATA, G_DATA, output=-1), VE,
     'output'),
    ('delays-reference-shape', _call(ltp.estimate_delays, H_DATA, G_DATA[:, :, :, :5]), CD,
     'reference'),
    ('delays-reference-zero', _call(ltp.estimate_delays, H_DATA, 0 * G_DATA), VE,
     'reference'),
    ('delays-max-delay', _call(ltp.estimate_delays, H_DATA, G_DATA, max_delay=-1.0), VE,
     'max_delay'),
    ('delays-max-delay-huge', _call(ltp.estimate_delays, H_DATA, G_DATA, max_delay=1e15), VE,
     'max_delay'),
    ('delays-unknown-keyword', _call(ltp.estimate_delays, H_DATA, G_DATA, harmonic=[0]), TE,
     'harmonic'),
    ('e-rms-shapes', _call(ltp.e_rms, np.ones(10), np.ones(9)), CD, 'y_hat'),
    ('e-rms-str', _call(ltp.e_rms, 'y', np.ones(1)), CA, 'y'),
    ('nrmse-zero-reference', _call(ltp.nrmse, np.zeros(5), np.ones(5)), VE, 'y'),
    ('nrmse-empty', _call(ltp.nrmse, [], []), VE, 'y'),
    ('nrmse-nan', _call(ltp.nrmse, np.ones(5), [1, 1, _NAN, 1, 1]), VE, 'y_hat'),

    # -- frequency-domain subspace identification --------------------------------
    ('fdsub-omega-missing', _call(ltp.fdsubspace, G_FD), CA, 'omega'),
    ('fdsub-omega-length', _call(ltp.fdsubspace, G_FD, W_FD[:-1]), CD, 'omega'),
    ('fdsub-frd-with-omega', _call(ltp.fdsubspace, FRD, W_FD), CA, 'omega'),
    ('fdsub-lti-data', _call(ltp.fdsubspace, ct.rss(2, 1, 1)), CA, 'data'),
    ('fdsub-omega-negative', _call(ltp.fdsubspace, G_FD, -W_FD), VE, 'omega'),
    ('fdsub-omega-repeated', _call(ltp.fdsubspace, G_FD, np.full(W_FD.size, 1.0)), VE,
     'omega'),
    ('fdsub-omega-nyquist', _call(ltp.fdsubspace, G_FD, W_FD * 100, dt=0.1), VE, 'omega'),
    ('fdsub-q-not-above-order', _call(ltp.fdsubspace, G_FD, W_FD, 2, q=2), VE, 'q'),
    ('fdsub-too-few-frequencies', _call(ltp.fdsubspace, G_FD[:3], W_FD[:3], 5), VE,
     'too few frequencies'),
    ('fdsub-order-and-max-order', _call(ltp.fdsubspace, G_FD, W_FD, 1, max_order=3), CA,
     'max_order'),
    ('fdsub-estimate-d', _call(ltp.fdsubspace, G_FD, W_FD, 1, estimate_d='no'), CA,
     'estimate_d'),
    ('fdsub-dt-negative', _call(ltp.fdsubspace, G_FD, W_FD, dt=-1.0), VE, 'dt'),
    ('fdsub-dt-contradicts-frd', _call(ltp.fdsubspace, FRD, dt=0), VE, 'dt'),
    ('fdsub-zero-data', _call(ltp.fdsubspace, 0 * G_FD, W_FD), VE, 'data'),
    ('fdsub-nan-data', _call(ltp.fdsubspace, np.full(12, _NAN + 0j), W_FD), VE, 'data'),
    ('fdsub-data-2d', _call(ltp.fdsubspace, np.ones((2, 12)), W_FD), CD, 'data'),
    ('fdsub-weights-shape', _call(ltp.fdsubspace, G_FD, W_FD, weights=np.ones(5)), CD,
     'weights'),
    ('fdsub-weights-negative', _call(ltp.fdsubspace, G_FD, W_FD, weights=-np.ones(12)), VE,
     'weights'),
    ('fdsub-timescale', _call(ltp.fdsubspace, G_FD, W_FD, timescale=-1.0), VE, 'timescale'),
    ('fdsub-order-float', _call(ltp.fdsubspace, G_FD, W_FD, 1.5), CA, 'order'),
    ('fdsub-unknown-keyword', _call(ltp.fdsubspace, G_FD, W_FD, ordr=1), TE, 'ordr'),

    # -- least-squares identification of switching systems ----------------------
    ('hls-period-zero', _call(ltp.hybrid_ls, T_LS, X_LS, U_LS, 0.0, [0.0]), VE, 'period'),
    ('hls-switching-not-from-zero', _call(ltp.hybrid_ls, T_LS, X_LS, U_LS, T, [0.1, 0.5]), VE,
     'switching_times'),
    ('hls-switching-decreasing', _call(ltp.hybrid_ls, T_LS, X_LS, U_LS, T, [0.0, 0.5, 0.2]),
     VE, 'switching_times'),
    ('hls-switching-beyond-period', _call(ltp.hybrid_ls, T_LS, X_LS, U_LS, T, [0.0, 1.5]), VE,
     'switching_times'),
    ('hls-nharmonics-negative', _call(ltp.hybrid_ls, T_LS, X_LS, U_LS, T, [0.0], -1), VE,
     'nharmonics'),
    ('hls-x-length', _call(ltp.hybrid_ls, T_LS, X_LS[:-1], U_LS, T, [0.0]), CD, 'x'),
    ('hls-u-length', _call(ltp.hybrid_ls, T_LS, X_LS, U_LS[:-3], T, [0.0]), CD, 'u'),
    ('hls-fractional-periods', _call(ltp.hybrid_ls, T_LS[:700], X_LS[:700], U_LS[:700], T,
                                     [0.0]), VE, 'integer number of periods'),
    ('hls-nonuniform-time', _call(ltp.hybrid_ls, T_LS ** 2, X_LS, U_LS, T, [0.0]), VE, 't'),
    ('hls-too-few-samples', _call(ltp.hybrid_ls, [0.0, 0.5], [1.0, 2.0], [0.0, 1.0], T,
                                  [0.0]), VE, 't'),
    ('hls-x-nan', _call(ltp.hybrid_ls, T_LS, np.full(T_LS.size, _NAN), U_LS, T, [0.0]), VE,
     'x'),
    ('hls-x-complex', _call(ltp.hybrid_ls, T_LS, X_LS + 1j, U_LS, T, [0.0]), CA, 'x'),
    ('hls-records-mismatch', _call(ltp.hybrid_ls, [T_LS, T_LS], [X_LS], [U_LS, U_LS], T,
                                   [0.0]), CD, 'x'),
    ('hls-nshifts-str', _call(ltp.hybrid_ls, T_LS, X_LS, U_LS, T, [0.0], nshifts='two'), CA,
     'nshifts'),
    ('hls-excitation-tol', _call(ltp.hybrid_ls, T_LS, X_LS, U_LS, T, [0.0],
                                 excitation_tol=2.0), VE, 'excitation_tol'),
    ('hls-too-little-data', _call(ltp.hybrid_ls, T_LS, X_LS, U_LS, T, [0.0, 0.25, 0.5, 0.75],
                                  3, nshifts=0), VE, 'too little data'),
    ('hls-zero-input', _call(ltp.hybrid_ls, T_LS, X_LS, 0 * U_LS, T, [0.0]), VE,
     r'\bu\b|input|excit'),
    ('hls-unknown-keyword', _call(ltp.hybrid_ls, T_LS, X_LS, U_LS, T, [0.0], nharmonic=1), TE,
     'nharmonic'),
    ('hls-result-A-shape', _call(ltp.HybridLSResult, np.ones((1, 2, 1, 1)),
                                 np.ones((1, 2, 1, 1)), T, [0.0]), CD, 'A'),
    ('hls-result-B-shape', _call(ltp.HybridLSResult, np.ones((1, 3, 1, 1)),
                                 np.ones((2, 3, 1, 1)), T, [0.0]), CD, 'B'),
    ('hls-result-times-count', _call(ltp.HybridLSResult, np.ones((2, 1, 1, 1)),
                                     np.ones((2, 1, 1, 1)), T, [0.0]), CD, 'switching_times'),
]

# Known defects: id -> reason.  Entries listed here are expected to fail
# (strict xfail) until the library module is fixed.
KNOWN_DEFECTS = {
}


def _params(table, defects):
    params = []
    for case_id, func, exc, match in table:
        marks = ()
        if case_id in defects:
            marks = pytest.mark.xfail(strict=True, reason=defects[case_id])
        params.append(pytest.param(func, exc, match, id=case_id, marks=marks))
    return params


def test_catalogue_size():
    ids = [case[0] for case in CATALOGUE]
    assert len(ids) == len(set(ids)), "duplicate catalogue ids"
    assert len(CATALOGUE) >= 60


@pytest.mark.parametrize('func, exc, match', _params(CATALOGUE, KNOWN_DEFECTS))
def test_malformed_call(func, exc, match):
    with warnings.catch_warnings():
        # warnings are not the subject here; an exception must still come out
        warnings.simplefilter('ignore')
        check_raises(func, exc, match)


#
# Accepted inputs that must warn
#

WARNINGS = [
    ('htf-unstable', _call(ltp.htf, ltp.ltpss([[1.0]], [[1.0]], [[1.0]], 0, period=T), 1),
     'unstable'),
    ('multisine-half-multiple', _call(ltp.multisine, [np.pi, 2.5 * np.pi], T, dt=0.01,
                                      nperiods=4), 'omega_p/2'),
    ('sines-half-multiple', _call(ltp.sine_experiments, [3 * np.pi], T, dt=0.01, nperiods=4),
     'omega_p/2'),
    ('sample-alpha-ignored', _call(ltp.sample_system, SYS, 0.1, alpha=0.5), 'alpha'),
    ('sample-prewarp-zoh', _call(ltp.sample_system, SYS, 0.1, 'zoh', prewarp_frequency=1.0),
     'prewarp_frequency'),
    ('floquet-transform-period-doubling', _call(ltp.floquet_transform, SYSD_FLIP), '2T'),
    ('impulse-feedthrough', _call(ltp.impulse_response, SYS_D1, 1.0), 'feedthrough'),
    ('estimate-ill-conditioned', _call(ltp.estimate_htf, [DATA] * 3, T, 1), 'ill-conditioned'),
]


@pytest.mark.parametrize('func, match', [pytest.param(f, m, id=i) for i, f, m in WARNINGS])
def test_accepted_with_warning(func, match):
    with pytest.warns(UserWarning, match=match):
        func()


#
# The checker itself
#

def test_checker_rejects_bare_index_error():
    def bad():
        raise IndexError("index 3 is out of bounds")
    with pytest.raises(AssertionError, match="bare IndexError"):
        check_raises(bad, ValueError, 'index')


def test_checker_rejects_broadcast_error():
    def bad():
        return np.ones(3) + np.ones(4)
    with pytest.raises(AssertionError, match="broadcast"):
        check_raises(bad, ValueError, 'operands')


def test_checker_reports_nan_result():
    with pytest.raises(pytest.fail.Exception, match="NaN"):
        check_raises(lambda: np.array([np.nan]), ValueError, 'x')
