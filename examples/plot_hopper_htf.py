"""
Simplified hopper: limit cycle, LTP model and theoretical HTF
=============================================================

The simplified vertical hopper of thesis §3.4 is a mass on a spring whose
damper acts only while the mass moves up, driven by ``cos 2πt``
(eq. 3.36, g = 9.81, k = 200, c = 2, m = 1, x0 = 0.2).  Its 1 s limit
cycle is found by `ltpcontrol.periodic_orbit`; about it the hopper is the
LTP system (3.39) whose damping flag is a square wave — a switching
`ltpcontrol.PeriodicMatrix` with the orbit's switching times.  Its
theoretical HTF is computed up to n_h = 10 harmonics (thesis §3.4.2) and
drawn with `ltpcontrol.bode_htf`.
"""

import matplotlib.pyplot as plt
import numpy as np

import ltpcontrol as ltp
from hopper import hopper_ltp, hopper_orbit

orbit = hopper_orbit()
print(orbit)
print("switching times within the period:", np.round(orbit.switching_times, 4))
print("return-map multipliers:", np.round(orbit.multipliers, 4))

# %%
# The analytic LTP model (3.39) and its HTF
# -----------------------------------------
sys = hopper_ltp(orbit)
H = ltp.htf(sys, nharmonics=10, internal_harmonics=60)
print(H)

# the model's Floquet multipliers equal the exact return-map eigenvalues
print("LTP model multipliers:", np.round(np.sort_complex(sys.floquet_multipliers()), 4))

cplt = ltp.bode_htf(H, harmonics=(-2, -1, 0, 1, 2), omega_limits=(0.5, 60),
                    omega_num=300, Hz=True, dB=True)
cplt.figure.savefig('hopper_htf.png', dpi=120)

# %%
# The limit cycle
# ---------------
fig, ax = plt.subplots()
ax.plot(orbit.time, orbit.states[0], label='position x')
ax.plot(orbit.time, orbit.states[1], label='velocity v')
for ts in orbit.switching_times:
    ax.axvline(ts, color='gray', linestyle=':')
ax.set_xlabel('time [s]')
ax.legend()
ax.set_title('Hopper limit cycle (switches dotted)')
plt.show()
