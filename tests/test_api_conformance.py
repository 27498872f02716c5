"""Meta-tests of the public API, in the spirit of python-control's
``kwargs_test.py`` and ``docstrings_test.py``.

* Every public function, class and method that accepts ``**kwargs`` rejects
  an unknown keyword with `TypeError` (plotting functions that hand their
  keywords to matplotlib may raise its `AttributeError`, as in
  python-control).  A table holds one minimal valid call per callable, and
  a discovery test makes sure the table covers every such callable.
* Every public name has a numpydoc docstring with a summary line and an
  ``Examples`` section containing ``>>>``, whose documented parameters match
  the signature (``*args``/``**kwargs`` may be documented through the names
  they accept, under Parameters or Other Parameters).
* A representative slice of the API runs on well-posed inputs with warnings
  turned into errors.
"""

import inspect
import warnings

import control as ct
import numpy as np
import pytest
from numpydoc.docscrape import ClassDoc, FunctionDoc

import ltpcontrol as ltp
from systems import damped_mathieu, mathieu

PUBLIC = {name: getattr(ltp, name) for name in ltp.__all__}


def test_all_names_exist_and_are_unique():
    assert len(ltp.__all__) == len(set(ltp.__all__))
    for name, obj in PUBLIC.items():
        assert obj is not None, name
        assert callable(obj), f"{name} is not callable"


#
# Unknown keywords
#

T = 1.0
BP = ltp.PeriodicMatrix([[[0.25]], [[1.0]], [[0.25]]], T)
SYS = ltp.ltpss([[-1.0]], BP, [[1.0]], 0, period=T, name='plant')
SYSD = SYS.sample(0.1)
# a small set of sine experiments on a first-order LTP plant (lifting data)
_SINE_PLANT = ltp.ltpss([[-2.0]], lambda t: np.array([[1 + 0.5 * np.cos(4 * np.pi * t)]]),
                        [[1.0]], 0, 0.5)
_SINE_EXC = ltp.sine_experiments(np.pi / 2 * np.array([k for k in range(1, 16) if k % 4]),
                                 0.5, dt=0.0125, nperiods=8, settle=12)
_SINE_RESPONSE = ltp.forced_response(_SINE_PLANT, _SINE_EXC.time, _SINE_EXC.inputs)
H = ltp.htf(SYS, 1)
OMEGA = np.linspace(0.5, 10.0, 20)
G_DATA = np.zeros((3, 1, 1, OMEGA.size), complex)
G_DATA[1, 0, 0] = 1 / (1j * OMEGA + 1)
G_DATA[0, 0, 0] = G_DATA[2, 0, 0] = 0.1 / (1j * OMEGA + 2)
H_DATA = ltp.HTFData(G_DATA, OMEGA, T)
BALL = ltp.HybridPlant([ltp.HybridMode(
    lambda t, x, u, p: [x[1], -9.81], guard=lambda t, x, u, p: x[0],
    reset=lambda t, x, u, p: [x[0], -0.8 * x[1]], target=0)], states=['h', 'v'])
FORCED = ct.nlsys(lambda t, x, u, p: -x + np.cos(2 * np.pi * t) + u, None,
                  states=1, inputs=1, name='forced')
EXC = ltp.chirp_replicas(T, 3, 4.0, 0.1, 10.0, dt=0.02)
DATA = (EXC.time, EXC.inputs, (1 + np.cos(2 * np.pi * EXC.time)) * EXC.inputs)
T_LS = np.arange(1000) * 1e-3


def _model(p, w):
    return np.broadcast_to(p[0] / (1j * w + 1), (3, 1, 1, w.size)).copy()


