r"""
Flapping blade in forward flight: stability boundary and mode identification
============================================================================

A rigid blade flapping about a hinge, in forward flight at advance ratio
:math:`\mu`, with time measured in azimuth (one period is one revolution,
:math:`2\pi`), Lock number :math:`\gamma = 12`, flap frequency 1/rev and no
reverse flow (Peters & Hohenemser 1971):

.. math::

    \beta'' + \tfrac{\gamma}{8}\big(1 + \tfrac43\mu\sin\psi\big)\beta'
    + \Big[1 + \tfrac{\gamma}{8}\big(\tfrac43\mu\cos\psi + \mu^2\sin 2\psi\big)\Big]\beta = 0 .

`ltpcontrol.floquet_modes` gives each mode's exponent on the branch of the
principal harmonic of its periodic mode shape, with its frequency, damping
and harmonic participation; `ltpcontrol.campbell` follows them over the
advance ratio.  In hover the modes are the blade's own (frequency 1/rev,
damping ratio 0.75, damped frequency 0.66/rev); as μ grows the damped
frequency drops to 1/2 /rev and then
locks onto 1/rev (real multipliers: the mode shape is a real cosine, whose
two harmonics ±1 carry equal shares), and the blade becomes unstable at the
boundary printed below.  The test of this script checks that boundary and
the identified modes against solutions integrated with
`scipy.integrate.solve_ivp`.
"""

import os

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
from scipy.optimize import brentq  # noqa: E402

import ltpcontrol as ltp  # noqa: E402
from rotor_models import flap_A  # noqa: E402

QUICK = os.environ.get('LTP_EXAMPLES_QUICK') == '1'


def blade(mu):
    """Flapping blade at advance ratio μ (time = azimuth, period 2π)."""
    return ltp.ltpss(lambda psi: flap_A(psi, mu), np.zeros((2, 0)), np.zeros((0, 2)), 0,
                     period=2 * np.pi)


# %%
# Mode identification at three advance ratios
# -------------------------------------------

print("  mu   freq [/rev]  damped freq  damping    Re      h*  principal share")
for mu in (0.0, 0.1, 0.2):
    modes = ltp.floquet_modes(blade(mu))
    i = int(np.argmax(modes.damped_frequency))
    print(f" {mu:4.1f} {modes.frequency[i]:11.6f} {modes.damped_frequency[i]:11.6f} "
          f"{modes.damping[i]:9.6f} "
          f"{modes.exponents[i].real:8.4f} {modes.principal_harmonic[i]:4d} "
          f"{modes.participation[i].max():10.3f}")

# %%
# Stability boundary
# ------------------


def growth(mu):
    return ltp.floquet_exponents(blade(mu)).real.max()


boundary = brentq(growth, 1.0, 2.0, xtol=1e-10)
print(f"flap stability boundary: mu = {boundary:.6f}")

# %%
# Campbell diagram over the advance ratio
# ---------------------------------------
#
# The rotor speed is 1 (time in azimuth), so the nP lines are at n rad/s.
# Each track keeps the branch nearest its previous exponent (``branch=
# 'continuous'``); past the frequency lock the two modes are real and split
# in damping, one of them crossing into instability.

values = np.linspace(0.0, 1.6, 17 if QUICK else 65)
cd = ltp.campbell(blade, values, rotor_speed=np.ones_like(values), per_rev=(1,),
                  n_jobs=1 if QUICK else None)
cplt = cd.plot(per_rev=(1,), tracks=[0, 1], title='Flapping blade, γ = 12')
cplt.axes[1, 0].axvline(boundary, color='r', lw=0.8)
cplt.axes[1, 0].set_xlabel('advance ratio μ')
cplt.axes[0, 0].set_ylabel('frequency [/rev]')
cplt.figure.savefig('flapping_blade.png', dpi=100)
