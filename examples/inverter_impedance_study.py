"""Impedance-based verdicts on the grid-following inverter, model and measured.

Not run by the documentation build (minutes of computation): run it from the
repository root with ``PYTHONPATH=. python examples/inverter_impedance_study.py``.

The inverter's admittance Y (``examples/grid_inverter.py``, 8 states, SOGI-PLL)
is closed by the grid impedance ``sL_g`` with the negative-feedback loop
``-Z_g Y``.  Three verdicts for each grid:

* the Floquet multipliers of the closed loop, integrated independently
  (solve_ivp, DOP853) after eliminating ``v = L_g di/dt`` by hand;
* the impedance product realized by `harmonic_product` (compared with the
  hand-written loop of the gallery example) and counted by `nyquist_htf`;
* the same admittance known only by frequency samples (an `HTFData` on a
  grid of spacing ω_g/64 with components up to |k| = K), counted by
  `impedance_nyquist` with ``open_loop_unstable=0``.
"""

import sys
import time
import warnings

import numpy as np
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

sys.path.insert(0, 'examples')
from grid_inverter import admittance  # noqa: E402

Lg0 = 10e-3
Y = admittance(Lg0)
T = Y.period
WP = 2 * np.pi / T
C = Y.C(0.0)
CB = float((C @ Y.B(0.0))[0, 0])
P = Y.A.fourier(1)


def hand_loop(Lg):
    return ltp.ltpss(Y.A, Y.B, -Lg * (C @ Y.A), [[-Lg * CB]], period=T)


def radius(Lg):
    M = np.eye(8) + Lg * Y.B(0.0) @ C / (1 - Lg * CB)
    A0, Ac, As = M @ P[1].real, 2 * M @ P[2].real, -2 * M @ P[2].imag

    def rhs(t, x):
        return ((A0 + Ac * np.cos(WP * t) + As * np.sin(WP * t)) @ x.reshape(8, 8)).ravel()
    sol = solve_ivp(rhs, (0, T), np.eye(8).ravel(), method='DOP853', rtol=1e-10, atol=1e-12)
    return float(np.abs(np.linalg.eigvals(sol.y[:, -1].reshape(8, 8))).max())


def main(models=True):
    warnings.filterwarnings('ignore', message='.*truncation edge')
    grids = (Lg0, 30e-3, 50e-3)
    print(f"{'L_g [mH]':>8} {'Floquet radius':>15}")
    rho = {Lg: radius(Lg) for Lg in grids}
    for Lg in grids:
        print(f"{Lg * 1e3:8.1f} {rho[Lg]:15.6f}")
    if models:
        N = 10
        for Lg in grids:
            Zg = ltp.rlc_impedance(L=Lg, period=T, nharmonics=N)
            L = ltp.harmonic_product(-Zg, Y)
            s = 0.3 + 200j
            diff = np.abs(ltp.htf(L, 3)(s) - ltp.htf(hand_loop(Lg), 3)(s)).max()
            t0 = time.perf_counter()
            resp = ltp.nyquist_htf(L, N, check=False, floquet_steps=32)
            print(f"model  L_g={Lg * 1e3:4.0f} mH: product - hand loop {diff:.1e}, "
                  f"Z={resp.closed_loop_unstable}, Floquet "
                  f"{'stable' if rho[Lg] < 1 else 'unstable'} ({time.perf_counter() - t0:.0f} s)")
            assert resp.stable == (rho[Lg] < 1)
    for K in (2, 6):
        for N in (10, 20, 40):
            w = np.arange(1, 64 * (N + 2)) * WP / 64
            Hd = ltp.HTFData(ltp.htf(Y, K).components(w)[1], w, period=T)
            for Lg in grids:
                Zg = ltp.rlc_impedance(L=Lg, period=T, nharmonics=N)
                with warnings.catch_warnings():
                    warnings.simplefilter('ignore')
                    resp = ltp.impedance_nyquist((-Zg, Hd), N, open_loop_unstable=0)
                ok = resp.stable == (rho[Lg] < 1)
                print(f"measured K={K} N={N:2d} L_g={Lg * 1e3:4.0f} mH: "
                      f"Z={resp.closed_loop_unstable}, max step "
                      f"{resp.max_phase_step:.2f} rad, closure gap {resp.closure_gap:.2f}, "
                      f"{'agrees' if ok else 'DISAGREES'} with Floquet")


if __name__ == '__main__':
    main(models='--data-only' not in sys.argv)