# name -> callable taking the extra keyword(s) and making a minimal valid call
KWARG_CALLS = {
    'LTPStateSpace': lambda **kw: ltp.LTPStateSpace([[-1.0]], [[1.0]], [[1.0]], [[0.0]],
                                                    T, **kw),
    'ltpss': lambda **kw: ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=T, **kw),
    'series': lambda **kw: ltp.series(SYS, SYS, **kw),
    'parallel': lambda **kw: ltp.parallel(SYS, SYS, **kw),
    'feedback': lambda **kw: ltp.feedback(SYS, 1.0, **kw),
    'append': lambda **kw: ltp.append(SYS, SYS, **kw),
    'negate': lambda **kw: ltp.negate(SYS, **kw),
    'interconnect': lambda **kw: ltp.interconnect([SYS, 2.0], inplist='sys[1].u[0]',
                                                  outlist='y[0]', check_unused=False, **kw),
    'forced_response': lambda **kw: ltp.forced_response(SYS, [0, 0.5, 1], **kw),
    'step_response': lambda **kw: ltp.step_response(SYS, 1.0, **kw),
    'initial_response': lambda **kw: ltp.initial_response(SYS, 1.0, 1.0, **kw),
    'impulse_response': lambda **kw: ltp.impulse_response(SYS, 1.0, **kw),
    'floquet_transform': lambda **kw: ltp.floquet_transform(SYS, **kw),
    'htf': lambda **kw: ltp.htf(SYS, 1, **kw),
    'bode_htf': lambda **kw: ltp.bode_htf(H, omega_num=5, **kw),
    'sample_system': lambda **kw: ltp.sample_system(SYS, 0.1, **kw),
    'c2d': lambda **kw: ltp.c2d(SYS, 0.1, **kw),
    'd2c': lambda **kw: ltp.d2c(SYSD, **kw),
    'floquet_realization': lambda **kw: ltp.floquet_realization(
        ltp.lift(SYSD, nharmonics=1), 1, SYSD.nsteps, **kw),
    'to_canonical': lambda **kw: ltp.to_canonical(SYS, **kw),
    'matrix_errors': lambda **kw: ltp.matrix_errors(SYS, SYS, **kw),
    'lifted_frequency_response': lambda **kw: ltp.lifted_frequency_response(
        _SINE_RESPONSE, 0.5, 1, transient=6.0, **kw),
    'identify_ltp': lambda **kw: ltp.identify_ltp(
        _SINE_RESPONSE, 0.5, 1, q=10, transient=6.0, input_hold='foh', **kw),
    'lift': lambda **kw: ltp.lift(SYSD, **kw),
    'simulate_hybrid': lambda **kw: ltp.simulate_hybrid(BALL, [0, 0.1], [1.0, 0.0], **kw),
    'periodic_orbit': lambda **kw: ltp.periodic_orbit(FORCED, T, [0.0], npoints=4, **kw),
    'period_map': lambda **kw: ltp.period_map(FORCED, T, [0.0], **kw),
    'chirp_replicas': lambda **kw: ltp.chirp_replicas(T, 3, 2.0, 0.0, 5.0, dt=0.01, **kw),
    'multisine': lambda **kw: ltp.multisine([1.5], T, dt=0.01, nperiods=4, **kw),
    'sine_experiments': lambda **kw: ltp.sine_experiments([1.5], T, dt=0.01, nperiods=4,
                                                          **kw),
    'estimate_htf': lambda **kw: ltp.estimate_htf(DATA, T, 1, segments=EXC.segments, **kw),
    'fit_htf': lambda **kw: ltp.fit_htf(_model, H_DATA, [1.0], **kw),
    'estimate_delays': lambda **kw: ltp.estimate_delays(H_DATA, G_DATA, **kw),
    'fdsubspace': lambda **kw: ltp.fdsubspace(1 / (1j * OMEGA + 1), OMEGA, 1, **kw),
    'hybrid_ls': lambda **kw: ltp.hybrid_ls(T_LS, np.sin(6 * np.pi * T_LS),
                                            np.cos(6 * np.pi * T_LS), T, [0.0], 0, **kw),
    'refine_ltp': lambda **kw: ltp.refine_ltp(
        ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=T), H_DATA, **kw),
    # public methods with **kwargs
    'LTPStateSpace.to_ss': lambda **kw: ltp.ltpss(ct.rss(1, 1, 1), T).to_ss(**kw),
    'LTPStateSpace.linearize': lambda **kw: SYS.linearize(0.1, **kw),
    'LTPStateSpace.average': lambda **kw: SYS.average(**kw),
    'LTPStateSpace.monodromy': lambda **kw: SYS.monodromy(**kw),
    'LTPStateSpace.floquet_multipliers': lambda **kw: SYS.floquet_multipliers(**kw),
    'LTPStateSpace.floquet_exponents': lambda **kw: SYS.floquet_exponents(**kw),
    'LTPStateSpace.is_stable': lambda **kw: SYS.is_stable(**kw),
    'LTPStateSpace.htf': lambda **kw: SYS.htf(1, **kw),
    'LTPStateSpace.sample': lambda **kw: SYS.sample(0.1, **kw),
    'HTF.plot': lambda **kw: H.plot(omega_num=5, **kw),
    'RotorStateSpace': lambda **kw: ltp.RotorStateSpace(
        ltp.PeriodicMatrix.constant([[-1.0]], T), [[1.0]], [[1.0]], [[0.0]], T, **kw),
    'RotorStateSpace.average': lambda **kw: ltp.RotorStateSpace(
        ltp.PeriodicMatrix.constant([[-1.0]], T), [[1.0]], [[1.0]], [[0.0]], T).average(**kw),
    'HarmonicNyquistResponse.plot': lambda **kw: ltp.nyquist_htf(
        ltp.ltpss(ct.tf([2], [1, 1]), period=0.2), 2).plot(**kw),
    # feedback around orbits
    'closed_loop_response': lambda **kw: ltp.closed_loop_response(
        FORCED, ct.ss([], [], [], [[-1.0]]), ltp.periodic_orbit(FORCED, T, [0.0]), [0, 0.5],
        **kw),
    'closed_loop_orbit': lambda **kw: ltp.closed_loop_orbit(
        FORCED, ct.ss([], [], [], [[-1.0]]), ltp.periodic_orbit(FORCED, T, [0.0]), **kw),
    'identify_arx': lambda **kw: ltp.identify_arx(DATA, T, 1, 1, ridge=1e-6, **kw),
    'compare_ltp': lambda **kw: ltp.compare_ltp(SYS, SYS, [1.0], **kw),
    'select_structure': lambda **kw: ltp.select_structure(ltp.lifted_frequency_response(
        _SINE_RESPONSE, 0.5, 1, transient=6.0), 0.5, [1], [0], **kw),
}

