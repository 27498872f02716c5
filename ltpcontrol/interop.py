"""The python-control bridge: python-control's entry points on LTP systems.

An `LTPStateSpace` is a `control.NonlinearIOSystem`.  Many python-control
functions already reach ltpcontrol through the system's own methods and
operators (``sys.sample``, ``sys.poles``, ``sys.zeros``, ``sys.dcgain``,
``sys.frequency_response``, ``sys(s)``, ``sys * other``, ``sys + other``,
``sys.feedback``), so they need nothing here.  The others would treat the
system as a generic nonlinear system (an ODE solver at default tolerances)
or fail deep inside with an unrelated message.  The bridge wraps only those
entry points (`BRIDGED`) with a dispatcher: a call that involves no
`LTPStateSpace` (or `PeriodicMatrix`) goes to python-control unchanged; a
call that does is

* routed to ltpcontrol's exact algorithm with python-control's arguments
  (time responses, block diagrams whose first block is not LTP,
  analysis and design), or
* refused with a `control.exception.ControlArgument` whose text comes from
  the one table `REFUSALS` and names the ltpcontrol way.

The bridge is on after ``import ltpcontrol`` (``ltp.config.defaults
['interop.enabled']``, default True).  `enable` and `disable` install and
remove the dispatchers (`disable` leaves python-control exactly as it is
without ltpcontrol); both also work as context managers.  The config key
turns installed dispatchers into pass-throughs while it is False.
"""

import functools
import inspect
import sys as _sys

import numpy as np
import control as ct
from control.exception import ControlArgument

from . import config
from ._analysis import design, lyapunov, norms, place, reduction
from ._core import interconnect, ltpsys, timeresp
from ._core.ltpsys import LTPStateSpace
from ._core.periodic_matrix import PeriodicMatrix
from ._core.refusals import REFUSED, refusal, refusal_error as _refusal  # noqa: F401

__all__ = ['enable', 'disable', 'is_enabled', 'original', 'refusal', 'BRIDGED', 'REFUSALS']

#: Every refusal text (python-control name -> what to use instead) is in one
#: table, ``ltpcontrol._core.refusals.REFUSED``, shared with the system's methods.
REFUSALS = REFUSED


def _matrix_refusal(name):
    return ControlArgument(f"{name} does not apply to a time-periodic matrix "
                           f"(PeriodicMatrix): use {REFUSALS[name]}")


#: ltpcontrol's functions that python-control's entry points reach, by name
_PUBLIC = {name: getattr(module, name)
           for module in (timeresp, ltpsys, interconnect, norms, lyapunov, design, place,
                          reduction)
           for name in module.__all__}


def _ltp_function(name):
    return _PUBLIC[name]


def _is_ltp(obj):
    return isinstance(obj, LTPStateSpace) or (
        isinstance(obj, (list, tuple)) and any(isinstance(o, LTPStateSpace) for o in obj))


def _involves(args, kwargs, test):
    return any(test(a) for a in args) or any(test(v) for v in kwargs.values())


#
# Time responses: python-control's arguments, ltpcontrol's exact simulation
#

#: python-control's keyword aliases of the time responses (documented in
#: `control.forced_response`): alias -> parameter
_TIME_ALIASES = {'T': 'timepts', 'U': 'inputs', 'u': 'inputs', 'X0': 'initial_state',
                 'x0': 'initial_state', 'return_x': 'return_states', 'T_num': 'timepts_num',
                 't_eval': 'evaluation_times', 'input': 'input_indices',
                 'output': 'output_indices'}


def _time_response(name):
    def route(orig, *args, **kwargs):
        for alias in [k for k in kwargs if k in _TIME_ALIASES]:
            key = _TIME_ALIASES[alias]
            if key in kwargs:
                raise ControlArgument(f"{name}: {key} given twice (as {key} and {alias})")
            kwargs[key] = kwargs.pop(alias)
        try:
            bound = inspect.signature(orig).bind(*args, **kwargs)
        except TypeError as exc:
            raise TypeError(f"{name}: {exc}") from None
        arg = dict(bound.arguments)
        arg.update(arg.pop('kwargs', {}))
        sysdata = arg.pop('sysdata') if 'sysdata' in arg else arg.pop('sys')
        if isinstance(sysdata, (list, tuple)):
            return ct.TimeResponseList([
                _simulate(name, s, dict(arg)) if isinstance(s, LTPStateSpace)
                else orig(s, **arg) for s in sysdata])
        return _simulate(name, sysdata, arg)
    return route


