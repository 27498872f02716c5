"""Every public callable of python-control called on an LTP system: the exact
answer or a clear error.

The test walks ``dir(control)``, so a new python-control function fails here
until it is classified.  It also writes the table shown in the documentation
(``docs/interop_table.csv``); with ``LTP_WRITE_TABLE=1`` it rewrites the file,
otherwise the file must equal what the test finds.
"""

import csv
import inspect
import io
import os
import warnings

import control as ct
import matplotlib
import numpy as np
import pytest

import ltpcontrol as ltp

matplotlib.use('Agg')

TABLE = os.path.join(os.path.dirname(__file__), '..', 'docs', 'interop_table.csv')

P = ltp.ltpss([[-1.0, 0.2], [0.0, -2.0]],
              ltp.PeriodicMatrix([[[0.25], [0.0]], [[1.0], [1.0]], [[0.25], [0.0]]], 1.0),
              [[1.0, 0.5]], 0, period=1.0, name='P')
K = ct.ss(ct.tf([2.0], [1.0, 3.0]))
t = np.linspace(0, 2, 41)

# python-control callables that take no system: classes, exceptions, data and
# plot utilities, defaults, generators of LTI systems
NO_SYSTEM = {
    'box_grid', 'combine_tf', 'combine_time_responses', 'common_timebase', 'correlation',
    'cvxopt_check', 'db2mag', 'defaults', 'describing_function', 'describing_function_plot',
    'drss', 'eigensys_realization', 'era', 'get_plot_axes', 'mag2db', 'markov',
    'nichols_grid', 'pade', 'pandas_check', 'pole_zero_subplots', 'reset_defaults',
    'reset_rcParams', 'rss', 'set_defaults', 'slycot_check', 'summing_junction', 'suptitle',
    'time_response_plot', 'unwrap', 'use_fbs_defaults', 'use_legacy_defaults',
    'use_matlab_defaults', 'white_noise', 'zpk', 'connect', 'friction_backlash_nonlinearity',
    'relay_hysteresis_nonlinearity', 'saturation_nonlinearity',
}

# arguments other than the system, where python-control needs them
CALLS = {
    'acker': lambda f: f(P, None, [-1, -2]),
    'append': lambda f: f(K, P),
    'balanced_reduction': lambda f: f(P, 1), 'balred': lambda f: f(P, 1),
    'c2d': lambda f: f(P, 0.1), 'sample_system': lambda f: f(P, 0.1),
    'disk_margins': lambda f: f(P, [1.0]),
    'dlqe': lambda f: f(P.sample(0.1), [[1.0]], [[1.0]]),
    'dlqr': lambda f: f(P.sample(0.1), np.eye(2), [[1.0]]),
    'evalfr': lambda f: f(P, 1j), 'freqresp': lambda f: f(P, [1.0]),
    'feedback': lambda f: f(K, P),
    'forced_response': lambda f: f(P, t, np.sin(t)),
    'gangof4': lambda f: f(P, K), 'gangof4_plot': lambda f: f(P, K),
    'gangof4_response': lambda f: f(P, K),
    'gram': lambda f: f(P, 'c'),
    'impulse_response': lambda f: f(P, t), 'initial_response': lambda f: f(P, t, [1, 0]),
    'input_output_response': lambda f: f(P, t, np.sin(t)),
    'interconnect': lambda f: f([P, K], inplist=['u[0]'], outlist=['y[0]']),
    'linearize': lambda f: f(P, [0, 0], 0, t=0.3),
    'lqe': lambda f: f(P, [[1.0]], [[1.0]]), 'lqr': lambda f: f(P, np.eye(2), [[1.0]]),
    'model_reduction': lambda f: f(P, [1]), 'modred': lambda f: f(P, [1]),
    'parallel': lambda f: f(K, P), 'series': lambda f: f(K, P),
    'place': lambda f: f(P, None, [-1, -2]), 'place_acker': lambda f: f(P, None, [-1, -2]),
    'place_varga': lambda f: f(P, None, [-1, -2]),
    'step_response': lambda f: f(P, t),
    'similarity_transform': lambda f: f(P, np.eye(2)),
    'create_statefbk_iosystem': lambda f: f(P, np.ones((1, 2))),
    'create_estimator_iosystem': lambda f: f(P, np.eye(1), np.eye(1)),
    'describing_function_response': lambda f: f(P, ct.saturation_nonlinearity(1), [1.0]),
    'find_eqpt': lambda f: f(P, [0, 0]), 'find_operating_point': lambda f: f(P, [0, 0]),
    'h2syn': lambda f: f(P, 1, 1), 'hinfsyn': lambda f: f(P, 1, 1),
    'ctrb': lambda f: f(P, np.eye(2)), 'obsv': lambda f: f(P, np.eye(2)),
    'lyap': lambda f: f(P, np.eye(2)), 'dlyap': lambda f: f(P, np.eye(2)),
    'care': lambda f: f(P, np.eye(2), np.eye(2)), 'dare': lambda f: f(P, np.eye(2), np.eye(2)),
}


