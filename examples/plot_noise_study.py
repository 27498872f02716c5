"""
Maximum-likelihood refinement under noise: a Monte-Carlo study
===============================================================

The Mathieu-type plant of thesis eq. (4.115) (period T = 0.5 s) is excited
by single cosines, one per experiment, and its output is measured with
white noise at the thesis's signal-to-noise ratio SNR = (A_signal /
A_noise)² = 12.5, set per experiment.  Each of 100 noise draws (run in
parallel with `ltpcontrol.monte_carlo`) is identified two ways:

1. *subspace*: `identify_ltp` with its defaults (lifted subspace model,
   Floquet realization, structured refit of the Floquet-form model to the
   harmonic data with all lines weighted alike);
2. *ML*: `refine_ltp` started from the subspace model and weighted by the
   standard deviation of every line's harmonic response, which is
   estimated from the output DFT bins between the lines.

Because the noise is set per experiment, the lines carry very different
noise levels and the weighting matters.  The study reports the HTF error
of each model against the true plant on a dense grid (unseen frequencies),
the bias of the ML parameters relative to their standard error, the ratio
of their sample variance to the reported covariance and to the Cramér-Rao
bound of the true plant (`refine_ltp` with ``maxiter=0``).

Set ``LTP_EXAMPLES_QUICK=1`` for 24 draws and ``LTP_NOISE_SNR`` for another
signal-to-noise ratio.
"""

import os
import time
import warnings

import matplotlib.pyplot as plt
import numpy as np

import ltpcontrol as ltp
from mathieu import mathieu_ltp

QUICK = os.environ.get('LTP_EXAMPLES_QUICK', '0') == '1'
#: Worker processes of the Monte-Carlo study: one in the quick run (the documentation
#: build runs beside the test suite, where more processes only compete for the cores).
N_JOBS = 1 if QUICK else 2
T, TS, OVERSAMPLE, K = 0.5, 0.01, 4, 1
SNR = float(os.environ.get('LTP_NOISE_SNR', '12.5'))
NDRAWS = 24 if QUICK else 100
#: 60 cosines at 0.15 + 0.1 k Hz (on the 0.05 Hz grid of the 20-s window).
FREQS = 0.15 + 0.1 * np.arange(1, 61)
DURATION, TRANSIENT = 40.0, 20.0
#: Refined model structure: B with K, C with 2K, D with K harmonics.
HARMONICS = (K, 2 * K, K)

true = mathieu_ltp()

###############################################################################
# Noise-free experiments (simulated once)
# ---------------------------------------

t_fine = np.arange(int(DURATION / TS) * OVERSAMPLE) * TS / OVERSAMPLE
u = np.cos(2 * np.pi * FREQS[:, None] * t_fine[None, :])
y = np.asarray(ltp.forced_response(true, t_fine, u[None]).outputs)[:, :, ::OVERSAMPLE]
t, u = t_fine[::OVERSAMPLE], u[:, ::OVERSAMPLE]
window = t >= TRANSIENT
noise_std = np.sqrt(np.mean(y[0][:, window] ** 2, axis=1) / SNR)     # per experiment
lfr = dict(transient=TRANSIENT, input_hold='foh', hold_step=TS / OVERSAMPLE)


def line_std(yw):
    """Std of each line's harmonic response from the DFT bins between the lines.

    A real output has lines at ``±Ω + nω_p``, i.e. on the bins ``≡ ±Ω (mod
    P)`` of a window of P periods; every other bin holds noise only.  With ``Y =
    (1/L) Σ y e^{-jωt}`` a noise bin has variance ``σ²/L`` and ``G = Y/U``,
    ``U = 1/2`` for a unit cosine.
    """
    L = yw.shape[-1]
    P = int(round(L * TS / T))
    spec = np.fft.rfft(yw, axis=-1) / L
    line = np.rint(FREQS * L * TS).astype(int)
    bins = np.arange(spec.shape[-1])
    offset = bins[None, :] - line[:, None]
    noise = (offset % P != 0) & ((offset + 2 * line[:, None]) % P != 0)
    noise &= (bins[None, :] % P != 0) & (bins[None, :] > 0)
    var = np.sum(np.abs(spec) ** 2 * noise, axis=-1) / noise.sum(axis=-1)
    return 2 * np.sqrt(var)


