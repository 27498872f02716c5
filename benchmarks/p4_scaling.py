"""P4: scaling of the identification routines.

``ltp.estimate_htf``: time versus record length.  The Mathieu plant (thesis
eq. 4.115, T = 0.5 s) is driven by 2K+1 = 5 time-shifted multisine
experiments (lines on the DFT grid of the window, band 0.5-40 rad/s,
random phases, 10 settling periods) sampled at 100 Hz; the window holds
P periods, P doubling over more than a decade.  The number of estimated
frequencies grows like P, so the cost is expected to grow like P log P (FFT)
and the log-log slope of time against samples should stay near 1 (target
<= 1.15).  The data are simulated (`ltp.forced_response`, 4x oversampled so
that the hold error is negligible, then decimated) outside the timing, and
every estimate is checked against the model HTF ``ltp.htf(sys, K)``
(relative error <= 1e-3).

The multisines are synthesised here by an inverse FFT of one window rather
than with ``ltp.multisine``, whose ``signal(t)`` forms an array of shape
(experiments, lines, samples), quadratic in the record length (tens of GB at
the largest size used here).

``ltp.fdsubspace``: time versus number of frequencies of the data (a
4-state, 2-input, 2-output LTI system, order given), with the fitted model
checked against the data (relative error <= 1e-8).
"""

import numpy as np

import control as ct

from _common import loglog_slope, median_time, row, timed

import ltpcontrol as ltp
from systems import mathieu

FS, K, NEXP, SETTLE, OVERSAMPLE = 100.0, 2, 5, 10, 4
BAND = (0.5, 40.0)
TOL_HTF, TOL_FDS = 1e-3, 1e-8
FULL = dict(periods=[64, 128, 256, 512, 1024, 2048, 4096], repeats=3,
            nfreq=[100, 300, 1000, 3000, 10000, 20000], fds_repeats=3)
QUICK = dict(periods=[16, 32, 64, 128], repeats=2, nfreq=[50, 100, 200, 400], fds_repeats=2)


def experiments(P, period, seed=0):
    """Time-shifted periodic multisines: t (L,), U (NEXP, L), window [start, stop)."""
    fs = FS * OVERSAMPLE
    nper = int(round(period * fs))
    nwin = P * nper
    step = 2 * np.pi / (P * period)
    bins = np.arange(int(np.ceil(BAND[0] / step)), int(np.floor(BAND[1] / step)) + 1)
    bins = bins[(2 * bins) % P != 0]                 # skip multiples of ω_p/2
    spec = np.zeros(nwin // 2 + 1, complex)
    spec[bins] = np.exp(1j * np.random.default_rng(seed).uniform(0, 2 * np.pi, bins.size))
    one = np.fft.irfft(spec, nwin)
    one /= np.abs(one).max()
    L = (SETTLE + P) * nper + 1
    idx = np.arange(L)
    shift = nper // NEXP                             # r T / R
    U = np.stack([one[(idx - r * shift) % nwin] for r in range(NEXP)])
    return idx / fs, U, (SETTLE * nper, (SETTLE + P) * nper)


def htf_data(P, sys):
    t, U, (a, b) = experiments(P, sys.period)
    resp = ltp.forced_response(sys, t, U[None])
    y = np.asarray(resp.outputs).reshape(NEXP, -1)
    d = OVERSAMPLE
    t, U, y = t[::d], U[:, ::d], y[:, ::d]
    data = [(t, U[r], y[r]) for r in range(NEXP)]
    return data, np.array([[a // d, b // d]])


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    rows = []
    # estimate_htf against record length
    sys = mathieu()
    model = ltp.htf(sys, K)
    sizes, times, errs, nfreqs = [], [], [], []
    for P in cfg['periods']:
        log(f"P4: estimate_htf, window of {P} periods")
        data, seg = htf_data(P, sys)
        el, _, H = median_time(
            lambda: ltp.estimate_htf(data, sys.period, K, segments=seg, progress=False),
            cfg['repeats'])
        w, G = H.components()
        _, Gm = model.components(w)
        errs.append(float(np.abs(G - Gm).max() / np.abs(Gm).max()))
        sizes.append(int(seg[0, 1] - seg[0, 0]))
        times.append(el)
        nfreqs.append(int(len(w)))
        del data
    slope = loglog_slope(sizes, times)
    half = len(sizes) // 2
    slope_top = loglog_slope(sizes[half:], times[half:])
    err = max(errs)
    rows.append(row(
        'P4a', f"estimate_htf vs record length {sizes[0]}..{sizes[-1]} samples x {NEXP}",
        ours='ltp.estimate_htf K=2', t_ours=times[-1], metric='slope', value=slope,
        target='<= 1.15', target_met=slope <= 1.15, err_ours=err, tol=TOL_HTF,
        checks={'estimate vs model HTF <= tol': err <= TOL_HTF},
        notes=f"log-log slope; upper half {slope_top:.3g}; t_ours at the largest size",
        extra=dict(samples=sizes, times=times, frequencies=nfreqs, errors=errs,
                   slope_upper_half=slope_top)))

    # fdsubspace against number of frequencies
    rng = np.random.default_rng(1)
    A = np.array([[-0.5, 2, 0, 0], [-2, -0.5, 0, 0], [0, 0, -1, 5], [0, 0, -5, -1.0]])
    G = ct.ss(A, rng.standard_normal((4, 2)), rng.standard_normal((2, 4)),
              rng.standard_normal((2, 2)))
    ftimes, ferrs = [], []
    for M in cfg['nfreq']:
        log(f"P4: fdsubspace, {M} frequencies")
        omega = np.logspace(-1, 2, M)
        data = ct.frd(G, omega)
        el, _, model_fd = median_time(lambda: ltp.fdsubspace(data, order=4),
                                      cfg['fds_repeats'])
        resp = model_fd(1j * omega)
        ferrs.append(float(np.abs(resp - data.frdata).max() / np.abs(data.frdata).max()))
        ftimes.append(el)
    fslope = loglog_slope(cfg['nfreq'], ftimes)
    half = len(ftimes) // 2
    fslope_top = loglog_slope(cfg['nfreq'][half:], ftimes[half:])
    ferr = max(ferrs)
    rows.append(row(
        'P4b', f"fdsubspace vs frequencies {cfg['nfreq'][0]}..{cfg['nfreq'][-1]} (2x2, n=4)",
        ours='ltp.fdsubspace order 4', t_ours=ftimes[-1], metric='slope', value=fslope,
        err_ours=ferr, tol=TOL_FDS, checks={'model vs data <= tol': ferr <= TOL_FDS},
        notes=f"log-log slope; upper half {fslope_top:.3g}; t_ours at the largest size",
        extra=dict(nfreq=cfg['nfreq'], times=ftimes, errors=ferrs,
                   slope_upper_half=fslope_top)))
    return rows
