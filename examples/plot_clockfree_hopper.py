"""
A clock-free hopping robot
==========================

The hopper of ``clockfree_hopper`` lengthens its leg when the body reaches
the bottom of stance — a controller that reacts to events, with no clock.
Its hopping gait is an isolated limit cycle with an unknown period, found
by `ltpcontrol.limit_cycle` with the apex (``v = 0`` in flight) as section.
Touchdown, bottom and liftoff all have saltation matrices different from
the identity.

First figure, left: the gait in the phase plane; right: apex heights of
hops simulated from perturbed states (plain event-located `solve_ivp`),
converging at the rate of the stability multiplier.  Second figure: the
gait followed by `ltpcontrol.orbit_continuation` as the leg extension
``delta`` grows — higher hops, longer periods, the multiplier stays inside
the unit circle.
"""

import os

import matplotlib

matplotlib.use('Agg')

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402
from clockfree_hopper import apex_map, hopping_gait  # noqa: E402

QUICK = bool(os.environ.get('LTP_EXAMPLES_QUICK'))

gait = hopping_gait(npoints=600)
(lam,) = gait.stability_multipliers
print(gait)
print(f"apex height {gait.x0[0]:.6f} m, period {gait.period:.6f} s, "
      f"stability multiplier {lam.real:.6f}")
names = gait.plant.mode_names
for t, i, j, S in zip(gait.switching_times, gait.mode_sequence, gait.mode_sequence[1:],
                      gait.saltation_matrices):
    print(f"  {names[i]:>11} -> {names[j]:<11} at t = {t:.4f} s, saltation matrix "
          f"{np.array2string(S, precision=3, suppress_small=True).replace(chr(10), '')}")

fig, axes = plt.subplots(1, 2, figsize=(10, 4))
for mode, name in enumerate(names):
    on = gait.modes == mode
    axes[0].plot(gait.states[0, on], gait.states[1, on], '.', ms=2, label=name)
axes[0].set(xlabel='z [m]', ylabel='v [m/s]', title='Hopping gait')
axes[0].legend(fontsize=8)

nhops = 15 if QUICK else 30
for h0 in (0.7 * gait.x0[0], 1.4 * gait.x0[0]):
    heights = [h0]
    for _ in range(nhops):
        heights.append(apex_map(heights[-1], rtol=1e-10, atol=1e-12)[0])
    err = np.abs(np.array(heights) - gait.x0[0])
    axes[1].semilogy(err, 'o-', ms=3, label=f'start at {h0:.3f} m')
axes[1].semilogy(err[0] * abs(lam) ** np.arange(nhops + 1), 'k--', label='|μ|ⁿ')
axes[1].set(xlabel='hop n', ylabel='|apex height − gait|', title='Perturbed hops')
axes[1].legend(fontsize=8)
fig.tight_layout()
fig.savefig('clockfree_hopper.png', dpi=100)

deltas = np.linspace(0.03, 0.06 if QUICK else 0.1, 4 if QUICK else 8)
branch = ltp.orbit_continuation(gait, 'delta', deltas)
print(branch)
cplt = branch.plot(title='Hopping gait versus leg extension delta')
cplt.figure.savefig('clockfree_hopper_branch.png', dpi=100)