# autonomous plants: limit cycles, return maps, continuation
_OSC = ct.nlsys(lambda t, x, u, p: [p['a'] * x[0] * (1 - x[0] ** 2 - x[1] ** 2) - x[1],
                                    p['a'] * x[1] * (1 - x[0] ** 2 - x[1] ** 2) + x[0]],
                None, states=2, inputs=0, params={'a': 0.5}, name='oscillator')
KWARG_CALLS.update({
    'limit_cycle': lambda **kw: ltp.limit_cycle(_OSC, 6.3, [1.0, 0.0], npoints=4, **kw),
    'poincare_map': lambda **kw: ltp.poincare_map(_OSC, [1.0, 0.0], **kw),
    'orbit_continuation': lambda **kw: ltp.orbit_continuation(
        ltp.limit_cycle(_OSC, 6.3, [1.0, 0.0], npoints=4), 'a', [0.5], **kw),
})

# plotting functions hand **kwargs to matplotlib, whose error is AttributeError
_MATPLOTLIB_KWARGS = {'bode_htf', 'HTF.plot', 'HarmonicNyquistResponse.plot'}
# sampled-data loops
KWARG_CALLS['LiftedNyquistResponse.plot'] = lambda **kw: ltp.lifted_nyquist(
    ltp.ltpss(ct.ss(ct.tf([0.5], [1, 0.5], 0.1)), period=0.2)).plot(**kw)
_MATPLOTLIB_KWARGS |= {'LiftedNyquistResponse.plot'}


def _accepts_var_keyword(func):
    try:
        sig = inspect.signature(func)
    except (TypeError, ValueError):
        return False
    return any(p.kind is p.VAR_KEYWORD for p in sig.parameters.values())


def _public_callables():
    """(qualified name, callable) for public names and their public methods."""
    out = []
    for name, obj in PUBLIC.items():
        out.append((name, obj))
        if inspect.isclass(obj):
            for attr, value in vars(obj).items():
                if attr.startswith('_') or isinstance(value, property):
                    continue
                member = getattr(obj, attr)
                if callable(member):
                    out.append((f"{name}.{attr}", member))
    return out


# abstract interfaces: calling them raises a pointer to their factories
_ABSTRACT = {'HTF'}


def test_kwarg_table_covers_every_var_keyword_callable():
    missing = [name for name, func in _public_callables()
               if _accepts_var_keyword(func) and name not in KWARG_CALLS
               and name not in _ABSTRACT]
    assert not missing, f"add a minimal call to KWARG_CALLS for {missing}"
    stale = [name for name in KWARG_CALLS
             if name not in dict(_public_callables())]
    assert not stale, f"KWARG_CALLS lists names that are not public: {stale}"


@pytest.mark.parametrize('name', sorted(KWARG_CALLS))
def test_minimal_call_is_valid(name):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        result = KWARG_CALLS[name]()
    assert result is not None