def hfr_error(model, omega):
    """Relative RMS error of the components G_k, |k| <= K, on `omega`."""
    _, G = ltp.htf(true, K).components(omega)
    _, Gm = ltp.htf(model, K).components(omega)
    return float(np.linalg.norm(Gm - G) / np.linalg.norm(G))


OMEGA_TEST = 2 * np.pi * np.linspace(0.2, 6.0, 233)     # mostly between the lines


def draw(rng):
    """One noise draw: HTF errors of both models and the ML parameters."""
    yn = y + noise_std[None, :, None] * rng.standard_normal(y.shape)
    G = ltp.lifted_frequency_response((t, u, yn), T, K, **lfr)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        sub = ltp.identify_ltp(G, T, 2, K, q=20)
    ml, info = ltp.refine_ltp(sub, G, std=line_std(yn[0][:, window]), harmonics=HARMONICS,
                              estimate_d=True, return_info=True)
    errors = [hfr_error(sub, OMEGA_TEST), hfr_error(ml, OMEGA_TEST)]
    return np.concatenate([errors, info.x, info.std ** 2, [info.noise_scale]])


if __name__ == '__main__':
    start = time.perf_counter()
    # Cramér-Rao bound at the true plant, noise std of the lines known exactly
    G0 = ltp.lifted_frequency_response((t, u, y), T, K, **lfr)
    L = int(window.sum())
    std_true = 2 * noise_std / np.sqrt(L)
    _, crb = ltp.refine_ltp(ltp.ltpss(true.A(0.0), true.B, true.C, np.zeros((1, 1)), T),
                            G0, std=std_true, harmonics=HARMONICS, estimate_d=True,
                            maxiter=0, return_info=True)
    res = ltp.monte_carlo(draw, NDRAWS, seed=2017, n_jobs=N_JOBS, progress=True)
    elapsed = time.perf_counter() - start
    p = crb.x.size
    errors, x = res.samples[:, :2], res.samples[:, 2:2 + p]
    var_reported, scale = res.samples[:, 2 + p:2 + 2 * p], res.samples[:, -1]
    z = (x.mean(axis=0) - crb.x) / (x.std(axis=0, ddof=1) / np.sqrt(NDRAWS))
    sample_var = x.var(axis=0, ddof=1)
    print(f"{NDRAWS} draws in {elapsed:.0f} s ({N_JOBS} worker{'s' if N_JOBS > 1 else ''}), "
          f"{p} parameters")
    print("HTF error median  subspace {:.4f}  ML {:.4f}".format(*np.median(errors, axis=0)))
    print("HTF error mean    subspace {:.4f}  ML {:.4f}".format(*np.mean(errors, axis=0)))
    print(f"ML better than subspace in {np.mean(errors[:, 1] < errors[:, 0]):.0%} of draws")
    print(f"bias / standard error: RMS {np.sqrt(np.mean(z ** 2)):.2f}, max "
          f"{np.max(np.abs(z)):.2f}")
    ratio_rep = sample_var / var_reported.mean(axis=0)
    ratio_crb = sample_var / np.diag(crb.cov)
    print(f"sample / reported variance: mean {ratio_rep.mean():.3f}, range "
          f"[{ratio_rep.min():.2f}, {ratio_rep.max():.2f}]")
    print(f"sample variance / CRB: mean {ratio_crb.mean():.3f}, max {ratio_crb.max():.2f}")
    whitened = np.trace(np.cov(x.T) @ np.linalg.inv(crb.cov)) / p
    print(f"tr(S CRB⁻¹)/p = {whitened:.3f}; mean noise scale {scale.mean():.3f}")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ax1.boxplot([errors[:, 0], errors[:, 1]], tick_labels=['subspace', 'ML'])
    ax1.set_yscale('log')
    ax1.set_ylabel('relative HTF error')
    ax1.set_title(f'{NDRAWS} draws at SNR {SNR}')
    ax2.semilogy(ratio_crb, 'o', label='sample variance / CRB')
    ax2.semilogy(ratio_rep, 'x', label='sample / reported variance')
    ax2.axhline(1.5, color='gray', ls=':')
    ax2.axhline(1.0, color='k', lw=0.5)
    ax2.set_xlabel('parameter')
    ax2.legend()
    fig.tight_layout()
    plt.show()
