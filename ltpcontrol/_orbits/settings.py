"""Integration settings of the hybrid integrator and of the orbit solvers' Newton steps."""

import numbers

import numpy as np
from control.exception import ControlArgument

from .._core.validation import check_positive_int

__all__ = []


def solver_settings(where, rtol=1e-10, atol=1e-12, method='DOP853', max_events=10000):
    """Checked `solve_ivp` settings of the hybrid integrator (`Flow`).

    Examples
    --------
    >>> from ltpcontrol._orbits.settings import solver_settings
    >>> solver_settings('simulate_hybrid')
    {'rtol': 1e-10, 'atol': 1e-12, 'method': 'DOP853', 'max_events': 10000}
    >>> solver_settings('simulate_hybrid', rtol=0)
    Traceback (most recent call last):
    ...
    ValueError: simulate_hybrid: rtol must be a positive number, got 0
    """
    for value, label in [(rtol, 'rtol'), (atol, 'atol')]:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real) \
                or not value > 0:
            raise ValueError(f"{where}: {label} must be a positive number, got {value!r}")
    if not isinstance(method, str):
        raise ControlArgument(f"{where}: method must be a solve_ivp method name, got {method!r}")
    return dict(rtol=float(rtol), atol=float(atol), method=method,
                max_events=check_positive_int(max_events, 'max_events'))


def newton_solver_settings(where, tol, rtol, atol, method, max_events):
    """`solver_settings` for a Newton solve to `tol`: integration tolerances below it.

    The residual of a shooting Newton iteration cannot drop below the
    integration error of the period map, so by default ``rtol = min(1e-10,
    tol/100)`` and ``atol = rtol/100``.

    Examples
    --------
    >>> from ltpcontrol._orbits.settings import newton_solver_settings
    >>> opts = newton_solver_settings('periodic_orbit', 1e-10, None, None, 'DOP853', 10)
    >>> opts['rtol'], opts['atol']
    (1e-12, 1e-14)
    """
    if rtol is None:
        valid = isinstance(tol, numbers.Real) and not isinstance(tol, bool) and 0 < tol < 1
        rtol = min(1e-10, 1e-2 * tol) if valid else 1e-12
    if atol is None and isinstance(rtol, numbers.Real) and not isinstance(rtol, bool):
        atol = 1e-2 * rtol
    return solver_settings(where, rtol, atol, method, max_events)


def inexact_options(opts, residual):
    """Integration settings for a Newton step at `residual` (inexact Newton).

    Far from the solution the period map need not be accurate to `rtol`:
    ``rtol_k = min(max(rtol, 1e-3 residual), max(rtol, 1e-8))`` (``atol``
    scaled alike), reaching the requested `rtol` as the residual falls.

    Examples
    --------
    >>> from ltpcontrol._orbits.settings import inexact_options
    >>> opts = dict(rtol=1e-12, atol=1e-14, method='DOP853', max_events=10)
    >>> inexact_options(opts, float('inf'))['rtol'], inexact_options(opts, 1e-7)['rtol']
    (1e-08, 1e-10)
    >>> inexact_options(opts, 1e-11)['atol']
    1e-14
    """
    rtol = min(max(opts['rtol'], 1e-3 * residual), max(opts['rtol'], 1e-8))
    return dict(opts, rtol=rtol, atol=opts['atol'] * rtol / opts['rtol'])