@pytest.mark.parametrize('name', sorted(KWARG_CALLS))
def test_unknown_keyword_is_rejected(name):
    allowed = (TypeError, AttributeError) if name in _MATPLOTLIB_KWARGS else TypeError
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        with pytest.raises(allowed, match=r"unknown_keyword_xyz|unrecognized|unexpected"):
            KWARG_CALLS[name](unknown_keyword_xyz=1)


#
# Docstrings
#

# result containers document their fields under Attributes, not Parameters
_RESULT_CLASSES = {'Excitation', 'HTFFit', 'DelayEstimate', 'FDSubspaceInfo',
                   'PeriodicOrbit', 'FloquetRealization', 'MatrixErrors', 'LTPSubspaceInfo',
                   'LTPComparison', 'StructureSelection'}
_RESULT_CLASSES |= {'ClosedLoopOrbit'}
_RESULT_CLASSES |= {'OrbitBranch', 'Bifurcation'}
_RESULT_CLASSES |= {'LMIDesign'}
_RESULT_CLASSES |= {'RefineInfo', 'MonteCarloResult'}
_RESULT_CLASSES |= {'HTFEstimateInfo', 'ARXInfo', 'HTFFitInfo'}
_RESULT_CLASSES |= {'FloquetModes', 'CampbellDiagram'}
_RESULT_CLASSES |= {'HarmonicNyquistResponse', 'HarmonicMargins', 'MarginPoint'}
_RESULT_CLASSES |= {'DelayMonodromy', 'StabilityChart'}
_RESULT_CLASSES |= {'HarmonicModes'}
_RESULT_CLASSES |= {'OutputFeedbackResult'}
_RESULT_CLASSES |= {'LTPValidation'}
_RESULT_CLASSES |= {'SampledNyquistResponse', 'LiftedNyquistResponse'}
_RESULT_CLASSES |= {'HinfStateFeedbackResult'}

DOC_DEFECTS = {}


def _doc(obj):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')     # numpydoc warns about unknown sections
        return ClassDoc(obj) if inspect.isclass(obj) else FunctionDoc(obj)


def _names(entries):
    """Parameter names of numpydoc entries; 'A, B' is split, stars dropped."""
    out = set()
    for entry in entries:
        for name in entry.name.split(','):
            name = name.strip().lstrip('*')
            if name:
                out.add(name)
    return out


def _doc_params(name):
    marks = ()
    if name in DOC_DEFECTS:
        marks = pytest.mark.xfail(strict=True, reason=DOC_DEFECTS[name])
    return pytest.param(name, id=name, marks=marks)


@pytest.mark.parametrize('name', [_doc_params(n) for n in ltp.__all__])
def test_docstring_summary_and_examples(name):
    obj = PUBLIC[name]
    assert inspect.getdoc(obj), f"{name} has no docstring"
    doc = _doc(obj)
    summary = ' '.join(doc['Summary']).strip()
    assert summary, f"{name}: no summary line"
    assert len(doc['Summary']) == 1, f"{name}: the summary must be one line"
    examples = '\n'.join(doc['Examples'])
    assert '>>>' in examples, f"{name}: no Examples section with >>>"


def parameter_problems(obj):
    """Mismatches between the documented parameters of `obj` and its signature."""
    doc = _doc(obj)
    documented = _names(doc['Parameters']) | _names(doc['Other Parameters'])
    params = list(inspect.signature(obj).parameters.values())
    if params and params[0].name in ('self', 'cls'):
        params = params[1:]
    named = [p.name for p in params if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
    has_var = any(p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD) for p in params)
    problems = []
    undocumented = set(named) - documented
    if undocumented:
        problems.append(f"parameters {sorted(undocumented)} are not documented")
    extra = documented - set(named) - {p.name for p in params}
    if extra and not has_var:
        problems.append(f"documents {sorted(extra)}, which are not parameters")
    # documented explicit parameters appear in signature order
    listed = []
    for entry in list(doc['Parameters']) + list(doc['Other Parameters']):
        for item in entry.name.split(','):
            item = item.strip().lstrip('*')
            if item in named and item not in listed:
                listed.append(item)
    order = [n for n in named if n in documented]
    if listed != order:
        problems.append(f"documented order {listed} differs from the signature {order}")
    return problems


@pytest.mark.parametrize('name', [n for n in ltp.__all__ if n not in _RESULT_CLASSES])
def test_documented_parameters_match_signature(name):
    problems = parameter_problems(PUBLIC[name])
    assert not problems, f"{name}: " + "; ".join(problems)


