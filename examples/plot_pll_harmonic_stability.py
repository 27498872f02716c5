r"""
Harmonic stability of a single-phase PLL
========================================

A single-phase phase-locked loop tracks the grid voltage
:math:`v = V\cos\omega_g t` with the product phase detector
:math:`e = -v\sin\hat\theta`.  About its periodic steady state
:math:`\hat\theta = \omega_g t` the detector's gain is not constant:

.. math::

    \delta e = -\frac{V}{2}\,(1 + \cos 2\omega_g t)\,\delta\varphi ,

a linear time-periodic loop with period :math:`\pi/\omega_g` (the
double-frequency ripple).  With a second-order low-pass filter
(poles at :math:`3\omega_b`) and a PI filter designed on the averaged
gain :math:`V/2` for the bandwidth :math:`\omega_b`, the averaged LTI
loop has the same gain margin 5 for every bandwidth.  The periodic loop
does not: the ripple couples the harmonics, and as the bandwidth
approaches the grid frequency the margin shrinks.

The stability of the loop with an extra gain k is judged twice, by the
generalized Nyquist criterion on the truncated HTF (`ltpcontrol.nyquist_htf`,
with the open loop's two integrators on the imaginary axis passed by
indentation) and by the Floquet multipliers of the closed loop; the gain
margin and the harmonic at which it is reached come from
`ltpcontrol.harmonic_margins`.
"""

import os

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import control as ct  # noqa: E402

import ltpcontrol as ltp  # noqa: E402

QUICK = os.environ.get('LTP_EXAMPLES_QUICK') == '1'
NH = 8                                   # harmonics of the loop HTF

# %%
# The linearized PLL
# ------------------

V, wg = 1.0, 2 * np.pi * 50
Tp = np.pi / wg                          # period of the ripple, ω_p = 2ω_g
# (V/2)(1 + cos ω_p t): exact Fourier coefficients V/4, V/2, V/4
ripple = np.array([[[0, 0, 0, V / 4]], [[0, 0, 0, V / 2]], [[0, 0, 0, V / 4]]])


def pll_loop(f_bw):
    """Loop δe -> filters -> PI -> phase -> detector, broken at the detector output."""
    bw = 2 * np.pi * f_bw
    kp, ki, a = bw / (V / 2), bw ** 2 / (2 * V), 3 * bw
    A = [[-a, 0, 0, 0], [a, -a, 0, 0], [0, 1, 0, 0], [0, kp, ki, 0]]
    return ltp.ltpss(A, [[a], [0], [0], [0]], ltp.PeriodicMatrix(ripple, Tp), 0,
                     period=Tp, name=f'PLL {f_bw} Hz')


L = pll_loop(30)
resp = ltp.nyquist_htf(L, NH)
m = ltp.harmonic_margins(L, NH)
gm_avg = ct.stability_margins(L.average())[0]
print(resp)
print(f"periodic loop: gain margin {m.gain_upper.value:.4f} reached at the strip "
      f"frequency {m.gain_upper.omega:.1f} rad/s (multiplier "
      f"{np.exp(1j * m.gain_upper.omega * Tp).real:+.0f}), harmonic "
      f"{m.gain_upper.harmonic}: {m.gain_upper.frequency / (2 * np.pi):.1f} Hz")
print(f"averaged LTI loop: gain margin {gm_avg:.4f}")
print(f"phase margin {m.phase.value:.2f} deg, disk margin {m.disk.value:.3f}")

# %%
# Nyquist and Floquet side by side
# --------------------------------
# Over a sweep of the extra gain k, the Nyquist verdict (closed-loop
# exponents in the right half plane, Z = P - encirclements) and the largest
# closed-loop Floquet multiplier agree; both change at the gain margin.

gains = np.linspace(0.5, 4.0, 8 if QUICK else 22)
radius, verdict = [], []
for k in gains:
    Lk = ltp.series(L, k)
    radius.append(np.abs(ltp.floquet_multipliers(ltp.feedback(Lk, 1))).max())
    verdict.append(ltp.nyquist_htf(Lk, NH).closed_loop_unstable)
radius, verdict = np.array(radius), np.array(verdict)
agree = np.all((radius < 1) == (verdict == 0))
print(f"Nyquist and Floquet agree at all {len(gains)} gains: {agree}")

bandwidths = np.array([10, 20, 30, 40, 50] if QUICK else np.arange(8, 62, 4))
margins = [ltp.harmonic_margins(pll_loop(f), NH, check=False).gain_upper.value
           for f in bandwidths]

fig, ax = plt.subplots(1, 3, figsize=(13, 4.2))
resp.plot(ax=ax[0], title="eigenloci of L̂ (30 Hz PLL)")
ax[0].set_xlim(-3, 1.5)
ax[0].set_ylim(-2.2, 2.2)
ax[1].semilogy(gains, radius, 'k-', label="max |Floquet multiplier|")
ax[1].plot(gains[verdict == 0], radius[verdict == 0], 'go', label="Nyquist: stable")
ax[1].plot(gains[verdict > 0], radius[verdict > 0], 'rx', label="Nyquist: unstable")
ax[1].axhline(1, color='0.6', lw=0.8)
ax[1].axvline(m.gain_upper.value, color='C3', ls='--', label="gain margin (periodic)")
ax[1].axvline(gm_avg, color='C0', ls=':', label="gain margin (averaged)")
ax[1].set_xlabel("extra loop gain k")
ax[1].legend(fontsize=7)
ax[1].set_title("closed loop: Floquet vs Nyquist")
ax[2].plot(bandwidths, margins, 'C3o-', label="periodic loop")
ax[2].axhline(gm_avg, color='C0', ls=':', label="averaged LTI loop")
ax[2].set_xlabel("PLL bandwidth [Hz]")
ax[2].set_ylabel("upper gain margin")
ax[2].legend(fontsize=8)
ax[2].set_title("harmonic coupling erodes the margin")
fig.tight_layout()
fig.savefig('pll_harmonic_stability.png', dpi=90)
