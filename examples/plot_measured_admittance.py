r"""
Impedance-based stability from a measured admittance, and a sampled-data loop
=============================================================================

A converter linearized about its periodic steady state is a periodic
*admittance* :math:`Y` (here a small two-state model modulated at the
fundamental, period 1 s).  In the laboratory it is not known as a model
but *measured*: its HTF is estimated from records of chirp replicas
(`ltpcontrol.estimate_htf`).  Connected to a network of impedance
:math:`Z = R + sL`, the loop :math:`L = ZY` decides stability.

`ltpcontrol.impedance_nyquist` counts the encirclements of the sampled
loop HTF (the improper :math:`sL` is exact on the HTF grid,
`ltpcontrol.rlc_impedance`).  Frequency samples cannot tell how many
unstable exponents the measured factor has: we state it
(``open_loop_unstable=0``, a converter stable on an ideal source).  The
verdict is set beside the exact count of the model
(`ltpcontrol.harmonic_product` realizes :math:`ZY` as one periodic system)
and the closed loop's Floquet multipliers, integrated independently.

The second part closes a digital controller around a damped Mathieu plant
through a zero-order hold (`ltpcontrol.sampled_loop`): one sampling period
of computation delay is tolerated, two are not
(`ltpcontrol.lifted_nyquist`).
"""

import os
import warnings

import matplotlib

matplotlib.use("Agg")

import control as ct  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

import ltpcontrol as ltp  # noqa: E402

T = 1.0
A0 = np.array([[-1.0, 3.0], [-3.0, -0.5]])
A1 = np.array([[0.4, 0.3j], [0.2, -0.2]])
A = ltp.PeriodicMatrix(np.stack([A1.conj(), A0 + 0j, A1]), T)
B = np.array([[1.0], [0.5]])
C = np.array([[1.0, 0.0]])
Y = ltp.ltpss(A, B, C, 0, period=T, name='Y')

# %%
# Measuring the admittance
# ------------------------
# Nine chirp replicas, shifted in the cycle phase, identify the components
# :math:`|k| \le 3` up to 7 Hz; the estimate's grid has a spacing that
# divides the fundamental, so the strip frequencies of the Nyquist
# criterion fall on it.

N, K = 6, 3
exc = ltp.chirp_replicas(T, 2 * K + 3, 12.0, 0.0, N + 1.0, dt=1 / 256, gap=8.0)
rec = ltp.forced_response(Y, exc.time, exc.inputs)
Ymeas = ltp.estimate_htf((exc.time, exc.inputs, rec.outputs), T, K, segments=exc.segments,
                         omega_limits=(0, (N + 1) * 2 * np.pi), name='Y measured')
w, G = Ymeas.components()
err = np.nanmax(np.abs(G - ltp.htf(Y, K).components(w)[1]))
print(f"estimate: {len(w)} frequencies, spacing {w[1] - w[0]:.4f} rad/s, "
      f"largest error {err:.1e}")


# %%
# Three networks, three verdicts
# ------------------------------

def floquet_radius(R, L):
    """Closed loop u = -(R y + L dy/dt) eliminated by hand, by solve_ivp."""
    cb = float((C @ B)[0, 0])

    def rhs(t, x):
        At = A(t)
        Kt = -(R * C + L * C @ At) / (1 + L * cb)
        return ((At + B @ Kt) @ x.reshape(2, 2)).ravel()
    sol = solve_ivp(rhs, (0, T), np.eye(2).ravel(), method='DOP853', rtol=1e-11, atol=1e-13)
    return np.abs(np.linalg.eigvals(sol.y[:, -1].reshape(2, 2))).max()


networks = {'R + sL': (0.5, 0.2), 'constant-power load': (-2.0, 0.2),
            'negative L': (2.0, -0.7)}
print(f"{'network':<20} {'measured Z':>10} {'model Z':>8} {'Floquet radius':>15}")
measured = {}
for label, (R, L) in networks.items():
    Z = ltp.LTIHTF(ct.tf([L, R], [1]), T, N, name='Z')
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')        # the count's caveats are in its report
        resp = measured[label] = ltp.impedance_nyquist((Z, Ymeas), N, open_loop_unstable=0)
    exact = ltp.nyquist_htf(ltp.harmonic_product(Z, Y), N)
    rho = floquet_radius(R, L)
    print(f"{label:<20} {resp.closed_loop_unstable:10d} {exact.closed_loop_unstable:8d} "
          f"{rho:15.4f}")
    assert resp.stable == exact.stable == (rho < 1)

print(measured['R + sL'].report(Hz=True))

# %%
# A digital controller with a computation delay
# ---------------------------------------------

Ap = ltp.PeriodicMatrix(np.array([[[0, 0], [-1.5, 0]], [[0, 1], [-4, -0.4]],
                                  [[0, 0], [-1.5, 0]]], complex), T)
plant = ltp.ltpss(Ap, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=T, name='Mathieu')
Kd = ct.tf([7.5, -5.0], [1, -0.3], 0.1)
sampled = {k: ltp.lifted_nyquist(ltp.sampled_loop(plant, Kd, 0.1, delay=k)) for k in (1, 2)}
for k, resp in sampled.items():
    print(f"delay {k} Ts: Z = {resp.closed_loop_unstable}, spectral radius "
          f"{np.abs(resp.multipliers).max():.4f}")

fig, axes = plt.subplots(1, 3, figsize=(13, 4.3))
for ax, label in zip(axes[:2], ('R + sL', 'constant-power load')):
    resp = measured[label]
    resp.plot(ax=ax, max_curve_magnitude=3, marker='.', linestyle='-',
              title=f"{label} (measured Y): Z = {resp.closed_loop_unstable}")
for k, resp in sampled.items():
    resp.plot(ax=axes[2], max_curve_magnitude=3, color=f'C{k}')
axes[2].set_title("sampled-data loop: lifted eigenloci")
axes[2].legend([plt.Line2D([], [], color=f'C{k}') for k in sampled],
               [f'delay {k} Ts' for k in sampled])
fig.tight_layout()
fig.savefig('measured_admittance.png', dpi=90)
if os.environ.get('LTP_SHOW'):
    plt.show()