def test_parameter_checker_detects_mismatches():
    def documented_wrongly(a, b, c=1):
        """Summary.

        Parameters
        ----------
        b : int
            Second.
        a : int
            First.
        d : int
            Not a parameter.
        """
    problems = ' '.join(parameter_problems(documented_wrongly))
    assert "['c'] are not documented" in problems
    assert "['d']" in problems
    assert "order" in problems


@pytest.mark.parametrize('name', sorted(_RESULT_CLASSES - {'PeriodicOrbit'}))
def test_result_fields_are_documented(name):
    obj = PUBLIC[name]
    fields = getattr(obj, '_fields', None) or list(obj.__dataclass_fields__)
    documented = _names(_doc(obj)['Attributes'])
    assert set(fields) <= documented, f"{name}: fields {set(fields) - documented} undocumented"


def test_public_methods_have_summaries():
    missing = []
    for name, member in _public_callables():
        if '.' not in name or name.startswith('Excitation.'):
            continue
        doc = inspect.getdoc(member)
        if not doc or not doc.strip().split('\n')[0]:
            missing.append(name)
    assert not missing, f"public methods without a docstring summary: {missing}"


#
# Warnings as errors on well-posed inputs
#

def _representative_slice():
    sys = mathieu()
    t = np.arange(0, 2, 0.01)
    u = np.sin(5 * t)
    ltp.forced_response(sys, t, u)
    ltp.step_response(sys, 1.0)
    ltp.initial_response(sys, 1.0, [1.0, 0.0])
    ltp.impulse_response(sys, 1.0)
    ltp.series(sys, ct.tf([1], [1, 2]))
    ltp.feedback(sys, 0.5)
    (sys + sys) * 2.0
    mu = ltp.floquet_multipliers(damped_mathieu())
    assert np.all(np.abs(mu) < 1)
    ltp.floquet_exponents(sys), ltp.monodromy(sys), ltp.is_stable(sys)
    ltp.floquet_transform(sys)
    H = ltp.htf(sys, 2)
    H(0.5j), H.components([1.0, 2.0]), H.to_frd([1.0]), H.predict(t[:100], u[:100])
    ltp.htf(damped_mathieu(), 1)
    ltp.bode_htf(H, omega_num=20)
    ltp.htf_map_plot(H, 1.0)
    sysd = ltp.sample_system(sys, 0.05)
    ltp.sample_system(sys, 0.05, 'tustin', prewarp_frequency=3.0)
    ltp.d2c(ltp.sample_system(sys, 0.05, 'tustin'))
    ltp.lift(sysd), ltp.lift(sysd, method='time'), ltp.htf(sysd, 2)
    ltp.forced_response(sysd, np.arange(40) * 0.05, np.ones(40))
    ltp.simulate_hybrid(BALL, np.linspace(0, 0.6, 61), [1.0, 0.0])
    orbit = ltp.periodic_orbit(FORCED, T, [0.0], npoints=16)
    ltp.linearize_orbit(FORCED, orbit)
    exc = ltp.chirp_replicas(T, 6, 8.0, 0.1, 20.0, dt=0.01)
    y = (1 + np.cos(2 * np.pi * exc.time)) * exc.inputs
    est = ltp.estimate_htf((exc.time, exc.inputs, y), T, 1, segments=exc.segments)
    ltp.fit_htf(_model, est, [1.0], harmonics=[0])
    ltp.estimate_delays(H_DATA, G_DATA)
    ltp.multisine(('band', 1.0, 10.0), T, dt=0.01, nperiods=4, nexperiments=3)
    ltp.sine_experiments([1.3, 2.2], 2 * np.pi, dt=np.pi / 50, nperiods=4, settle=2)
    ltp.e_rms(u, 1.01 * u), ltp.nrmse(u, 1.01 * u)
    G = ct.ss([[0.6, 0.3], [-0.3, 0.6]], [[1.0], [0.0]], [[1.0, 1.0]], [[0.5]], 0.1)
    ltp.fdsubspace(ct.frd(G, np.linspace(0.5, 30, 30)))
    ltp.hybrid_ls(T_LS, np.sin(6 * np.pi * T_LS), np.cos(6 * np.pi * T_LS), T, [0.0],
                  0, nshifts=1)


def test_representative_slice_emits_no_warnings():
    _representative_slice()                  # first run: lazy imports settle
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        _representative_slice()
    assert [str(w.message) for w in caught] == []