def _close(a, b):
    return np.allclose(np.asarray(a, complex), np.asarray(b, complex), atol=1e-9)


def _same_system(a, b):
    tt = np.linspace(0, 3, 61)
    return isinstance(a, ltp.LTPStateSpace) and _close(
        ltp.step_response(a, tt).outputs, ltp.step_response(b, tt).outputs)


def _same_response(a, b):
    return _close(a.outputs, b.outputs) and _close(a.time, b.time)


# successful calls and the independent ltpcontrol answer they must equal
EXACT = {
    'append': (lambda r: _same_system(r, ltp.append(K, P)), "ltp.append"),
    'feedback': (lambda r: _same_system(r, ltp.feedback(K, P)), "ltp.feedback"),
    'series': (lambda r: _same_system(r, ltp.series(K, P)), "ltp.series (operator)"),
    'parallel': (lambda r: _same_system(r, ltp.parallel(K, P)), "ltp.parallel (operator)"),
    'negate': (lambda r: _same_system(r, ltp.negate(P)), "ltp.negate (operator)"),
    'interconnect': (lambda r: _same_system(r, ltp.interconnect(
        [P, K], inplist=['u[0]'], outlist=['y[0]'])), "ltp.interconnect"),
    'forced_response': (lambda r: _same_response(r, ltp.forced_response(P, t, np.sin(t))),
                        "ltp.forced_response"),
    'input_output_response': (lambda r: _same_response(
        r, ltp.forced_response(P, t, np.sin(t))), "ltp.forced_response"),
    'step_response': (lambda r: _same_response(r, ltp.step_response(P, t)),
                      "ltp.step_response"),
    'initial_response': (lambda r: _same_response(r, ltp.initial_response(P, t, [1, 0])),
                         "ltp.initial_response"),
    'impulse_response': (lambda r: _same_response(r, ltp.impulse_response(P, t)),
                         "ltp.impulse_response"),
    'sample_system': (lambda r: _close(r.A.sample(10), ltp.sample_system(P, 0.1).A.sample(10)),
                      "sys.sample (method)"),
    'zeros': (lambda r: _close(np.sort_complex(r), np.sort_complex(ltp.zeros(P))),
              "sys.zeros (method)"),
    'poles': (lambda r: _close(r, ltp.floquet_exponents(P)), "sys.poles: Floquet exponents"),
    'pole_zero_map': (lambda r: _close(r.poles, ltp.floquet_exponents(P)),
                      "sys.poles and sys.zeros (methods)"),
    'linearize': (lambda r: _close(r.A, P.A(0.3)), "sys.linearize: frozen at t"),
    'norm': (lambda r: np.isclose(r, ltp.norm(P, 2)), "ltp.norm"),
    'linfnorm': (lambda r: np.isclose(r[0], ltp.norm(P, 'inf', tol=1e-10)),
                 "ltp.norm(sys, 'inf')"),
    'hankel_singular_values': (lambda r: _close(r, ltp.hsvd(P)), "ltp.hsvd"),
    'balanced_reduction': (lambda r: _same_system(r, ltp.balred(P, 1)), "ltp.balred"),
    'minreal': (lambda r: _same_system(r, ltp.minreal(P)), "ltp.minreal"),
    'gram': (lambda r: _close(r(0.3), ltp.gram(P, 'c')(0.3)), "ltp.gram"),
    'lqr': (lambda r: _close(r[0](0.3), ltp.lqr(P, np.eye(2), [[1.0]])[0](0.3)), "ltp.lqr"),
    'lqe': (lambda r: _close(r[0](0.3), ltp.lqe(P, [[1.0]], [[1.0]])[0](0.3)), "ltp.lqe"),
    'dlqr': (lambda r: _close(r[0].sample(10), ltp.dlqr(P.sample(0.1), np.eye(2),
                                                       [[1.0]])[0].sample(10)), "ltp.dlqr"),
    'dlqe': (lambda r: _close(r[0].sample(10), ltp.dlqe(P.sample(0.1), [[1.0]],
                                                       [[1.0]])[0].sample(10)), "ltp.dlqe"),
    # generic I/O system queries and conversions (no LTI assumption)
    'isctime': (lambda r: r is True, "generic"), 'isdtime': (lambda r: r is False, "generic"),
    'issiso': (lambda r: r is True, "generic"),
    'issys': (lambda r: r is isinstance(P, ct.LTI), "generic: not an LTI system"),
    'timebase': (lambda r: r == 0, "generic"),
    'iosys_repr': (lambda r: isinstance(r, str) and 'P' in r, "generic"),
}
ALIASES = {'balred': 'balanced_reduction', 'hsvd': 'hankel_singular_values',
           'minimal_realization': 'minreal', 'c2d': 'sample_system', 'system_norm': 'norm'}

