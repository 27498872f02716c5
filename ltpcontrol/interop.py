"""python-control's entry points called on linear time-periodic systems.

python-control's functions treat an `LTPStateSpace` as a generic nonlinear
I/O system (time responses by a default-tolerance ODE solver) or fail deep
inside with an unrelated message.  At import, ltpcontrol wraps the entry
points listed below (in every python-control module that holds them) with
a thin dispatcher: a call that involves no `LTPStateSpace` goes unchanged
to python-control; a call that does is

* routed to ltpcontrol's exact algorithm with the same arguments
  (`ROUTES`), or
* routed to the same-named ltpcontrol function when it exists, and refused
  naming it otherwise (`HOOKS`: adding ``ltp.zeros`` turns ``ct.zeros``
  from an error into the exact answer with no change here), or
* refused with a `control.exception.ControlArgument` that names the
  ltpcontrol way to get the quantity (`REFUSED`).

``ct.sample_system``/``ct.c2d``, ``ct.poles`` and ``ct.linearize`` need no
wrapper: they call the system's own methods.
"""

import functools
import inspect
import sys as _sys

import numpy as np
import control as ct
from control.config import _process_kwargs
from control.exception import ControlArgument
from control.timeresp import _timeresp_aliases

from ._analysis import design, lyapunov, norms, place, reduction, zeros
from ._core import interconnect, ltpsys, timeresp
from ._core.ltpsys import LTPStateSpace
from ._core.periodic_matrix import PeriodicMatrix
from ._core.refusals import REFUSED, refusal, refusal_error as _refusal  # noqa: F401

__all__ = []


def _is_ltp(obj):
    return isinstance(obj, LTPStateSpace) or (
        isinstance(obj, (list, tuple)) and any(isinstance(o, LTPStateSpace) for o in obj))


def _involves_ltp(args, kwargs):
    return any(_is_ltp(a) for a in args) or any(_is_ltp(v) for v in kwargs.values())


#: ltpcontrol's functions that python-control's entry points reach, by name
_PUBLIC = {name: getattr(module, name)
           for module in (timeresp, ltpsys, interconnect, zeros, norms, lyapunov, design,
                          place, reduction)
           for name in module.__all__}


def _ltp_function(name):
    return _PUBLIC.get(name)


#
# Time responses: same arguments, exact LTP simulation
#

def _time_response(name):
    def route(orig, *args, **kwargs):
        _process_kwargs(kwargs, _timeresp_aliases)
        bound = inspect.signature(orig).bind(*args, **kwargs)
        arg = dict(bound.arguments)
        arg.update(arg.pop('kwargs', {}))
        sysdata = arg.pop('sysdata') if 'sysdata' in arg else arg.pop('sys')
        if isinstance(sysdata, (list, tuple)):
            return ct.TimeResponseList([_dispatch(name, orig, s, **arg) for s in sysdata])
        return _simulate(name, sysdata, arg)
    return route


def _dispatch(name, orig, sys, **arg):
    if isinstance(sys, LTPStateSpace):
        return _simulate(name, sys, dict(arg))
    return orig(sys, **arg)


def _simulate(name, sys, arg):
    if arg.pop('params', None):
        raise ControlArgument(f"{name}: an LTPStateSpace has no parameters (params)")
    if arg.pop('interpolate', False):
        raise ControlArgument(f"{name}: interpolate=True is not supported for an "
                              "LTPStateSpace; give the input on the output time grid")
    num = arg.pop('timepts_num', None)
    if num is not None:
        if arg.get('timepts') is None or np.ndim(arg['timepts']) != 0:
            raise ControlArgument(f"{name}: give timepts (a final time or a grid) with "
                                  "timepts_num for an LTPStateSpace")
        arg['timepts'] = np.linspace(0, arg['timepts'], int(num))
    if name == 'input_output_response':
        # exact simulation: solver settings do not apply
        for key in ('ignore_errors', 'solve_ivp_kwargs', 'solve_ivp_method', 'method'):
            arg.pop(key, None)
        times = arg.pop('evaluation_times', 'T')
        if not (isinstance(times, str) and times == 'T'):
            raise ControlArgument("input_output_response: an LTPStateSpace is evaluated at "
                                  "timepts (evaluation_times='T')")
        name = 'forced_response'
    ret = arg.get('return_states')
    if ret is None:
        arg['return_states'] = bool(ct.config.defaults.get(f'{name}.return_x', False))
    return _ltp_function(name)(sys, **arg)


#
# Block diagrams: LTP results for LTP, LTI and static blocks
#

def _supported_block(obj):
    return isinstance(obj, (LTPStateSpace, ct.StateSpace, ct.TransferFunction,
                            PeriodicMatrix, int, float, np.number, np.ndarray, list))


def _blocks(name):
    def route(orig, *args, **kwargs):
        systems = list(args[0]) if name == 'interconnect' else list(args)
        if not all(_supported_block(s) for s in systems):
            return orig(*args, **kwargs)        # a nonlinear block: python-control's system
        return _ltp_function(name)(*args, **kwargs)
    return route


#: python-control name -> router ``route(original, *args, **kwargs)``
ROUTES = {
    'forced_response': _time_response('forced_response'),
    'step_response': _time_response('step_response'),
    'initial_response': _time_response('initial_response'),
    'impulse_response': _time_response('impulse_response'),
    'input_output_response': _time_response('input_output_response'),
    'feedback': _blocks('feedback'),
    'series': _blocks('series'),
    'parallel': _blocks('parallel'),
    'append': _blocks('append'),
    'interconnect': _blocks('interconnect'),
}

