"""Input checks shared by every public entry point.

Each helper raises python-control's exceptions (`ControlDimension` is a
`ValueError`, `ControlArgument` a `TypeError`) or a builtin with a message
that names the offending argument.
"""

import numbers

import numpy as np
from control.exception import ControlArgument, ControlDimension

__all__ = []


def check_kwargs(kwargs, where):
    """Reject leftover keyword arguments, as python-control does.

    Examples
    --------
    >>> from ltpcontrol._validation import check_kwargs
    >>> check_kwargs({'colour': 1}, 'plot')
    Traceback (most recent call last):
    ...
    TypeError: plot: unrecognized keyword(s): ['colour']
    """
    if kwargs:
        raise TypeError(f"{where}: unrecognized keyword(s): {sorted(kwargs)}")


def check_period(period, name="period"):
    """Return `period` as a positive finite float.

    Examples
    --------
    >>> from ltpcontrol._validation import check_period
    >>> check_period(2)
    2.0
    """
    if isinstance(period, (bool, np.bool_)) or not isinstance(
            period, (numbers.Real, np.floating, np.integer)):
        raise ControlArgument(f"{name} must be a real number, got {period!r}")
    period = float(period)
    if not np.isfinite(period) or period <= 0:
        raise ValueError(f"{name} must be positive and finite, got {period}")
    return period


def check_positive_int(value, name, minimum=1):
    """Return `value` as an int >= `minimum`.

    Examples
    --------
    >>> from ltpcontrol._validation import check_positive_int
    >>> check_positive_int(3.0, 'nharmonics', minimum=0)
    3
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(
            value, (numbers.Integral, np.integer)):
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            value = int(value)
        else:
            raise ControlArgument(f"{name} must be an integer, got {value!r}")
    value = int(value)
    if value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value}")
    return value


def real_array(data, name, ndim=None, allow_complex=False):
    """Convert `data` to a finite float (or complex) ndarray.

    Parameters
    ----------
    data : array_like
        Data to convert.
    name : str
        Argument name used in error messages.
    ndim : int or tuple of int, optional
        Allowed numbers of dimensions.
    allow_complex : bool
        Keep complex data instead of rejecting it.

    Examples
    --------
    >>> from ltpcontrol._validation import real_array
    >>> real_array([[1, 2]], 'B', ndim=2)
    array([[1., 2.]])
    """
    try:
        arr = np.asarray(data)
    except Exception as exc:  # ragged lists and the like
        raise ControlArgument(f"{name} could not be converted to an array: {exc}")
    if arr.dtype == object:
        raise ControlArgument(f"{name} must be numeric (got a ragged or object array)")
    if arr.dtype.kind == "c":
        if not allow_complex:
            if np.all(arr.imag == 0):
                arr = arr.real
            else:
                raise ControlArgument(f"{name} must be real-valued, got complex data")
    elif arr.dtype.kind not in "biuf":
        raise ControlArgument(f"{name} must be numeric, got dtype {arr.dtype}")
    arr = arr.astype(complex if arr.dtype.kind == "c" else float)
    if ndim is not None:
        allowed = (ndim,) if isinstance(ndim, int) else tuple(ndim)
        if arr.ndim not in allowed:
            raise ControlDimension(
                f"{name} must have {' or '.join(map(str, allowed))} dimensions, "
                f"got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains NaN or inf")
    return arr


def commensurate(a, b, rtol=None, max_multiple=None):
    """Return the common period ``q a = p b`` of periods `a` and `b`.

    The ratio ``a/b`` must equal a fraction ``p/q`` in lowest terms within
    the relative tolerance `rtol`, with ``p, q <= max_multiple`` (defaults:
    ``ltp.config.defaults['period.rtol']`` and ``['period.max_multiple']``);
    otherwise the periods are taken as incommensurate and `ValueError` is
    raised.

    Examples
    --------
    >>> from ltpcontrol._validation import commensurate
    >>> commensurate(0.5, 1.5)
    1.5
    >>> commensurate(1.0, 1.5)
    3.0
    """
    from fractions import Fraction
    from .config import _get
    rtol, qmax = _get('period.rtol', rtol), _get('period.max_multiple', max_multiple)
    ratio = a / b
    frac = Fraction(ratio).limit_denominator(int(qmax))
    p, q = frac.numerator, frac.denominator
    if 1 <= p <= qmax and abs(ratio - p / q) <= rtol * ratio:
        return max(a, b) if 1 in (p, q) else q * a
    raise ValueError(f"periods {a} and {b} are incommensurate: their ratio {ratio:.12g} "
                     f"is no fraction p/q with p, q <= {qmax} (tolerance {rtol:g}; see "
                     "ltp.config.defaults['period.max_multiple'])")


def steps_per_period(period, dt, name="dt"):
    """Return ``N = period/dt`` as an int, or raise if it is not an integer.

    Examples
    --------
    >>> from ltpcontrol._validation import steps_per_period
    >>> steps_per_period(0.5, 0.01)
    50
    """
    ratio = period / dt
    nsteps = int(round(ratio))
    if nsteps < 1 or abs(ratio - nsteps) > 1e-9 * max(1.0, ratio):
        raise ValueError(f"{name}={dt} does not divide the period {period} into an "
                         f"integer number of steps (period/{name} = {ratio})")
    return nsteps