def _simulate(name, sys, arg):
    if arg.pop('params', None):
        raise ControlArgument(f"{name}: an LTPStateSpace has no parameters (params)")
    if arg.pop('interpolate', False):
        raise ControlArgument(f"{name}: interpolate=True is not supported for an "
                              "LTPStateSpace; give the input on the output time grid")
    num = arg.pop('timepts_num', None)
    if num is not None:
        if arg.get('timepts') is None or np.ndim(arg['timepts']) != 0:
            raise ControlArgument(f"{name}: give timepts (a final time) with "
                                  "timepts_num for an LTPStateSpace")
        arg['timepts'] = np.linspace(0, arg['timepts'], int(num))
    if name == 'input_output_response':
        # an exact simulation: the ODE solver's settings do not apply
        for key in ('ignore_errors', 'solve_ivp_kwargs', 'solve_ivp_method', 'method'):
            arg.pop(key, None)
        times = arg.pop('evaluation_times', 'T')
        if not (isinstance(times, str) and times == 'T'):
            raise ControlArgument("input_output_response: an LTPStateSpace is evaluated at "
                                  "timepts (evaluation_times='T')")
        name = 'forced_response'
    if arg.get('return_states') is None:
        arg['return_states'] = bool(ct.config.defaults.get(f'{name}.return_x', False))
    return _ltp_function(name)(sys, **arg)


#
# Block diagrams whose first block python-control handles itself
#

def _supported_block(obj):
    return isinstance(obj, (LTPStateSpace, ct.StateSpace, ct.TransferFunction,
                            PeriodicMatrix, int, float, np.number, np.ndarray, list))


def _blocks(name):
    def route(orig, *args, **kwargs):
        systems = list(args[0]) if name == 'interconnect' else list(args[:2])
        if not all(_supported_block(s) for s in systems):
            return orig(*args, **kwargs)        # a nonlinear block: python-control's system
        return _ltp_function(name)(*args, **kwargs)
    return route


#
# Analysis and design: python-control's calling conventions, ltpcontrol's functions
#

def _keywords(name, kwargs, accepted=(), ignored=()):
    """Drop keywords without effect on the exact answer; refuse the others by name."""
    for key in ignored:
        kwargs.pop(key, None)
    extra = set(kwargs) - set(accepted)
    if extra:
        raise ControlArgument(f"{name}: keyword(s) {sorted(extra)} are not supported for "
                              f"a linear time-periodic system; see ltp.{name}")
    return kwargs


def _method_none(name, kwargs):
    method = kwargs.pop('method', None)
    if method not in (None, 'slycot', 'scipy'):
        raise ControlArgument(f"{name}: unknown method {method!r}")


def _route_lqr(orig, sys, *args, **kwargs):
    _method_none('lqr', kwargs)
    return _ltp_function('lqr')(sys, *args, **_keywords('lqr', kwargs, ('integral_action',)))


def _route_dlqr(orig, sys, *args, **kwargs):
    _method_none('dlqr', kwargs)
    return _ltp_function('dlqr')(sys, *args, **_keywords('dlqr', kwargs, ('integral_action',)))


def _route_lqe(orig, sys, *args, **kwargs):
    _method_none('lqe', kwargs)
    return _ltp_function('lqe')(sys, *args, **_keywords('lqe', kwargs))


def _route_dlqe(orig, sys, *args, **kwargs):
    _method_none('dlqe', kwargs)
    return _ltp_function('dlqe')(sys, *args, **_keywords('dlqe', kwargs))


def _route_minreal(orig, sys, tol=None, verbose=True):
    # python-control's default verbose=True prints the number of removed states
    return _ltp_function('minreal')(sys, tol, verbose=verbose)


def _route_balred(orig, sys, orders, method='truncate', alpha=None):
    if alpha is not None:
        raise ControlArgument("balanced_reduction: alpha (a stability boundary shift) is "
                              "not supported for a linear time-periodic system")
    return _ltp_function('balred')(sys, orders, method=method)


def _route_hsvd(orig, sys):
    hsv = _ltp_function('hsvd')(sys)
    return hsv[0] if len(hsv) == 1 else hsv      # one vector for constant matrices


