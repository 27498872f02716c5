"""
Bifurcations of periodic orbits
===============================

`ltpcontrol.orbit_continuation` follows an orbit in one plant parameter and
reads bifurcations from its stability multipliers.

*Fold of cycles.*  In polar coordinates ``ṙ = r (p + r² − r⁴)``, ``θ̇ = 1``
the stable cycle ``r² = (1 + √(1 + 4p))/2`` meets the unstable one at
``p = −1/4``, where its multiplier ``exp(2π · 2r² (1 − 2r²))`` reaches +1.
Natural-parameter continuation cannot turn around the fold: it halves its
steps as the multiplier tends to 1 and locates the fold by extrapolation.

*Period doubling.*  The Rössler system ``ẋ = −y − z, ẏ = x + a y,
ż = b + z (x − c)`` with ``a = b = 0.2`` has a stable cycle whose multiplier
crosses −1 near ``c = 2.83``, the first step of its period-doubling cascade.
"""

import os

import matplotlib

matplotlib.use('Agg')

import control as ct  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402

QUICK = bool(os.environ.get('LTP_EXAMPLES_QUICK'))


def normal_form(t, x, u, p):
    r2 = x[0] ** 2 + x[1] ** 2
    g = p['p'] + r2 - r2 ** 2
    return [x[0] * g - x[1], x[1] * g + x[0]]


def normal_form_jacobian(t, x, u, p):
    r2 = x[0] ** 2 + x[1] ** 2
    g, dg = p['p'] + r2 - r2 ** 2, 2 - 4 * r2
    return [[g + dg * x[0] ** 2, dg * x[0] * x[1] - 1],
            [dg * x[0] * x[1] + 1, g + dg * x[1] ** 2]]


sys = ct.nlsys(normal_form, None, states=2, inputs=0, params={'p': 0.0}, name='fold')
orbit = ltp.limit_cycle(sys, 6.0, [1.0, 0.0], jacobian=normal_form_jacobian)
branch = ltp.orbit_continuation(orbit, 'p', np.linspace(0, -0.28, 5 if QUICK else 8))
(fold,) = branch.bifurcations
print(branch)
print(f"fold at p = {fold.value:.8f} (exact -0.25, error {fold.value + 0.25:.1e})")
cplt = branch.plot(title='Fold of cycles of ṙ = r (p + r² − r⁴)')
cplt.figure.savefig('orbit_fold.png', dpi=100)


def rossler(t, x, u, p):
    return [-x[1] - x[2], x[0] + p['a'] * x[1], p['b'] + x[2] * (x[0] - p['c'])]


def rossler_jacobian(t, x, u, p):
    return [[0, -1, -1], [1, p['a'], 0], [x[2], 0, x[0] - p['c']]]


sys = ct.nlsys(rossler, None, states=['x', 'y', 'z'], inputs=0,
               params={'a': 0.2, 'b': 0.2, 'c': 2.5}, name='rossler')
orbit = ltp.limit_cycle(sys, 5.7, [0.0, 3.0, 1.8], section=lambda x: x[0], direction=-1,
                        jacobian=rossler_jacobian)
values = np.linspace(2.5, 3.0, 3 if QUICK else 6)
branch = ltp.orbit_continuation(orbit, 'c', values)
(pd,) = branch.bifurcations
print(branch)
print(f"period doubling at c = {pd.value:.8f}, multiplier {pd.multiplier.real:.8f}")
cplt = branch.plot(title='Rössler system (a = b = 0.2): period doubling')
cplt.figure.savefig('orbit_period_doubling.png', dpi=100)
