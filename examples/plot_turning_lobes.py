r"""
Stability lobes of turning against the closed form
==================================================

Regenerative chatter in turning: the tool cuts the surface left by the
previous revolution, so the chip thickness depends on the vibration now and
one revolution ago,

.. math::

    m\ddot x + c\dot x + kx = -k_c w\,\bigl(x(t) - x(t-\tau)\bigr),
    \qquad \tau = 60/\Omega .

The critical width of cut :math:`w` at each spindle speed comes from
`ltpcontrol.stability_chart` of `ltpcontrol.ltpdss` models (the refined
boundary of the dominant characteristic multiplier), and is drawn over the
closed-form lobes: for a chatter frequency ω above the natural one,
:math:`w(\omega) = ((m\omega^2-k)^2 + (c\omega)^2) / (2k_c(m\omega^2-k))` and
:math:`\omega\tau = \arg(1-z)^{-1} + 2\pi j` with
:math:`z = (m\omega^2 - k - jc\omega)/(k_c w)`, lobe j = 0, 1, ...
(dimensionless units, m = k = k_c = 1, c = 0.1).
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402

m, c, k, kc = 1.0, 0.1, 1.0, 1.0


def turning(speed, w):
    """Turning at spindle speed `speed` (revolutions per unit time) and width w."""
    tau = 1.0 / speed
    A = [[0.0, 1.0], [-(k + kc * w) / m, -c / m]]
    Ad = [[0.0, 0.0], [kc * w / m, 0.0]]
    return ltp.ltpdss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=tau, delays=[(tau, Ad)])


# %%
# The chart: 40 speeds, the boundary refined between w = 0 and w = 0.5
# ---------------------------------------------------------------------

speeds = np.linspace(0.05, 0.35, 40)
chart = ltp.stability_chart(turning, speeds, [0.0, 0.5], n_jobs=1, tol=1e-9, progress=False,
                            xlabel='spindle speed (rev per unit time)', ylabel='width w')
crit = chart.critical()

# %%
# Closed-form lobes and the comparison
# ------------------------------------

om = 1 + np.geomspace(1e-4, 3, 4000)
wl = ((m * om**2 - k) ** 2 + (c * om) ** 2) / (2 * kc * (m * om**2 - k))
z = (m * om**2 - k - 1j * c * om) / (kc * wl)
phase = np.mod(-np.angle(1 - z), 2 * np.pi)
fig, ax = plt.subplots(figsize=(7, 4))
for j in range(8):
    tau_j = (phase + 2 * np.pi * j) / om
    ax.plot(1 / tau_j, wl, color='0.7', lw=1, label='closed-form lobes' if j == 0 else None)
ax.plot(speeds, crit, 'k.', ms=4, label='stability_chart (critical w)')
ax.set_xlim(speeds[0], speeds[-1])
ax.set_ylim(0, 0.5)
ax.set_xlabel(chart.xlabel)
ax.set_ylabel(chart.ylabel)
ax.legend(loc='upper left')
ax.set_title('Turning: stability lobes')

# the critical width of each speed equals the lowest closed-form lobe there
env = np.full(len(speeds), np.inf)
for j in range(8):
    tau_j = (phase + 2 * np.pi * j) / om
    env = np.minimum(env, np.interp(1 / speeds, tau_j[::-1], wl[::-1],
                                    left=np.inf, right=np.inf))
print(f"largest relative gap to the (sampled) closed-form envelope: "
      f"{np.nanmax(np.abs(crit / env - 1)):.1e}")
plt.show()