def _route_place(name):
    def route(orig, A, B, p, *args, **kwargs):
        # python-control's (A, B, p): the LTP plant takes the place of A (B may be None)
        if not isinstance(A, LTPStateSpace):
            raise _refusal(name, "ltp.place(sys, p) with the plant as an LTPStateSpace "
                           "(the first argument)")
        if B is not None:
            raise ControlArgument(f"{name}: give the LTPStateSpace as A and B=None "
                                  "(the plant holds its input matrix)")
        if args or kwargs.get('dtime') or kwargs.get('alpha') is not None:
            raise ControlArgument(f"{name}: dtime and alpha are not supported for a "
                                  "linear time-periodic system; see ltp.place")
        return _ltp_function('place')(A, p)
    return route


def _route_gram(orig, sys, type):
    return _ltp_function('gram')(sys, type)


def _route_norm(orig, system, p=2, tol=1e-6, print_warning=True, method=None):
    return _ltp_function('norm')(system, p, tol, print_warning, method)


def _route_linfnorm(orig, sys, tol=1e-10):
    # python-control returns (peak gain, peak frequency)
    return _ltp_function('norm')(sys, 'inf', tol=tol, return_frequency=True)


#: python-control name -> router ``route(original, *args, **kwargs)`` for
#: calls that involve an LTPStateSpace.  Each of these entry points would
#: otherwise simulate the system with an ODE solver, return a nonlinear
#: interconnection, or fail with an unrelated message.
ROUTES = {
    'forced_response': _time_response('forced_response'),
    'step_response': _time_response('step_response'),
    'initial_response': _time_response('initial_response'),
    'impulse_response': _time_response('impulse_response'),
    'input_output_response': _time_response('input_output_response'),
    'feedback': _blocks('feedback'),
    'append': _blocks('append'),
    'interconnect': _blocks('interconnect'),
    'lqr': _route_lqr, 'dlqr': _route_dlqr, 'lqe': _route_lqe, 'dlqe': _route_dlqe,
    'gram': _route_gram,
    'norm': _route_norm,
    'linfnorm': _route_linfnorm,
    'minreal': _route_minreal,
    'hankel_singular_values': _route_hsvd,
    'balanced_reduction': _route_balred,
    'place': _route_place('place'),
    'place_varga': _route_place('place_varga'),
    'acker': _route_place('acker'),
    'place_acker': _route_place('place_acker'),
}

#: python-control names refused for an LTPStateSpace argument (not reached
#: through a method of the system)
_REFUSED_SYS = ('bode_plot', 'nyquist_plot', 'nyquist_response', 'nichols_plot',
                'singular_values_plot', 'margin', 'stability_margins', 'disk_margins',
                'bandwidth', 'damp',
                'root_locus_map', 'root_locus_plot', 'step_info', 'similarity_transform',
                'canonical_form', 'reachable_form', 'observable_form', 'modal_form',
                'ss', 'tf', 'ss2tf', 'tf2ss', 'mixsyn', 'h2syn', 'hinfsyn', 'augw',
                'find_operating_point', 'create_statefbk_iosystem',
                'create_estimator_iosystem', 'describing_function_response', 'lyap',
                'pole_zero_plot', 'phase_crossover_frequencies', 'phase_plane_plot',
                'phase_plot', 'frd', 'nlsys', 'ssdata', 'tfdata', 'split_tf', 'bdschur',
                'model_reduction', 'ispassive', 'solve_passivity_LMI', 'get_input_ff_index',
                'get_output_fb_index', 'dlyap', 'ctrb', 'obsv', 'care', 'dare')

#: python-control functions of matrices refused for a PeriodicMatrix argument
_MATRIX_REFUSED = ('lyap', 'dlyap', 'care', 'dare', 'lqr', 'dlqr', 'lqe', 'dlqe', 'place',
                   'place_acker', 'place_varga', 'acker', 'ctrb', 'obsv',
                   'create_statefbk_iosystem')

#: Every wrapped python-control name (the bridge's whole footprint).
BRIDGED = tuple(sorted(set(ROUTES) | set(_REFUSED_SYS) | set(_MATRIX_REFUSED)))


