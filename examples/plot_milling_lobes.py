r"""
Stability lobes of 1-DOF milling
================================

Insperger and Stépán's benchmark: a one-degree-of-freedom tool in
up-milling with 2 teeth at 5 % radial immersion,

.. math::

    m\ddot x + c\dot x + kx = -a_p\,h(t)\,\bigl(x(t) - x(t-\tau)\bigr),
    \qquad \tau = \frac{60}{N\Omega},

where the specific cutting force :math:`h(t)` is nonzero only while a tooth
is in the cut (a short part of the tooth period at 5 % immersion) and the
delay equals the period.  The switching instants are element edges of the
spectral-element monodromy, so the discretization converges spectrally.
`ltpcontrol.stability_chart` gives the dominant multiplier over spindle
speed and axial depth and the refined lowest boundary: the stability lobe
diagram, with its flip (period-doubling, μ = -1) and Hopf (complex μ)
lobes.  Benchmark P12 computes 200 speeds against a semi-discretization.
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402

N, KT, KN, FN, ZETA, MASS, AD = 2, 6e8, 2e8, 922.0, 0.011, 0.03993, 0.05
WN = 2 * np.pi * FN


def milling(rpm, depth_mm):
    """The milling model at `rpm` and axial depth in mm."""
    ap = depth_mm * 1e-3
    T = 60.0 / (N * rpm)
    ws = 2 * np.pi * rpm / 60
    t_ex = np.arccos(1 - 2 * AD) / ws            # the tooth leaves the cut

    def h(t):
        t = np.mod(np.asarray(t, float), T)
        phi = ws * t
        return np.where(t < t_ex, np.sin(phi) * (KT * np.cos(phi) + KN * np.sin(phi)), 0.0)

    def A(t):
        hv = np.asarray(h(t))
        out = np.zeros(hv.shape + (2, 2))
        out[..., 0, 1] = 1.0
        out[..., 1, 0] = -WN**2 - ap * hv / MASS
        out[..., 1, 1] = -2 * ZETA * WN
        return out

    def Ad(t):
        out = np.zeros(np.shape(t) + (2, 2))
        out[..., 1, 0] = ap * h(t) / MASS
        return out
    bps = [0.0, t_ex]
    return ltp.ltpdss(
        ltp.PeriodicMatrix.from_function(A, T, (2, 2), breakpoints=bps, check=False),
        [[0.0], [1.0]], [[1.0, 0.0]], 0, period=T,
        delays=[(T, ltp.PeriodicMatrix.from_function(Ad, T, (2, 2), breakpoints=bps,
                                                     check=False))])


# %%
# The chart
# ---------

rpm = np.linspace(5000, 25000, 36)
depth = np.linspace(0.01, 5.0, 11)
chart = ltp.stability_chart(milling, rpm, depth, n_jobs=1, tol=1e-6, progress=False,
                            xlabel='spindle speed (rpm)', ylabel='axial depth (mm)')
cplt = chart.plot(title='1-DOF milling, up-milling, 2 teeth, a/D = 0.05')
print(f"lowest critical depth {np.nanmin(chart.critical()):.3f} mm at "
      f"{rpm[np.nanargmin(chart.critical())]:.0f} rpm")

# %%
# The dominant multiplier at a point above a lobe
# -----------------------------------------------
#
# `delay_monodromy` reports the discretization and its accuracy estimate.

M = ltp.delay_monodromy(milling(10000.0, 3.0))
print(M)
print("dominant multipliers:", np.round(M.multipliers[:2], 6))
plt.show()