#: python-control name -> ltpcontrol function with the same arguments (analysis,
#: synthesis, reduction), reached when this version of ltpcontrol provides it
HOOKS = {name: name for name in ('zeros', 'norm', 'lyap', 'dlyap', 'gram', 'lqr', 'dlqr',
                                 'lqe', 'dlqe', 'place', 'h2syn', 'hinfsyn', 'minreal')}
HOOKS.update(hankel_singular_values='hsvd', balanced_reduction='balred')

#: python-control functions of matrices -> the ltpcontrol way when a matrix is
#: a `PeriodicMatrix` (or, for those not hooked above, the system an LTPStateSpace)
MATRIX_REFUSED = {
    'lyap': "ltp.lyap(A, Q) for the periodic Lyapunov equation",
    'dlyap': "ltp.dlyap(A, Q) with the step matrices stacked, shape (N, n, n)",
    'care': "ltp.care(A, B, Q, R) for the periodic Riccati equation",
    'dare': "ltp.dare(A, B, Q, R) with the step matrices stacked, shape (N, ., .)",
    'lqr': "ltp.lqr(sys, Q, R) with the plant as an LTPStateSpace",
    'dlqr': "ltp.dlqr(sys, Q, R) with the plant as an LTPStateSpace",
    'lqe': "ltp.lqe(sys, QN, RN) with the plant as an LTPStateSpace",
    'dlqe': "ltp.dlqe(sys, QN, RN) with the plant as an LTPStateSpace",
    'place': "ltp.place(sys, p) with the plant as an LTPStateSpace",
    'acker': "ltp.place(sys, p) with the plant as an LTPStateSpace",
    'ctrb': "ltp.lift(sys) (the lifted LTI system's controllability)",
    'obsv': "ltp.lift(sys) (the lifted LTI system's observability)",
}


#: python-control's return convention where it differs from the ltpcontrol
#: function's: one vector of Hankel singular values for constant matrices
_ADAPT = {'hankel_singular_values': lambda hsv: hsv[0] if len(hsv) == 1 else hsv}


def _hook(name, target):
    adapt = _ADAPT.get(name, lambda result: result)

    def route(orig, *args, **kwargs):
        fn = _ltp_function(target)
        if fn is None:
            raise ControlArgument(
                f"{name} does not apply to a linear time-periodic system "
                f"(LTPStateSpace) and its periodic counterpart ltp.{target} is not "
                "available in this version of ltpcontrol")
        return adapt(fn(*args, **kwargs))
    return route


def _refuse(name, hint):
    def route(orig, *args, **kwargs):
        raise _refusal(name, hint)
    return route


def _routes():
    table = dict(ROUTES)
    table.update({name: _hook(name, target) for name, target in HOOKS.items()})
    table.update({name: _refuse(name, hint) for name, hint in REFUSED.items()})
    table.update({name: _refuse(name, hint) for name, hint in MATRIX_REFUSED.items()
                  if name not in table})
    return table


def _periodic_matrix(args, kwargs):
    return any(isinstance(a, PeriodicMatrix) for a in (*args, *kwargs.values()))


def _wrap(orig, route, matrix_hint=None, name=None):
    @functools.wraps(orig)
    def dispatcher(*args, **kwargs):
        if matrix_hint and _periodic_matrix(args, kwargs):
            raise ControlArgument(f"{name} does not apply to a time-periodic matrix "
                                  f"(PeriodicMatrix): use {matrix_hint}")
        if _involves_ltp(args, kwargs):
            return route(orig, *args, **kwargs)
        return orig(*args, **kwargs)
    dispatcher._ltp_route = route
    return dispatcher


def install():
    """Wrap python-control's entry points (idempotent).

    Every module of the ``control`` package that holds a listed function
    (including aliases such as ``bode`` for ``bode_plot``) gets the same
    dispatcher, so internal calls between python-control modules see it too.

    Examples
    --------
    Importing ltpcontrol has installed the dispatchers; installing again
    changes nothing, and LTI systems still reach python-control:

    >>> from ltpcontrol.interop import install
    >>> wrapped = ct.dcgain
    >>> install()
    >>> ct.dcgain is wrapped, hasattr(wrapped, '_ltp_route')
    (True, True)
    >>> float(ct.dcgain(ct.tf([2], [1, 1])))
    2.0
    """
    modules = [m for n, m in list(_sys.modules.items())
               if m is not None and (n == 'control' or n.startswith('control.'))]
    for name, route in _routes().items():
        orig = getattr(ct, name, None)
        if orig is None or hasattr(orig, '_ltp_route'):
            continue
        wrapped = _wrap(orig, route, MATRIX_REFUSED.get(name), name)
        for mod in modules:
            for attr, value in list(vars(mod).items()):
                if value is orig:
                    setattr(mod, attr, wrapped)


def original(name):
    """python-control's own function behind a wrapped entry point.

    Examples
    --------
    >>> from ltpcontrol.interop import original
    >>> original('dcgain') is ct.dcgain.__wrapped__, hasattr(original('dcgain'), '_ltp_route')
    (True, False)
    >>> float(original('dcgain')(ct.tf([2], [1, 1])))
    2.0
    """
    fn = getattr(ct, name)
    return getattr(fn, '__wrapped__', fn)
