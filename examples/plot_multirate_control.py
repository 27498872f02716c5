r"""
Multirate digital control: an actuator at 2 ms, a sensor at 3 ms
================================================================

A lightly damped, unstable plant

.. math::

    \ddot x = 4 x - 0.2\,\dot x + u, \qquad y = x,

is controlled by a digital controller whose base step is ``Ts = 1 ms``; the
actuator accepts a new command every 2 ms (held in between) and the sensor
delivers a sample every 3 ms (the controller keeps the last one).  The
sampled-data plant is a periodic system of period 6 ms
(`ltpcontrol.sample_multirate`).  An LQ state feedback and a Kalman
predictor are designed on that periodic model with `ltpcontrol.dlqr` and
`ltpcontrol.dlqe`; the observer-based controller is a periodic system of
the same period.

The closed loop is then checked three ways: its stability verdict against
the lifted LTI closed loop, its gain and phase margins through the lifting
(`ltpcontrol.lifted_margins`), and a simulation of the *continuous* plant
(exact zero-order hold between the instants where the actuator updates)
driven by the controller.
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import scipy.linalg as la  # noqa: E402
import control as ct  # noqa: E402

import ltpcontrol as ltp  # noqa: E402

# %%
# The multirate model
# -------------------

G = ct.ss([[0.0, 1.0], [4.0, -0.2]], [[0.0], [1.0]], [[1.0, 0.0]], 0,
          inputs='u', outputs='y', states=['x', 'v'])
Ts = 1e-3
P = ltp.sample_multirate(G, Ts, input_periods=[2], output_periods=[3])
print(P.nsteps, P.state_labels)        # period 6 steps; plant states and the two holds

# %%
# LQ feedback and Kalman predictor on the periodic model
# ------------------------------------------------------

Q = np.diag([1e3, 1.0, 0.0, 0.0])
K, X, E = ltp.dlqr(P, Q, [[1e-3]])
L, Pe, Ee = ltp.dlqe(P, [[1.0]], [[1e-4]])
print("regulator multipliers", np.abs(E).max() ** P.nsteps)
print("predictor multipliers", np.abs(Ee).max() ** P.nsteps)

N = P.nsteps
Ak, Bk, Ck, Dk = (M.sample(N) for M in (P.A, P.B, P.C, P.D))
Kk, Lk = K.sample(N), L.sample(N)
# observer-based controller, input y, output K x_hat (the loop closes with u = -K x_hat)
Ac = Ak - Bk @ Kk - Lk @ Ck + Lk @ Dk @ Kk
ctrl = ltp.ltpss(Ac, Lk, Kk, 0, period=P.period, dt=Ts, inputs='y', outputs='Kx')

# %%
# Stability: periodic loop and lifted LTI loop agree
# --------------------------------------------------

closed = ltp.feedback(P, ctrl)
lifted = ct.feedback(ltp.lift(P, method='time'), ltp.lift(ctrl, method='time'))
print("periodic closed loop stable:", ltp.is_stable(closed),
      "| lifted LTI closed loop stable:",
      bool(np.abs(np.linalg.eigvals(lifted.A)).max() < 1))
gm, pm, gm_low = ltp.lifted_margins(ltp.series(P, ctrl))
print(f"gain margins x{gm:.2f} and /{gm_low:.2f}, phase margin {pm:.1f} deg")

# %%
# Simulation of the continuous plant
# ----------------------------------
#
# The controller runs at the base step with the held measurement; the
# plant sees the command that the actuator latched at its last update.

n = 2
M = np.zeros((n + 1, n + 1))
M[:n, :n], M[:n, n:] = G.A, G.B
E1 = la.expm(M * Ts)
Ad, Bd = E1[:n, :n], E1[:n, n:]
steps = 1200
x = np.array([0.05, 0.0])
xhat = np.zeros(4)
u_held, y_held = 0.0, 0.0
t, y_log, u_log = np.arange(steps) * Ts, [], []
for s in range(steps):
    k = s % N
    if s % 3 == 0:
        y_held = (G.C @ x)[0]                   # the sensor samples
    cmd = -(Kk[k] @ xhat)[0]
    if s % 2 == 0:
        u_held = cmd                            # the actuator updates
    y_log.append((G.C @ x)[0])
    u_log.append(u_held)
    xhat = Ac[k] @ xhat + Lk[k] @ np.array([y_held])
    x = Ad @ x + Bd[:, 0] * u_held

fig, ax = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
ax[0].plot(t * 1e3, y_log, label='y = x (continuous plant)')
ax[0].set_ylabel('position')
ax[0].legend()
ax[1].step(t * 1e3, u_log, where='post', label='u (held 2 ms)')
ax[1].set_xlabel('time [ms]')
ax[1].set_ylabel('command')
ax[1].legend()
fig.suptitle('Multirate LQG: actuator every 2 ms, sensor every 3 ms')
fig.tight_layout()
