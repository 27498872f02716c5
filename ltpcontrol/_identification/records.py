"""Identification data: one record type, one parser, one sampling tolerance, one axis order.

A record is one experiment on a uniform time grid: times ``t`` (L,), inputs
``u`` (nu, L) and outputs ``y`` (ny, L) — channels first, time last, as in
`control.TimeResponseData`.  Every identification entry point reads its
time-domain data through `as_records`, which accepts

- a `control.TimeResponseData`, however it was built (by a simulation or by
  hand, ``ct.TimeResponseData(t, y, inputs=u)``); a response with several
  traces gives one record per trace;
- a `control.TimeResponseList` (one record per response and trace);
- a tuple ``(t, u, y)`` with ``u``, ``y`` of shape (L,), (nu, L), or
  (nu, nexp, L) for nexp experiments on the same grid (one channel beside a
  3D signal may be given squeezed, (nexp, L), as python-control squeezes
  one channel with several traces);
- a list of any of these.

The sampling is checked once, with one tolerance (``TIME_RTOL`` of
``_core/validation.py``).  Errors name the argument and the record
(``data[2] time must be increasing and uniformly spaced``).
"""

from dataclasses import dataclass

import numpy as np
import control as ct
from control.exception import ControlArgument, ControlDimension

from .._core.validation import TIME_RTOL, time_record

__all__ = []


@dataclass(frozen=True)
class Record:
    """One uniformly sampled experiment: ``t`` (L,), ``u`` (nu, L), ``y`` (ny, L)."""

    t: np.ndarray
    u: np.ndarray
    y: np.ndarray
    dt: float
    input_labels: tuple | None = None
    output_labels: tuple | None = None

    @property
    def nsamples(self):
        return self.t.size

    @property
    def duration(self):
        """``L dt``: the time the record covers, one sample step per sample."""
        return self.t.size * self.dt


def as_records(data, name='data', *, min_samples=2, min_duration=None, what=None):
    """Parse identification data into a list of `Record`.

    Parameters
    ----------
    data : control.TimeResponseData, control.TimeResponseList, tuple or list
        See the module docstring.
    name : str
        The argument's name in error messages.
    min_samples : int
        Fewest samples a record may hold.
    min_duration : float, optional
        Shortest duration ``L dt`` a record may cover (a period, or a
        transient plus a period).
    what : str, optional
        What `min_duration` is, for the error message.

    Returns
    -------
    list of Record
        All with the same numbers of inputs and outputs.

    Examples
    --------
    >>> from ltpcontrol._identification.records import as_records
    >>> t = np.linspace(0, 1, 11)
    >>> r, = as_records(ct.TimeResponseData(t, np.sin(t), inputs=np.cos(t)))
    >>> r.u.shape, r.y.shape, r.dt
    ((1, 11), (1, 11), 0.1)
    >>> as_records([(t, t, t), (t[::-1], t, t)])
    Traceback (most recent call last):
    ...
    ValueError: data[1] time must be increasing and uniformly spaced
    """
    single = isinstance(data, (ct.TimeResponseData, tuple))
    items = [data] if single else data
    if isinstance(items, ct.TimeResponseList):
        items = list(items)
    if not isinstance(items, list) or not items:
        raise ControlArgument(
            f"{name} must be a control.TimeResponseData, a tuple (t, u, y) or a non-empty "
            f"list of these, got {type(data).__name__}")
    records = []
    for i, item in enumerate(items):
        where = name if single else f"{name}[{i}]"
        records.extend(_parse(item, where, min_samples))
    first = records[0]
    for k, rec in enumerate(records):
        if rec.u.shape[0] != first.u.shape[0] or rec.y.shape[0] != first.y.shape[0]:
            raise ControlDimension(
                f"{name}: every record needs the same channels; record {k} has "
                f"{rec.u.shape[0]} inputs and {rec.y.shape[0]} outputs, record 0 has "
                f"{first.u.shape[0]} and {first.y.shape[0]}")
        if min_duration is not None and rec.duration < min_duration * (1 - 1e-9):
            raise ValueError(
                f"{name}: record {k} covers {rec.duration:.6g} s, shorter than "
                f"{what or 'the shortest usable record'} ({min_duration:.6g} s)")
    return records


