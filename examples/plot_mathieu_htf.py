"""
Harmonic transfer function of the Mathieu system
================================================

The thesis's Mathieu-type LTP system (eq. 4.115) has a constant state
matrix and periodic input and output matrices,

.. math::

   \\dot x = \\begin{bmatrix} 0 & 1 \\\\ -\\omega_n^2 & -2\\zeta\\omega_n \\end{bmatrix} x
   + \\begin{bmatrix} 0 \\\\ 1 + 2\\beta_b\\cos\\omega_p t \\end{bmatrix} u, \\qquad
   y = (1 + 2\\beta_c \\cos\\omega_p t)\\, x_1,

with :math:`\\omega_p = 4\\pi`, :math:`\\omega_n = 2\\pi`, :math:`\\zeta = 0.3`,
:math:`\\beta_b = 0.2`, :math:`\\beta_c = 0.1`.  Its HTF components
:math:`G_0` and :math:`G_{\\pm1}` (the analogue of the thesis's Fig. 4.2) are
drawn with `ltpcontrol.bode_htf`, and checked against a simulation.
"""

import matplotlib.pyplot as plt
import numpy as np

import ltpcontrol as ltp

wp, wn, zeta, beta_b, beta_c = 4 * np.pi, 2 * np.pi, 0.3, 0.2, 0.1
T = 2 * np.pi / wp
B = ltp.PeriodicMatrix([[[0], [beta_b]], [[0], [1]], [[0], [beta_b]]], T)
C = ltp.PeriodicMatrix([[[beta_c, 0]], [[1, 0]], [[beta_c, 0]]], T)
sys = ltp.ltpss([[0, 1], [-wn ** 2, -2 * zeta * wn]], B, C, 0, period=T, name='Mathieu')

H = ltp.htf(sys, nharmonics=3)
print(H)

# %%
# Components G_0 and G_±1 (thesis Fig. 4.2)
# -----------------------------------------
cplt = ltp.bode_htf(H, omega_limits=(0.1 * 2 * np.pi, 20 * 2 * np.pi), omega_num=400,
                    Hz=True, dB=True)
cplt.figure.savefig('mathieu_htf.png', dpi=120)

# %%
# The HTF predicts the simulated steady state
# -------------------------------------------
# A cosine at 0.35 Hz produces output lines at 0.35 + 2n Hz with complex
# amplitudes :math:`\tfrac12 H_{n,0}(j\omega)`.
f, h = 0.35, 0.002
t = np.arange(0, 40, h)
y = ltp.forced_response(sys, t, np.cos(2 * np.pi * f * t)).outputs
win = t >= 20
for n in (-1, 0, 1):
    line = np.mean(y[win] * np.exp(-1j * (2 * np.pi * f + n * wp) * t[win]))
    # the simulated input is the linear interpolant of the samples: its line
    # at ω is scaled by sinc²(ωh/2)
    pred = 0.5 * np.sinc(f * h) ** 2 * H(2j * np.pi * f)[n + 3, 3]
    print(f"n = {n:+d}: simulated {abs(line):.6e}, HTF {abs(pred):.6e}, "
          f"relative difference {abs(line - pred) / abs(pred):.1e}")

# %%
# Harmonic magnitude map
# ----------------------
ltp.htf_map_plot(H, 2 * np.pi * f)
plt.show()
