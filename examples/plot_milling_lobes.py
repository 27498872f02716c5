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

# The model (``examples/milling_models.py``, shared with benchmark P12):
from milling_models import milling_mm as milling  # noqa: E402


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