# python-control's own error text is clear for these calls
CLEAR_AS_IS = {'connection_table', 'ss2io'}


def _public():
    return sorted(n for n in dir(ct) if not n.startswith('_')
                  and callable(getattr(ct, n)) and not inspect.isclass(getattr(ct, n)))


def _outcome(name):
    call = CALLS.get(name, lambda f: f(P))
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        try:
            result = call(getattr(ct, name))
        except Exception as exc:            # the error must say what to do
            text = str(exc).replace('\n', ' ')
            clear = name in CLEAR_AS_IS or any(
                key in text for key in ('LTPStateSpace', 'time-periodic', 'ltp.', 'give dt'))
            return ('error' if clear else 'UNCLEAR ERROR'), f"{type(exc).__name__}: {text}"
    check, how = EXACT.get(ALIASES.get(name, name), (None, None))
    try:
        ok = check is not None and bool(check(result))
    except Exception:
        ok = False
    if not ok:
        return 'UNVERIFIED RESULT', type(result).__name__
    return 'exact', how


def _table():
    rows = []
    for name in _public():
        if name in NO_SYSTEM:
            continue
        kind, detail = _outcome(name)
        if kind == 'error':
            hint = detail.split(': use ', 1)
            detail = (f"{detail.split(':', 1)[0]}: use {hint[1]}" if len(hint) == 2
                      else detail)
        rows.append((f"``ct.{name}``", kind, detail))
    return rows


def _csv(rows):
    out = io.StringIO()
    csv.writer(out, lineterminator='\n').writerows(rows)
    return out.getvalue()


@pytest.mark.slow
def test_every_python_control_entry_point_is_exact_or_a_clear_error():
    unknown = [n for n in NO_SYSTEM if n not in dir(ct)]
    assert not unknown, f"names python-control no longer has: {unknown}"
    rows = _table()
    bad = [r for r in rows if r[1] not in ('exact', 'error')]
    assert not bad, bad
    text = _csv(rows)
    if os.environ.get('LTP_WRITE_TABLE'):
        with open(TABLE, 'w', encoding='utf-8') as fh:
            fh.write(text)
    with open(TABLE, encoding='utf-8') as fh:
        assert fh.read() == text, ("docs/interop_table.csv is out of date: rerun this "
                                   "test with LTP_WRITE_TABLE=1")