def refuse_ambiguous(data, name, where):
    """Raise for a tuple ``(t, u, y)`` with 2D ``(k, L)`` u and y, k > 1.

    Under the one axis order those are k channels of one experiment; entry
    points that earlier read such arrays as k experiments of one channel
    refuse them rather than misread them.

    Examples
    --------
    >>> from ltpcontrol._identification.records import refuse_ambiguous
    >>> t = np.arange(5.0)
    >>> refuse_ambiguous((t, np.ones((1, 2, 5)), np.ones((1, 2, 5))), 'data', 'f')  # 3D: clear
    >>> refuse_ambiguous((t, np.ones((2, 5)), np.ones((2, 5))), 'data', 'f')
    Traceback (most recent call last):
    ...
    control.exception.ControlDimension: f: data has inputs and outputs of shape (2, L), ...
    """
    if not (isinstance(data, tuple) and len(data) == 3):
        return
    try:
        u, y = np.asarray(data[1], dtype=float), np.asarray(data[2], dtype=float)
    except (TypeError, ValueError):          # ragged or non-numeric: as_records names it
        return
    if u.ndim == 2 and y.ndim == 2 and u.shape[0] == y.shape[0] > 1:
        k = u.shape[0]
        raise ControlDimension(
            f"{where}: {name} has inputs and outputs of shape ({k}, L), which are {k} "
            f"channels of one experiment (channels first, time last); give {k} "
            f"experiments of one channel as arrays of shape (1, {k}, L), a list of "
            "(t, u, y) records or a control.TimeResponseData with traces")


def common_grid(records, name='data'):
    """Stack records sampled on one time grid: ``t, dt, U (nu, nexp, L), Y (ny, nexp, L)``.

    Examples
    --------
    >>> from ltpcontrol._identification.records import as_records, common_grid
    >>> t = np.linspace(0, 1, 11)
    >>> t, dt, U, Y = common_grid(as_records([(t, np.ones((2, 11)), np.ones(11))] * 3))
    >>> U.shape, Y.shape
    ((2, 3, 11), (1, 3, 11))
    >>> common_grid(as_records([(t, t, t), (t + 1, t, t)]))
    Traceback (most recent call last):
    ...
    control.exception.ControlDimension: data: every experiment must share one time grid; record 1 has 11 samples from t = 1, record 0 has 11 from t = 0
    """
    t = records[0].t
    for k, rec in enumerate(records):
        if rec.t.shape != t.shape or not np.allclose(rec.t, t, rtol=0,
                                                     atol=TIME_RTOL * records[0].dt):
            raise ControlDimension(
                f"{name}: every experiment must share one time grid; record {k} has "
                f"{rec.t.size} samples from t = {rec.t[0]:.6g}, record 0 has {t.size} "
                f"from t = {t[0]:.6g}")
    U = np.stack([rec.u for rec in records], axis=1)
    Y = np.stack([rec.y for rec in records], axis=1)
    return t, records[0].dt, U, Y


def _parse(item, where, min_samples):
    """The records of one item: a response (all its traces) or a tuple."""
    if isinstance(item, ct.TimeResponseData):
        if item.u is None or np.size(item.u) == 0:
            raise ControlArgument(f"{where} carries no inputs; pass a response with inputs "
                                  "or a tuple (t, u, y)")
        t, u, y = item.time, item.u, item.y
        ulabels = tuple(item.input_labels) if item.input_labels is not None else None
        ylabels = tuple(item.output_labels) if item.output_labels is not None else None
    elif isinstance(item, tuple) and len(item) == 3:
        t, u, y = item
        ulabels = ylabels = None
    else:
        raise ControlArgument(f"{where} must be a control.TimeResponseData or a tuple "
                              f"(t, u, y), got {type(item).__name__}")
    u = _real(u, f"{where} inputs")
    y = _real(y, f"{where} outputs")
    # a single channel given squeezed, (nexp, L), beside a 3D signal (python-control's
    # squeeze of one channel with several traces)
    if np.ndim(u) == 2 and np.ndim(y) == 3 and np.shape(u)[0] == np.shape(y)[1] != 1:
        u = np.asarray(u)[None]
    if np.ndim(y) == 2 and np.ndim(u) == 3 and np.shape(y)[0] == np.shape(u)[1] != 1:
        y = np.asarray(y)[None]
    u = _channels(u, f"{where} inputs")
    y = _channels(y, f"{where} outputs")
    if u.shape[1:] != y.shape[1:]:
        raise ControlDimension(
            f"{where}: inputs {u.shape} and outputs {y.shape} must have the same "
            "experiments (axis 1) and samples (axis 2)")
    out = []
    for j in range(u.shape[1]):
        rec = where if u.shape[1] == 1 else f"{where} experiment {j}"
        tj, dt, (uj, yj) = time_record(t, {f"{rec} inputs": u[:, j], f"{rec} outputs": y[:, j]},
                                       tname=f"{rec} time", min_samples=min_samples)
        out.append(Record(tj, uj, yj, dt, ulabels, ylabels))
    return out


def _real(x, what):
    """``x`` as a float array, or a clear error for ragged or non-numeric data."""
    try:
        return np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be a real array of equal-length rows (a ragged or "
                         "non-numeric list was given)") from None


def _channels(x, what):
    """``x`` as a finite real array (channels, experiments, samples)."""
    arr = _real(x, what)
    if arr.ndim not in (1, 2, 3) or arr.size == 0:
        raise ControlDimension(f"{what} must have shape (L,), (channels, L) or "
                               f"(channels, experiments, L), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{what} must be finite (it holds NaN or inf)")
    if arr.ndim == 1:
        return arr[None, None, :]
    return arr[:, None, :] if arr.ndim == 2 else arr
