"""The system argument of a public function: `as_ltp`.

An `LTPStateSpace`, or an LTI system converted when a period is given;
optionally required to be discrete or continuous time.
"""

import control as ct
from control.exception import ControlArgument

from .ltpsys import LTPStateSpace, ltpss
from .validation import check_period

__all__ = []


def as_ltp(sys, name="sys", *, period=None, discrete=None, lti_hint=None):
    """Return `sys` as an `LTPStateSpace`, or raise naming the argument.

    Parameters
    ----------
    sys : LTPStateSpace or control.StateSpace or control.TransferFunction
        The system argument.
    name : str
        Argument name used in error messages.
    period : float, optional
        If given, an LTI `sys` is converted with ``ltpss(sys, period)``;
        passing it with an `LTPStateSpace` is an error.
    discrete : bool, optional
        Require a discrete-time (True) or continuous-time (False) system.
    lti_hint : str, optional
        The python-control function to suggest when `sys` is LTI and no
        `period` is given.

    Examples
    --------
    >>> from ltpcontrol._core.coerce import as_ltp
    >>> as_ltp(ct.ss(-1, 1, 1, 0), period=2.0).period
    2.0
    >>> as_ltp(ct.ss(-1, 1, 1, 0), lti_hint='control.forced_response')
    Traceback (most recent call last):
    ...
    control.exception.ControlArgument: sys must be an LTPStateSpace; it is an LTI system: use control.forced_response, or convert it with ltpss(sys, period)
    """
    if isinstance(sys, LTPStateSpace):
        if period is not None:
            raise TypeError(f"the period is taken from the LTPStateSpace {name}; "
                            "do not pass period")
    elif isinstance(sys, (ct.StateSpace, ct.TransferFunction)):
        if period is None:
            use = f"use {lti_hint}, or " if lti_hint else ""
            raise ControlArgument(f"{name} must be an LTPStateSpace; it is an LTI system: "
                                  f"{use}convert it with ltpss(sys, period)")
        sys = ltpss(sys, check_period(period))
    else:
        raise ControlArgument(f"{name} must be an LTPStateSpace, got {type(sys).__name__}")
    if discrete is not None and sys.isdtime(strict=True) != discrete:
        kind = "discrete" if discrete else "continuous"
        raise ValueError(f"{name} must be a {kind}-time system, got a "
                         f"{'continuous' if discrete else 'discrete'}-time one")
    return sys
