r"""
Gramians, norms and zeros of a periodic system
==============================================

The damped Mathieu equation of thesis eq. (4.24) with a periodically
modulated actuator and a velocity-weighted sensor,

.. math::

    \ddot x + 2\zeta\omega_n \dot x + (1 + 2\beta\cos\omega_p t)\,\omega_n^2 x
    = (1 + 0.4\cos\omega_p t)\,u, \qquad y = x + 0.3\,\dot x/\omega_n,

is analysed the way python-control analyses an LTI system: periodic
gramians (`ltpcontrol.gram`), the H2, L∞ and Hankel norms
(`ltpcontrol.norm`) and the transmission zeros (`ltpcontrol.zeros`).

The figure shows the gramians over one period — a periodic system is more
or less controllable and observable depending on the phase — and the
largest Hankel singular value ``sqrt(λ_max(P(t) Q(t)))``, whose maximum over
the start time ``t`` is the Hankel norm.  The lower panel shows σ_max of
the harmonic transfer function over ``[0, ω_p/2]`` (beyond which it
repeats) with the certified L∞ norm and its peak frequency marked.
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402

# %%
# The system
# ----------

T, wn, zeta, beta = 0.5, 2 * np.pi * 0.37, 0.1, 0.3
wp = 2 * np.pi / T
A = ltp.PeriodicMatrix([[[0, 0], [-beta * wn ** 2, 0]],
                        [[0, 1], [-wn ** 2, -2 * zeta * wn]],
                        [[0, 0], [-beta * wn ** 2, 0]]], T)
B = ltp.PeriodicMatrix([[[0], [0.2]], [[0], [1]], [[0], [0.2]]], T)
sys = ltp.ltpss(A, B, [[1.0, 0.3 / wn]], 0, period=T, name='mathieu')
print("Floquet exponents:", np.round(ltp.floquet_exponents(sys), 4))

# %%
# Gramians, norms and zeros
# -------------------------

P, Q = ltp.gram(sys, 'c'), ltp.gram(sys, 'o')
t = np.linspace(0, T, 201)
Pt, Qt = P(t), Q(t)
hsv = np.sqrt([np.linalg.eigvals(p @ q).real.max() for p, q in zip(Pt, Qt)])

h2 = ltp.norm(sys, 2)
hankel = ltp.norm(sys, 'hankel')
linf, wpeak = ltp.norm(sys, 'inf', return_frequency=True)
print(f"H2 norm     {h2:.6f}")
print(f"Hankel norm {hankel:.6f}  (at t = 0 alone: {hsv[0]:.6f})")
print(f"L-inf norm  {linf:.6f}  at {wpeak:.4f} rad/s")
print("zeros:", np.round(ltp.zeros(sys), 4))

# %%
# The figure
# ----------

H = ltp.htf(sys, 3)
w = np.linspace(0, wp / 2, 600)
sigma = np.linalg.norm(H(1j * w), ord=2, axis=(0, 1))

fig, axes = plt.subplots(3, 1, figsize=(7, 8.5), constrained_layout=True)
ax = axes[0]
for i, name in enumerate(['position', 'velocity']):
    ax.plot(t, Pt[:, i, i] / Pt[:, i, i].mean(), label=f'P(t), {name}')
    ax.plot(t, Qt[:, i, i] / Qt[:, i, i].mean(), '--', label=f'Q(t), {name}')
ax.set_xlabel('t [s]')
ax.set_ylabel('relative to the mean')
ax.set_title('diagonals of the controllability (P) and observability (Q) gramians')
ax.legend(fontsize=8, ncol=2)
ax = axes[1]
ax.plot(t, hsv)
ax.axhline(hankel, color='k', lw=0.8, ls=':', label=f'Hankel norm {hankel:.4f}')
ax.set_xlabel('start time t [s]')
ax.set_title('largest Hankel singular value over the start time')
ax.legend(fontsize=8)
ax = axes[2]
ax.plot(w, sigma, label='σ_max of the HTF (K = 3)')
ax.plot([wpeak], [linf], 'o', color='C3', label=f'L∞ = {linf:.4f} at {wpeak:.3f} rad/s')
ax.set_xlabel('ω [rad/s]')
ax.set_title('HTF gain over one fundamental interval')
ax.legend(fontsize=8)
fig.savefig('analysis.png', dpi=90)
