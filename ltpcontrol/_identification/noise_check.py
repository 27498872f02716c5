"""Is the content of the free DFT bins noise?  (`identify_ltp`'s noise level).

The noise level of sine records is estimated from the DFT bins of the
analysis window that the response to the experiment's lines cannot reach
(`lifted_frequency_response`).  What lands there is noise only if it is
stationary and without structure the model could owe.  Two tests on every
experiment's free bins:

* *stationarity*: the free-bin content, transformed back to time, has the
  same power in the first and the last quarter of the window (a decaying
  transient left in the window has far more power at the start);
* *no lines*: the noise estimate of an output coefficient is the mean
  power of four free bins next to it; for noise each bin holds about a
  quarter of it (the largest of four exponential variates exceeds 3/4 of
  their sum with probability 1/16), a deterministic line (nonlinear or
  event distortion, a periodic disturbance at another frequency) holds
  all of it.

A content that fails either test is no noise: `identify_ltp` then does not
subtract it from the held-out error, with a warning naming the test.

Limits: broadband stationary distortion (e.g. of impacts at instants that
drift with the excitation) passes both tests and is counted as noise; it
shows in a time-domain validation on records (`validate_ltp`).
"""

import numpy as np

#: largest power ratio of the first to the last quarter of the free-bin content
_STATIONARY_RATIO = 3.0
#: share of four-bin groups dominated (> 3/4 of their sum) by one bin above
#: which the free bins hold lines (1/16 for noise)
_LINE_SHARE = 0.3


def _free_bin_check(yw, lines, N, K, dt, nbins=4):
    """The reason why the free-bin content of the records ``yw (ny, nexp, Lw)`` (step
    `dt`, N samples per period; lines in rad/s per experiment) is not noise (a
    string), or None when it passes both tests (or cannot be tested).

    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(64 * 20)
    >>> y = np.cos(2 * np.pi * 3 * t / t.size) + 0.01 * rng.standard_normal(t.size)
    >>> line = [np.array([2 * np.pi * 3 / t.size])]
    >>> print(_free_bin_check(y[None, None], line, 64, 2, 1.0))
    None
    >>> y2 = y + 5 * np.exp(-t / 50.0)                # a transient in the window
    >>> _free_bin_check(y2[None, None], line, 64, 2, 1.0)[:28]
    'a transient (the free-bin co'
    """
    ny, nexp, Lw = yw.shape
    P = Lw // N
    harm = np.arange(-K, K + 1)
    ratios, dominated, groups = [], 0, 0
    for e, Om in enumerate(lines):
        idx = np.asarray(Om, float) * Lw * dt / (2 * np.pi)
        if not idx.size or np.any(np.abs(idx - np.round(idx)) > 1e-6):
            continue                                          # off the grid: leakage
        idx = np.round(idx).astype(int)
        occupied = np.zeros(P, bool)
        occupied[0] = True
        occupied[idx % P] = occupied[-idx % P] = True
        if occupied.all():
            continue
        spec = np.fft.fft(yw[:, e], axis=-1)
        free = ~occupied[np.arange(Lw) % P]
        r = np.fft.ifft(np.where(free, spec, 0.0), axis=-1).real
        q = Lw // 4
        first, last = np.sum(r[:, :q] ** 2), np.sum(r[:, -q:] ** 2)
        if last > 0:
            ratios.append(first / last)
        elif first > 0:
            ratios.append(np.inf)
        power = np.abs(spec) ** 2
        offsets = np.concatenate([[d, -d] for d in range(1, nbins * P + 1)])
        for res in np.unique(idx % P):
            d = offsets[~occupied[(res + offsets) % P]][:nbins]
            if d.size < nbins:
                continue
            on = idx % P == res
            bins = (idx[on, None, None] + harm[:, None] * P + d) % Lw
            pw = power[:, bins]                                   # (ny, lines, 2K+1, nbins)
            total = pw.sum(-1)
            dominated += int(np.sum(pw.max(-1) > 0.75 * total))
            groups += total.size
    if ratios and np.median(ratios) > _STATIONARY_RATIO:
        return (f"a transient (the free-bin content of the window has {np.median(ratios):.3g} "
                "times more power in its first quarter than in its last; increase "
                "transient=)")
    if groups and dominated > _LINE_SHARE * groups:
        return (f"lines, not noise (one bin dominates {dominated} of the {groups} groups "
                "of free bins next to the output frequencies: nonlinear or event "
                "distortion, or a disturbance)")
    return None
