r"""
Higher-harmonic control of a rotor blade in forward flight
==========================================================

A rigid flapping blade in forward flight (Peters & Hohenemser; time is the
azimuth ψ, so the rotor speed is 1 and the period 2π) with Lock number
γ = 8, flap frequency p = 1.1 and advance ratio μ = 0.3:

.. math::

    \beta'' + \tfrac{\gamma}{8}\big(1 + \tfrac43\mu\sin\psi\big)\beta'
    + \Big[p^2 + \tfrac{\gamma}{8}\big(\tfrac43\mu\cos\psi
    + \mu^2\sin 2\psi\big)\Big]\beta = \tfrac{\gamma}{8}
    \big(1 + \tfrac83\mu\sin\psi + 2\mu^2\sin^2\psi\big)\,\theta + d ,

measured through the flap moment :math:`y = p^2\beta`.  A 3/rev load d
shakes the blade.  Higher-harmonic control adjusts the 3/rev pitch
:math:`\theta = -(\theta_c\cos 3\psi + \theta_s\sin 3\psi)` with the
quasi-static T-matrix update, which in continuous time is the periodic
compensator `ltpcontrol.hhc_controller` (demodulate at 3/rev, integrate,
remodulate).  The T-matrix comes from the blade's HTF
(`ltpcontrol.hhc_tmatrix`); since the blade is periodic, the 3/rev input
also answers at 3/rev through the component :math:`G_6`.

The loop is stable by the generalized Nyquist criterion and by the
Floquet multipliers, with the margins printed below, and the simulated
3/rev output decays to zero.
"""

import os

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402

QUICK = os.environ.get('LTP_EXAMPLES_QUICK') == '1'

# %%
# The blade and its T-matrix
# --------------------------

GAM, PF, MU, NREV = 8.0, 1.1, 0.3, 3
TR = 2 * np.pi


def A(t):
    return np.array([[0.0, 1.0],
                     [-(PF ** 2 + GAM / 8 * (4 / 3 * MU * np.cos(t) + MU ** 2 * np.sin(2 * t))),
                      -GAM / 8 * (1 + 4 / 3 * MU * np.sin(t))]])


def B(t):
    # columns: pitch θ (periodic aerodynamic gain) and the load d
    return np.array([[0.0, 0.0],
                     [GAM / 8 * (1 + 8 / 3 * MU * np.sin(t) + 2 * MU ** 2 * np.sin(t) ** 2),
                      1.0]])


blade = ltp.ltpss(ltp.PeriodicMatrix.from_function(A, TR),
                  ltp.PeriodicMatrix.from_function(B, TR), [[PF ** 2, 0.0]], 0, period=TR,
                  name='blade', inputs=['theta', 'd'], outputs='M')
P = blade[0, 0]                          # pitch -> flap moment
T = ltp.hhc_tmatrix(P, NREV)
print("T-matrix at 3/rev:\n", np.round(T, 5))

# %%
# The controller and the loop
# ---------------------------
# Integration rate γ = 0.1 (a relaxation α = 0.63 per revolution).

K = ltp.hhc_controller(T, NREV, 0.1)
resp = ltp.nyquist_htf((P, K), 8)
m = ltp.harmonic_margins((P, K), 8)
closed = ltp.feedback(P, K)
mu = np.abs(ltp.floquet_multipliers(closed)).max()
print(resp)
print(f"largest closed-loop Floquet multiplier {mu:.3f}")
print(f"gain margin {m.gain_upper.value:.2f} at {m.gain_upper.frequency:.3f} rad/s "
      f"(harmonic {m.gain_upper.harmonic}), phase margin {m.phase.value:.1f} deg "
      f"at {m.phase.frequency:.3f} rad/s")

# %%
# Simulation
# ----------
# The load enters the blade; the controller acts on the measured moment.

Kfull = ltp.ltpss(K.A, K.B, ltp.PeriodicMatrix.block([[K.C], [np.zeros((1, 2))]]),
                  np.zeros((2, 1)), period=K.period)
loop = ltp.feedback(blade, Kfull)
nrevs = 15 if QUICK else 30
t = np.linspace(0, nrevs * TR, nrevs * 200 + 1)
d = 0.5 * np.cos(NREV * t + 0.4)
u = np.vstack([np.zeros_like(t), d])
y_open = np.atleast_2d(ltp.forced_response(blade, t, u).outputs)[0]
y_hhc = np.atleast_2d(ltp.forced_response(loop, t, u).outputs)[0]


def nrev_amplitude(y):
    """3/rev amplitude over each revolution."""
    out = []
    for r in range(nrevs):
        sel = slice(200 * r, 200 * (r + 1) + 1)          # one revolution, both ends
        out.append(abs(2 / TR * np.trapezoid(y[sel] * np.exp(-3j * t[sel]), t[sel])))
    return np.array(out)


a_open, a_hhc = nrev_amplitude(y_open), nrev_amplitude(y_hhc)
print(f"3/rev moment, last revolution: {a_open[-1]:.4f} open loop, {a_hhc[-1]:.2e} "
      f"with HHC ({20 * np.log10(a_open[-1] / a_hhc[-1]):.0f} dB)")

fig, ax = plt.subplots(1, 3, figsize=(13, 4))
resp.plot(ax=ax[0], title="eigenloci of the HHC loop")
ax[0].set_xlim(-2, 1)
ax[0].set_ylim(-1.5, 1.5)
ax[1].plot(t / TR, y_open, color='0.6', lw=0.8, label="open loop")
ax[1].plot(t / TR, y_hhc, 'C3', lw=0.8, label="HHC")
ax[1].set_xlabel("revolutions")
ax[1].set_ylabel("flap moment")
ax[1].legend(fontsize=8)
ax[2].semilogy(np.arange(1, nrevs + 1), a_open, 'o-', color='0.6', label="open loop")
ax[2].semilogy(np.arange(1, nrevs + 1), a_hhc, 'C3o-', label="HHC")
ax[2].set_xlabel("revolution")
ax[2].set_ylabel("3/rev amplitude")
ax[2].legend(fontsize=8)
fig.tight_layout()
fig.savefig('rotor_hhc.png', dpi=90)
