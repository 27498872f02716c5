"""
Limit cycles of the van der Pol oscillator
==========================================

``ẍ − μ (1 − x²) ẋ + x = 0`` has no clock: its period is an unknown of the
problem.  `ltpcontrol.limit_cycle` finds the orbit by shooting with the
Poincaré section ``ẋ = 0`` (crossed downwards) as phase condition, for
μ = 0.5, 1 and 5.  The monodromy matrix has the phase multiplier 1 and one
stability multiplier, which Liouville's formula gives independently as
``exp(∫ μ (1 − x̄²) dt)`` over one period.  For μ = 5 that multiplier
(about 1e-37) is far below the rounding level of the monodromy matrix,
whose eigenvalue is then a rounding-level number (about 1e-14): the
orbit is strongly attracting either way.
"""

import matplotlib

matplotlib.use('Agg')

import control as ct  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402


def vdp(t, x, u, p):
    return [x[1], p['mu'] * (1 - x[0] ** 2) * x[1] - x[0]]


def vdp_jacobian(t, x, u, p):
    return [[0, 1], [-2 * p['mu'] * x[0] * x[1] - 1, p['mu'] * (1 - x[0] ** 2)]]


fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
print(f"{'mu':>4} {'period':>12} {'phase mult. - 1':>16} {'stability mult.':>16} "
      f"{'Liouville':>12}")
for mu in (0.5, 1.0, 5.0):
    sys = ct.nlsys(vdp, None, states=['x', 'v'], inputs=0, params={'mu': mu}, name='vdp')
    orbit = ltp.limit_cycle(sys, None, [2.0, 0.0], section=lambda x: x[1], direction=-1,
                            jacobian=vdp_jacobian, npoints=800)
    t = np.linspace(0, orbit.period, 4001)
    x = orbit(t)
    div = mu * (1 - x[0] ** 2)
    liouville = np.exp(np.sum((div[1:] + div[:-1]) / 2 * np.diff(t)))
    (lam,) = orbit.stability_multipliers
    print(f"{mu:4g} {orbit.period:12.8f} {orbit.phase_multiplier - 1:16.2e} "
          f"{lam.real:16.6e} {liouville:12.6e}")
    axes[0].plot(x[0], x[1], label=f"μ = {mu:g}, T = {orbit.period:.4f}")
    axes[0].plot(*orbit.x0, 'ko', ms=4)
    axes[1].plot(t / orbit.period, x[0], label=f"μ = {mu:g}")
axes[0].axhline(0, color='k', lw=0.6, ls=':')
axes[0].set(xlabel='x', ylabel='ẋ', title='Limit cycles (dots: start on the section ẋ = 0)')
axes[0].legend(fontsize=8)
axes[1].set(xlabel='t / T', ylabel='x', title='One period')
fig.tight_layout()
fig.savefig('van_der_pol_orbit.png', dpi=100)