def _dispatcher(orig, name):
    route = ROUTES.get(name)
    refuse_sys = name in _REFUSED_SYS
    refuse_matrix = name in _MATRIX_REFUSED

    @functools.wraps(orig)
    def dispatcher(*args, **kwargs):
        if config.defaults['interop.enabled']:
            if _involves(args, kwargs, _is_ltp):
                if route is not None:
                    return route(orig, *args, **kwargs)
                if refuse_sys:
                    raise refusal(name)
            if refuse_matrix and _involves(args, kwargs,
                                           lambda a: isinstance(a, PeriodicMatrix)):
                raise _matrix_refusal(name)
        return orig(*args, **kwargs)
    dispatcher._ltp_bridge = name
    return dispatcher


#
# Installation
#

_originals = {}           # name -> python-control's function
_installed = {}           # name -> dispatcher
_cache = {}               # name -> dispatcher (the same object on every enable)


def _control_modules():
    return [m for n, m in list(_sys.modules.items())
            if m is not None and (n == 'control' or n.startswith('control.'))]


def _rebind(old, new):
    """Replace `old` by `new` wherever a python-control module holds it."""
    for mod in _control_modules():
        for attr, value in list(vars(mod).items()):
            if value is old:
                setattr(mod, attr, new)


class _Switch:
    """Return value of `enable`/`disable`: a context manager that restores the
    previous state on exit (the switch itself happens at the call)."""

    def __init__(self, previous):
        self.previous = previous

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        (enable if self.previous else disable)()
        return False

    def __repr__(self):
        return f"<ltpcontrol.interop: enabled={is_enabled()}>"


def enable():
    """Route python-control's entry points for LTP systems to ltpcontrol.

    Installs a dispatcher for each name in ``BRIDGED`` wherever a python-control
    module holds the function (including aliases such as ``bode`` and the
    defining module, so internal calls between python-control modules see
    it), and sets ``ltp.config.defaults['interop.enabled'] = True``.  Calls
    without an LTP system go to python-control unchanged.  Idempotent.

    Returns
    -------
    switch : context manager
        Restores the previous state when used in a ``with`` statement.

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> with ltp.interop.disable():
    ...     ltp.interop.is_enabled()
    False
    >>> ltp.interop.is_enabled()
    True
    >>> float(ct.forced_response(sys, [0, 1], [1, 1]).outputs[-1])  # doctest: +ELLIPSIS
    0.632120558...
    """
    previous = is_enabled()
    for name in BRIDGED:
        if name in _installed:
            continue
        orig = getattr(ct, name, None)
        if orig is None or hasattr(orig, '_ltp_bridge'):     # absent, or an alias
            continue
        wrapped = _cache.setdefault(name, _dispatcher(orig, name))
        _originals[name], _installed[name] = orig, wrapped
        _rebind(orig, wrapped)
    config.defaults['interop.enabled'] = True
    return _Switch(previous)


def disable():
    """Remove the bridge: python-control is exactly as without ltpcontrol.

    python-control then treats an `ltpcontrol.LTPStateSpace` as a generic nonlinear
    system: its time responses come from python-control's ODE solver, and
    the system warns that they are not ltpcontrol's exact simulation.

    Returns
    -------
    switch : context manager
        Restores the previous state when used in a ``with`` statement.

    Examples
    --------
    >>> switch = ltp.interop.disable()
    >>> hasattr(ct.forced_response, '_ltp_bridge')
    False
    >>> _ = ltp.interop.enable()
    >>> ct.forced_response._ltp_bridge
    'forced_response'
    """
    previous = is_enabled()
    for name in list(_installed):
        _rebind(_installed.pop(name), _originals.pop(name))
    config.defaults['interop.enabled'] = False
    return _Switch(previous)


def is_enabled():
    """True when the dispatchers are installed and ``interop.enabled`` is set.

    Examples
    --------
    >>> ltp.interop.is_enabled()
    True
    """
    return bool(_installed) and bool(config.defaults['interop.enabled'])


def original(name):
    """python-control's own function behind a bridged entry point.

    Examples
    --------
    >>> from ltpcontrol.interop import original
    >>> original('dcgain') is ct.dcgain
    True
    >>> original('forced_response') is ct.forced_response.__wrapped__
    True
    """
    fn = getattr(ct, name)
    return fn.__wrapped__ if hasattr(fn, '_ltp_bridge') else fn
