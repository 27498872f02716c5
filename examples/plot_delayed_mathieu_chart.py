r"""
Stability chart of the delayed damped Mathieu equation
======================================================

Insperger and Stépán's delayed damped Mathieu equation,

.. math::

    \ddot x + \kappa\dot x + (\delta + \varepsilon\cos t)\,x = b\,x(t - 2\pi),

combines parametric excitation and a delay equal to the period; its
stability chart in the (δ, b) plane holds both the Ince-Strutt tongues and
the delay's D-curves.  Without forcing (ε = 0) the boundaries are known in
closed form: :math:`b = \delta` (a real root λ = 0) and, for λ = jω,
:math:`b = -\kappa\omega/\sin 2\pi\omega`,
:math:`\delta = \omega^2 - \kappa\omega\cot 2\pi\omega`.
`ltpcontrol.stability_chart` draws ``max|μ|`` and the refined boundary; at
ε = 0 the refined points lie on the D-curves, at ε = 1 the stable domain
shrinks and splits.
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402

KAPPA = 0.1


def mathieu(eps):
    def factory(delta, b):
        if eps:
            A = ltp.PeriodicMatrix.from_function(
                lambda t: np.array([[0.0, 1.0], [-delta - eps * np.cos(t), -KAPPA]]),
                2 * np.pi, (2, 2), check=False)
        else:
            A = [[0.0, 1.0], [-delta, -KAPPA]]
        return ltp.ltpdss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi,
                          delays=[(2 * np.pi, [[0.0, 0.0], [b, 0.0]])])
    return factory


delta = np.linspace(-0.5, 3.0, 18)
b = np.linspace(-1.2, 1.2, 13)
fig, axs = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
charts = {}
for ax, eps in zip(axs, (0.0, 1.0)):
    charts[eps] = ltp.stability_chart(mathieu(eps), delta, b, n_jobs=1, tol=1e-8,
                                      progress=False, xlabel='δ', ylabel='b')
    charts[eps].plot(ax=ax, title=f'ε = {eps:g}')

# %%
# The closed-form D-curves over the ε = 0 chart
# ---------------------------------------------

w = np.linspace(1e-3, 2.0, 4000)
s = np.sin(2 * np.pi * w)
keep = np.abs(s) > 1e-2
db, bb = (w**2 - KAPPA * w * np.cos(2 * np.pi * w) / s), -KAPPA * w / s
db[~keep] = np.nan
axs[0].plot(db, bb, 'b-', lw=0.8, label='D-curves (λ = jω)')
axs[0].plot(delta, delta, 'b--', lw=0.8, label='b = δ (λ = 0)')
axs[0].set_xlim(delta[0], delta[-1])
axs[0].set_ylim(b[0], b[-1])
axs[0].legend(loc='lower right', fontsize=8)

# distance of the refined ε = 0 boundary to the closed form
from scipy.optimize import brentq  # noqa: E402
gaps = []
for d, bv in charts[0.0].boundary:
    best = abs(bv - d)
    for k in range(8):
        f = lambda x: x**2 - KAPPA * x / np.tan(2 * np.pi * x) - d  # noqa: E731
        lo, hi = k / 2 + 1e-12, (k + 1) / 2 - 1e-12
        if f(lo) * f(hi) < 0:
            x = brentq(f, lo, hi, xtol=1e-15)
            best = min(best, abs(-KAPPA * x / np.sin(2 * np.pi * x) - bv))
    gaps.append(best)
print(f"{len(gaps)} refined boundary points at ε = 0; largest distance to the closed "
      f"form {max(gaps):.1e}")
plt.show()
