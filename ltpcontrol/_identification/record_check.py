"""Held-out validation of `identify_ltp` in the time domain, on the records themselves.

The held-out NRMSE of `identify_ltp` is computed on the harmonics of the
held-out lines that the lifted data hold.  The question users ask is another
one: does the model predict a record?  Here the model identified without the
held-out lines is simulated (`ltpcontrol.forced_response`, from rest, with
the records' input hold) on the held-out experiments, the records whose
every line is held out, and compared with them sample by sample in the
analysis window.  What the harmonic figure cannot see shows up there: the
output beyond the harmonics analysed (an impact's jump), a slow transient of
the model, inputs off the DFT grid.

The noise's share is removed as for the harmonic figure.  In the window of
P periods, ω_p is P DFT bins and a line at bin l drives only the bins
``±l + mP`` and ``mP``; the mean power of the other (free) bins of the
output is the noise power per bin, and by Parseval the noise energy of the
window is that mean.  The free bins of the residual are used when they hold
less (a transient the model reproduces is not noise).  The share
``sqrt(nrmse² - noise²)`` is uncertain by about ``noise² sqrt(2/n)`` (n the
real samples or free bins behind each estimate); a disagreement with the
harmonic figure, or a share above ``validation_tol`` (then ``success`` is
False), is reported only beyond three times that.
"""

import warnings
from dataclasses import dataclass

import numpy as np

from .._core.timeresp import forced_response
from .holdout import _model_share
from .lifted_response import _analysis_window, _lines, _parse_response

__all__ = []

#: a time-domain model share this many times the harmonic one (plus a tenth of the
#: tolerance) disagrees with it
_DISAGREE = 2.0


@dataclass(frozen=True)
class RecordCheck:
    """Time-domain check of the held-out experiments (see the module notes)."""

    nrmse: float = np.nan        #: ‖ŷ - y‖ / ‖y‖ over the held-out records' windows
    noise: float = np.nan        #: the noise's NRMSE over the same samples
    error: float = np.nan        #: the model's share, sqrt(nrmse² - noise²)
    spread: float = np.nan       #: standard deviation of error² from the noise estimate
    nrecords: int = 0            #: held-out experiments simulated


def record_check(model, data, period, held_lines, *, frequencies=None, transient=None,
                 input_hold='foh'):
    """The `RecordCheck` of `model` (simulated with `input_hold`) on the experiments of
    `data` whose lines are all among `held_lines` (rad/s); ``nrecords == 0`` when
    there is none.

    Examples
    --------
    >>> from ltpcontrol._identification.record_check import record_check
    >>> sys = ltp.ltpss([[-2.0]], lambda t: np.array([[1 + 0.5 * np.cos(4 * np.pi * t)]]),
    ...                 [[1.0]], 0, period=0.5)
    >>> exc = ltp.sine_experiments([np.pi / 2, 3 * np.pi / 2], 0.5, dt=0.0125, nperiods=8,
    ...                            settle=8)
    >>> resp = ltp.forced_response(sys, exc.time, exc.inputs)
    >>> check = record_check(sys, resp, 0.5, [3 * np.pi / 2], transient=4.0,
    ...                      input_hold='foh')
    >>> check.nrecords, bool(check.nrmse < 1e-8)
    (1, True)
    """
    t, dt, u, y, _, _ = _parse_response(data)
    N = int(round(period / dt))
    tw, uw, yw = _analysis_window(t, u, y, dt, N, transient or 0.0)
    Lw = tw.size
    window = Lw * dt
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')        # identify_ltp has reported the lines
        lines = _lines(uw, frequencies, window, dt, period, skip=True)
    held_bins = np.round(np.asarray(held_lines, float) * window / (2 * np.pi)).astype(int)
    bins = [np.round(Om * window / (2 * np.pi)).astype(int) for Om in lines]
    chosen = [e for e, b in enumerate(bins) if b.size and np.all(np.isin(b, held_bins))]
    if not chosen:
        return RecordCheck()
    start = t.size - Lw
    sim = np.asarray(forced_response(model, t, u[:, chosen], input_hold=input_hold,
                                     compute_states=False).outputs)
    sim = sim.reshape(y.shape[0], len(chosen), -1)[..., start:]
    yh = yw[:, chosen]
    err = sim - yh
    ref = float(np.sum(yh ** 2))
    if not ref > 0:
        return RecordCheck(nrecords=len(chosen))
    nrmse = float(np.sqrt(np.sum(err ** 2) / ref))
    P = Lw // N
    noise_energy, nfree = 0.0, Lw
    for i, e in enumerate(chosen):
        free = _free_bins(bins[e], P, Lw)
        nfree = min(nfree, int(free.sum()))
        if not free.any():
            return RecordCheck(nrmse, nrecords=len(chosen))
        # per output: the smaller of the data's and the residual's free-bin power
        Yf = np.mean(np.abs(np.fft.fft(yh[:, i], axis=-1)[:, free]) ** 2, axis=-1)
        Ef = np.mean(np.abs(np.fft.fft(err[:, i], axis=-1)[:, free]) ** 2, axis=-1)
        noise_energy += float(np.sum(np.minimum(Yf, Ef)))
    noise = float(np.sqrt(noise_energy / ref))
    spread = noise ** 2 * np.sqrt(2.0 / max(nfree, 1) + 2.0 / err.size)
    return RecordCheck(nrmse, noise, _model_share(nrmse, noise), float(spread), len(chosen))


def _free_bins(lines, P, Lw):
    """Mask of the DFT bins (of Lw) that the response to the bins `lines` leaves free:
    all but ``±l + mP`` and ``mP`` (P bins per ω_p).

    >>> np.flatnonzero(~_free_bins(np.array([1]), 4, 12)).tolist()
    [0, 1, 3, 4, 5, 7, 8, 9, 11]
    """
    k = np.arange(Lw)
    busy = k % P == 0
    for b in np.atleast_1d(lines):
        busy |= (k - b) % P == 0
        busy |= (k + b) % P == 0
    return ~busy


def verdict(check, figure, tol):
    """``(disagrees, fails)``: the time-domain model share of `check` exceeds the
    harmonic `figure` (the held-out model error) `_DISAGREE` times (plus a tenth of
    `tol`), and it exceeds `tol`, each beyond three spreads of the noise estimate.

    >>> verdict(RecordCheck(0.2, 0.01, 0.2, 1e-6, 3), 0.01, 0.05)
    (True, True)
    >>> verdict(RecordCheck(0.2, 0.01, 0.2, 1e-6, 3), 0.18, 0.05)   # the harmonics show it
    (False, True)
    >>> verdict(RecordCheck(0.3, 0.29, 0.077, 0.01, 3), 0.06, 0.05)   # within the spread
    (False, False)
    """
    if check.nrecords == 0 or not (np.isfinite(check.error) and np.isfinite(figure)):
        return False, False
    share = check.error
    spread = 3 * (check.spread if np.isfinite(check.spread) else 0.0)
    disagrees = share > _DISAGREE * figure + tol / 10 and share ** 2 - figure ** 2 > spread
    fails = share > tol and share ** 2 - tol ** 2 > spread
    return bool(disagrees), bool(fails)
