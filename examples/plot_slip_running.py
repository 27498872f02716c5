"""
The running SLIP as an autonomous hybrid plant
==============================================

``slip_model`` predicts the strides of the extended spring-loaded inverted
pendulum (thesis Chapter 2) by composing flight, stance and collision maps.
``slip_running`` writes the same model as a clock-free
`ltpcontrol.HybridPlant`; the apex-to-apex (stride) map then comes from the
orbit machinery, `ltpcontrol.poincare_map` on the apex section ``vz = 0``,
with its Jacobian from the variational equations and the saltation
matrices of touchdown and liftoff.

Left: next-apex height and speed against the apex height, from the hybrid
plant (lines) and from ``slip_model.predict_stride`` with the numerically
integrated damped stance ``"SLIPD"`` (markers).  Right: one stride of the
body from both.  The printout compares the stride-map Jacobian with finite
differences of ``predict_stride``, and gives the multipliers of the lossless
running gait at the neutral touchdown angle: 1 (energy is conserved, so
the gaits form a family) and the one that decides whether the apex height
returns to the gait.
"""

import os

import matplotlib

matplotlib.use('Agg')

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402
from slip_model import (SLIPParams, neutral_touchdown_angle, predict_stride,  # noqa: E402
                        stride_trajectory)
from slip_running import apex_return_map, apex_state, slip_plant  # noqa: E402

QUICK = bool(os.environ.get('LTP_EXAMPLES_QUICK'))

P, theta, speed = SLIPParams(), -0.2, 1.0
plant = slip_plant(P, theta)
heights = np.linspace(0.26, 0.36, 4 if QUICK else 11)
ours = np.array([apex_return_map(plant, [0.0, speed, z])[0] for z in heights])
theirs = predict_stride(np.column_stack([0 * heights, speed + 0 * heights, heights]), theta, P,
                        method='SLIPD')
print("largest difference of the next apex [vy, z]:",
      f"{np.max(np.abs(ours - np.column_stack([theirs.apex.vy, theirs.apex.z]))):.2e}")

apex = np.array([0.0, speed, 0.3])
_, T, J = apex_return_map(plant, apex, jacobian=True)
h, fd = 1e-6, np.empty((2, 2))
for j, i in enumerate((1, 2)):
    sp, sm = (predict_stride(apex + d, theta, P, method='SLIPD')
              for d in (h * np.eye(3)[i], -h * np.eye(3)[i]))
    fd[:, j] = [sp.apex.vy - sm.apex.vy, sp.apex.z - sm.apex.z]
print("stride-map Jacobian (hybrid plant):\n", J)
print("largest difference to finite differences of predict_stride:",
      f"{np.max(np.abs(J - fd / (2 * h))):.1e}")

lossless = SLIPParams(m_l=0.0, d=0.0, d_h=0.0, d_v=0.0)
for v in ((1.0,) if QUICK else (1.0, 1.5)):
    gait_apex = np.array([0.0, v, 0.3])
    theta_n = float(neutral_touchdown_angle(gait_apex, lossless, method='SLIP'))
    nxt, _, J0 = apex_return_map(slip_plant(lossless, theta_n), gait_apex, jacobian=True)
    mu = np.sort(np.linalg.eigvals(J0).real)
    print(f"lossless gait at {v} m/s, apex 0.3 m: neutral angle {theta_n:.5f} rad, "
          f"return-map multipliers {mu}")

fig, axes = plt.subplots(1, 2, figsize=(10, 4))
axes[0].plot(heights, ours[:, 1], 'C0-', label="next apex z (hybrid plant)")
axes[0].plot(heights, theirs.apex.z, 'C0o', mfc='none', label="slip_model SLIPD")
axes[0].plot(heights, ours[:, 0], 'C1-', label="next apex ẏ (hybrid plant)")
axes[0].plot(heights, theirs.apex.vy, 'C1o', mfc='none', label="slip_model SLIPD")
axes[0].set(xlabel='apex height z [m]', ylabel='next apex [m, m/s]',
            title=f'Stride map, ẏ = {speed} m/s, θ_td = {theta} rad')
axes[0].legend(fontsize=7)

t = np.linspace(0, T, 300)
resp = ltp.simulate_hybrid(plant, t, apex_state(apex), 'flight')
y = np.concatenate([[0.0], np.cumsum(np.diff(t) * (resp.states[2, 1:] + resp.states[2, :-1]) / 2)])
axes[1].plot(y, resp.states[1], label='hybrid plant')
ys, zs, _, _ = stride_trajectory(apex, theta, P, 'SLIPD', t[::10])
axes[1].plot(ys, zs, 'k.', label='slip_model')
axes[1].set(xlabel='y [m]', ylabel='z [m]', title='One stride (apex to apex)')
axes[1].legend(fontsize=8)
fig.tight_layout()
fig.savefig('slip_running.png', dpi=100)
