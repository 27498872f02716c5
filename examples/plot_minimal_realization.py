r"""
Minimal realization of a periodic system: an order that changes with the step
=============================================================================

A multirate sampled-data model carries hold states: the last command of an
actuator that updates every 2 steps and the last sample of a sensor read
every 3 steps.  At step 0 of the 6-step period both channels refresh, so
neither hold is needed there; at the other steps one or the other is.  The
minimal periodic realization (`ltpcontrol.minreal`) therefore has an order
that varies over the period — a `ltpcontrol.DiscreteLTPSystem`, whose
matrices ``A_k`` are ``n_{k+1} x n_k``.

Second, a periodic system with one unreachable and one unobservable mode,
hidden by a random periodic change of coordinates, is reduced to its
minimal order.  Both reductions keep the input-output map exactly: the
figure compares the largest singular value of the lifted transfer function
(`ltpcontrol.lift`, standard time lifting) before and after.
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import control as ct  # noqa: E402

import ltpcontrol as ltp  # noqa: E402

# %%
# Multirate model: hold states that are needed only at some steps
# ---------------------------------------------------------------

G = ct.ss([[0.0, 1.0], [-4.0, -0.4]], [[0.0], [1.0]], [[1.0, 0.0]], 0)
P = ltp.sample_multirate(G, 0.01, input_periods=[2], output_periods=[3])
Pmin = ltp.minreal(P)
print(P.nstates, '->', Pmin.nstates)
print(repr(Pmin))

# %%
# Hidden modes under a random periodic change of coordinates
# -----------------------------------------------------------

rng = np.random.default_rng(3)
N = 4
A = np.zeros((N, 4, 4))
A[:, :2, :2] = 0.8 * rng.standard_normal((N, 2, 2))
A[:, 2, 2] = 1.2                              # unreachable (and unstable) mode
A[:, 3, 3] = 0.5                              # unobservable mode
A[:, 0, 2], A[:, 3, 0] = 0.7, 0.4
B = np.zeros((N, 4, 1))
B[:, :2] = rng.standard_normal((N, 2, 1))
B[:, 3] = 1.0
C = np.zeros((N, 1, 4))
C[:, :, :2] = rng.standard_normal((N, 1, 2))
C[:, 0, 2] = 1.0
T = np.eye(4) + 0.5 * rng.standard_normal((N, 4, 4))
Ti = np.linalg.inv(T)
big = ltp.ltpss(np.array([T[(k + 1) % N] @ A[k] @ Ti[k] for k in range(N)]),
                np.array([T[(k + 1) % N] @ B[k] for k in range(N)]),
                np.array([C[k] @ Ti[k] for k in range(N)]), 0, period=N * 0.1, dt=0.1)
small = ltp.minreal(big)
print(big.nstates, '->', small.nstates)

# %%
# The lifted transfer functions are unchanged
# --------------------------------------------

theta = np.linspace(1e-3, np.pi, 300)
fig, ax = plt.subplots(1, 2, figsize=(9, 3.6))
for a, (full, red, title) in zip(ax, ((P, Pmin, 'multirate model'),
                                      (big, small, 'hidden modes'))):
    Lf, Lr = ltp.lift(full, method='time'), ltp.lift(red, method='time')
    sf = [np.linalg.norm(Lf(np.exp(1j * th)), 2) for th in theta]
    sr = [np.linalg.norm(Lr(np.exp(1j * th)), 2) for th in theta]
    gap = max(np.abs(Lf(np.exp(1j * th)) - Lr(np.exp(1j * th))).max() for th in theta[::30])
    a.semilogy(theta, sf, lw=3, alpha=0.5, label='original')
    a.semilogy(theta, sr, '--', label=f'minimal (gap {gap:.0e})')
    a.set_title(title)
    a.set_xlabel(r'$\theta$ (lifted frequency, rad per period)')
    a.legend()
ax[0].set_ylabel(r'$\sigma_{max}$ of the lifted transfer function')
fig.tight_layout()
