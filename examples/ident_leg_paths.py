"""The hopper leg identified on every documented data path.

Leg ``m ẍ + c(t) ẋ + k(t) x = f`` with k ±50 %, c ±30 % and an actuator
``τ ḟ = -f + u`` 40 times faster (period 0.5 s, output x; the plant of
``tests/test_ident_leg.py``).  Paths:

* lifted FRD from 38 single-sine records, with K harmonics (fewer than the
  model produces), with 3K + 1 and with the default (every harmonic the
  sampling holds), noise-free and at 30 dB (seeds 0-2);
* HTF route: 2K_h + 4 phase-shifted chirp replicas (0-12 Hz) at 30 dB
  (seeds 0-2) → `estimate_htf` → `identify_ltp`, with K_h = K harmonics and
  with K_h = 3K + 1 taken by `estimate_htf`'s defaults (harmonics and band).

Every model is simulated next to the plant on a fresh record of filtered
noise (cut-off 2 ω_p, 60 periods); the table prints ``success``, the
number of warnings, the held-out NRMSE and the fresh NRMSE.

Run ``python examples/ident_leg_paths.py [frd|htf]`` (minutes on one core;
the HTF route with K = 3 is the longest).
"""

import sys
import warnings

import numpy as np
import scipy.signal

import ltpcontrol as ltp

T = 0.5
WP = 2 * np.pi / T
DT = T / 64
P = 20


def leg(m=1.0, k0=400.0, c0=8.0, tau=0.01):
    A = np.zeros((3, 3, 3), complex)
    A[1] = [[0, 1, 0], [-k0 / m, -c0 / m, 1 / m], [0, 0, -1 / tau]]
    A[0, 1, 0] = A[2, 1, 0] = -0.25 * k0 / m
    A[0, 1, 1], A[2, 1, 1] = 0.15j * c0 / m, -0.15j * c0 / m
    return ltp.ltpss(ltp.PeriodicMatrix(A, T), [[0], [0], [1 / tau]], [[1, 0, 0]], 0,
                     period=T)


def fresh(model, plant, nper=60):
    L = int(nper * T / DT)
    b, a = scipy.signal.butter(4, 2 * WP * DT / np.pi)
    u = scipy.signal.lfilter(b, a, np.random.default_rng(0).standard_normal((1, L)), axis=1)
    t = np.arange(L) * DT
    y = ltp.forced_response(plant, t, u).outputs
    return float(np.linalg.norm(ltp.forced_response(model, t, u).outputs - y)
                 / np.linalg.norm(y))


def run(label, data, K, plant):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        model, info = ltp.identify_ltp(data, T, 3, K, return_info=True)
    print(f"{label:34s} success={info.success!s:5s} warnings={len(caught)} "
          f"holdout={info.holdout_nrmse:.3g} fresh={fresh(model, plant):.3g}", flush=True)


def main():
    mode = sys.argv[1] if len(sys.argv) > 1 else 'frd'
    plant = leg()
    if mode == 'frd':
        bins = np.array([b for b in range(1, 9 * P) if (2 * b) % P][:114:3])
        lines = bins * 2 * np.pi / (P * T)
        t = np.arange(2 * P * 64) * DT
        u = np.cos(lines[:, None] * t)[None]
        y = ltp.forced_response(plant, t, u).outputs
        sigma = np.sqrt(np.mean(y ** 2) / 1e3)
        for K in (2, 3):
            for seed in (None, 0, 1, 2):
                yn = y if seed is None else \
                    y + sigma * np.random.default_rng(seed).standard_normal(y.shape)
                for Kd in (K, 3 * K + 1, None):
                    G = ltp.lifted_frequency_response((t, u, yn), T, Kd, transient=P * T,
                                                      input_hold='foh')
                    Kd = 'default' if Kd is None else Kd
                    noise = 'noise-free' if seed is None else f'30 dB seed {seed}'
                    run(f"FRD K={K} data {Kd} harm. {noise}", G, K, plant)
    else:
        K = int(sys.argv[2]) if len(sys.argv) > 2 else 2
        for Kh in (K, 3 * K + 1):
            exc = ltp.chirp_replicas(T, 2 * Kh + 4, 20.0, 0.0, 12.0, dt=DT, gap=4.0)
            yc = ltp.forced_response(plant, exc.time, exc.inputs).outputs
            sigma = np.sqrt(np.mean(yc ** 2) / 1e3)
            for seed in range(3):
                yn = yc + sigma * np.random.default_rng(seed).standard_normal(yc.shape)
                with warnings.catch_warnings():
                    warnings.simplefilter('ignore')
                    if Kh == K:
                        H = ltp.estimate_htf((exc.time, exc.inputs, yn), T, Kh,
                                             segments=exc.segments,
                                             omega_limits=(0.0, 2 * np.pi * (12.0 + 2 * Kh)))
                    else:                    # the defaults: every harmonic the design holds
                        H = ltp.estimate_htf((exc.time, exc.inputs, yn), T,
                                             segments=exc.segments)
                run(f"HTF K={K} data {H.nharmonics} harm. 30 dB seed {seed}", H, K, plant)


if __name__ == '__main__':
    main()
