"""Input checks shared by every public entry point.

Each helper raises python-control's exceptions (`ControlDimension` is a
`ValueError`, `ControlArgument` a `TypeError`) or a builtin with a message
that names the offending argument.  There is one helper per concept (the
system argument, which needs the system class, is checked by
``_core/coerce.py``):

- `check_period`: a period; `check_positive`: any other positive quantity
  (``dt``, ``Ts``, durations, frequencies, tolerances),
- `check_positive_int`: counts and orders,
- `real_array`: numeric arrays,
- `time_record`: a uniformly sampled time record and its signals (one tolerance,
  `TIME_RTOL`).
"""

import numbers
from fractions import Fraction

import numpy as np
from control.exception import ControlArgument, ControlDimension

from ..config import _get

__all__ = []

#: Relative deviation of the sample steps from their mean below which a time
#: vector counts as uniformly sampled.
TIME_RTOL = 1e-6


def check_kwargs(kwargs, where):
    """Reject leftover keyword arguments, as python-control does.

    Examples
    --------
    >>> from ltpcontrol._core.validation import check_kwargs
    >>> check_kwargs({'colour': 1}, 'plot')
    Traceback (most recent call last):
    ...
    TypeError: plot: unrecognized keyword(s): ['colour']
    """
    if kwargs:
        raise TypeError(f"{where}: unrecognized keyword(s): {sorted(kwargs)}")


def check_positive(value, name, below=None):
    """Return `value` as a positive finite float (less than `below` if given).

    For sample times, durations, frequencies and tolerances; periods go
    through `check_period`.

    Examples
    --------
    >>> from ltpcontrol._core.validation import check_positive
    >>> check_positive(0.01, 'dt')
    0.01
    >>> check_positive(0, 'Ts')
    Traceback (most recent call last):
    ...
    ValueError: Ts must be positive and finite, got 0.0
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(
            value, (numbers.Real, np.floating, np.integer)):
        raise ControlArgument(f"{name} must be a real number, got {value!r}")
    value = float(value)
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be positive and finite, got {value}")
    if below is not None and value >= below:
        raise ValueError(f"{name} must lie in (0, {below}), got {value}")
    return value


def check_method(method):
    """python-control's `method` keyword of its LTI solvers ('slycot' or
    'scipy'): accepted for the same calls to work; the periodic algorithms
    have no such choice.

    Examples
    --------
    >>> from ltpcontrol._core.validation import check_method
    >>> check_method('scipy')
    >>> check_method('fast')
    Traceback (most recent call last):
    ...
    control.exception.ControlArgument: method must be None, 'slycot' or 'scipy', got 'fast'
    """
    if method is not None and not (isinstance(method, str) and method in ('slycot', 'scipy')):
        raise ControlArgument(f"method must be None, 'slycot' or 'scipy', got {method!r}")


def check_period(period, name="period"):
    """Return the period `period` as a positive finite float.

    Examples
    --------
    >>> from ltpcontrol._core.validation import check_period
    >>> check_period(2)
    2.0
    """
    return check_positive(period, name)


def check_positive_int(value, name, minimum=1):
    """Return `value` as an int >= `minimum`.

    Examples
    --------
    >>> from ltpcontrol._core.validation import check_positive_int
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
    >>> from ltpcontrol._core.validation import real_array
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
    >>> from ltpcontrol._core.validation import commensurate
    >>> commensurate(0.5, 1.5)
    1.5
    >>> commensurate(1.0, 1.5)
    3.0
    """
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
    >>> from ltpcontrol._core.validation import steps_per_period
    >>> steps_per_period(0.5, 0.01)
    50
    """
    ratio = period / dt
    nsteps = int(round(ratio))
    if nsteps < 1 or abs(ratio - nsteps) > 1e-9 * max(1.0, ratio):
        raise ValueError(f"{name}={dt} does not divide the period {period} into an "
                         f"integer number of steps (period/{name} = {ratio})")
    return nsteps


def time_record(t, signals, *, tname="t", min_samples=2):
    """Parse one uniformly sampled time record.

    Parameters
    ----------
    t : array_like, shape (L,)
        Sample times, increasing and uniformly spaced to within `TIME_RTOL`
        of the mean step.
    signals : dict
        ``{name: array_like}``; each array has shape (k, L), or (L,) for one
        channel.
    tname : str
        Name of the time argument in error messages.
    min_samples : int
        Fewest samples accepted.

    Returns
    -------
    t : ndarray, shape (L,)
    dt : float
        Mean sample step ``(t[-1] - t[0]) / (L - 1)``.
    arrays : list of ndarray, each (k, L)
        The signals, in the order of `signals`.

    Examples
    --------
    >>> from ltpcontrol._core.validation import time_record
    >>> t, dt, (u,) = time_record([0.0, 0.5, 1.0], {'u': [1, 2, 3]})
    >>> dt, u.shape
    (0.5, (1, 3))
    >>> time_record([0.0, 0.5, 1.5], {'u': [1, 2, 3]})
    Traceback (most recent call last):
    ...
    ValueError: t must be increasing and uniformly spaced
    """
    t = real_array(t, tname, ndim=1)
    arrays = [np.atleast_2d(real_array(x, name, ndim=(1, 2))) for name, x in signals.items()]
    L = t.size
    for name, arr in zip(signals, arrays):
        if arr.shape[1] != L:
            raise ControlDimension(f"{name} has {arr.shape[1]} samples but {tname} has {L}")
    if L < min_samples:
        raise ValueError(f"{tname} must hold at least {min_samples} samples, got {L}")
    dt = (t[-1] - t[0]) / (L - 1) if L > 1 else 0.0
    if L > 1 and (dt <= 0 or np.max(np.abs(np.diff(t) - dt)) > TIME_RTOL * dt):
        raise ValueError(f"{tname} must be increasing and uniformly spaced")
    return t, float(dt), arrays


def as_matrix(value, name):
    """A real matrix from a scalar (1 x 1), a row (1 x n) or a matrix; `name` in errors.

    Examples
    --------
    >>> from ltpcontrol._core.validation import as_matrix
    >>> as_matrix(2.0, 'k').shape, as_matrix([1, 2], 'k').shape
    ((1, 1), (1, 2))
    >>> as_matrix([[1, np.nan]], 'k')
    Traceback (most recent call last):
    ...
    ValueError: k contains NaN or inf
    """

    arr = real_array(value, name, ndim=(0, 1, 2))
    if arr.ndim == 0:
        arr = arr.reshape(1, 1)
    elif arr.ndim == 1:
        arr = arr[np.newaxis, :]
    return arr


def index_list(spec, labels, what):
    """Indices of signals named or numbered in `spec` (a slice, a name, an index or a list).

    Examples
    --------
    >>> from ltpcontrol._core.validation import index_list
    >>> index_list(['y', 0], ['x', 'y'], 'output'), index_list(slice(1, None), ['x', 'y'], 'output')
    ([1, 0], [1])
    >>> index_list('z', ['x', 'y'], 'output')
    Traceback (most recent call last):
    ...
    ValueError: unknown output name 'z'
    """

    if isinstance(spec, slice):
        return list(range(len(labels)))[spec]
    specs = spec if isinstance(spec, (list, tuple, np.ndarray)) else [spec]
    out = []
    for s in specs:
        if isinstance(s, str):
            if s not in labels:
                raise ValueError(f"unknown {what} name {s!r}")
            out.append(labels.index(s))
        elif isinstance(s, (int, np.integer)):
            if not -len(labels) <= s < len(labels):
                raise ValueError(f"{what} index {s} out of range")
            out.append(int(s) % len(labels))
        else:
            raise ControlArgument(f"invalid {what} index {s!r}")
    return out
