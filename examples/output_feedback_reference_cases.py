"""Periodic output feedback on the reference toolbox's test plants (not run in CI).

Run with ``PYTHONPATH=. python examples/output_feedback_reference_cases.py``
(a few minutes on a shared machine).  Every gain is checked on the loop
``feedback(sys, K)`` by its independently computed Floquet multipliers.

* Bittanti and Colaneri's Example 1.2 (period 2π): constant, switching and
  first-order harmonic output gains, stabilization and LQ.
* The chocolate plant (period 2): no constant output gain stabilizes it,
  a gain switching at t = 1 or a first-order harmonic gain does (D = 0); with
  D = 1 the harmonic family needs an unbounded gain and is refused.
* Pitelkau's satellite sampled 120 times per orbit, Q = diag(2, 1, 0, 0),
  R = 1e-11: LQ output feedback with a constant, a two-piece and a
  per-step (120 gains) switching gain; the periodic LQR cost is the lower
  bound.
"""

import time
import warnings

import numpy as np

import ltpcontrol as ltp


def report(name, K, info):
    mu = np.abs(ltp.floquet_multipliers(ltp.feedback(plant_of[name], K))).max() \
        if K is not None else np.nan
    print(f"{name:42s} success={info.success!s:5s} sdeg={info.sdeg: .6g} "
          f"cost={info.cost: .6g} max|mu|={mu:.6g}  ({info.message[:50]})", flush=True)


warnings.simplefilter('ignore')
plant_of = {}
T = 2 * np.pi
bc = ltp.ltpss(lambda t: np.array([[-1 + np.sin(t), 0], [1 - np.cos(t), -3]]),
               lambda t: np.array([[-1 - np.cos(t)], [2 - np.sin(t)]]), [[0, 1.0]], 0,
               period=T)
for label, kw in (('constant', {}), ('switching [0, pi]', {'times': [0, np.pi]}),
                  ('harmonic order 1', {'order': 1})):
    for kind in ('ofstab', 'oflqr'):
        name = f"B&C Ex. 1.2 {kind} {label}"
        plant_of[name] = bc
        start = time.time()
        K, info = (ltp.ofstab(bc, maxiter=50, **kw) if kind == 'ofstab'
                   else ltp.oflqr(bc, np.eye(2), [[1.0]], **kw))
        report(name, K, info)

d = 0.9
for D in (0.0, 1.0):
    choc = ltp.ltpss([[0, 1], [-1, 2 * d]], [[0], [1]], [[-2, 2 * d]], D, period=2.0)
    for label, kw in (('constant', {}), ('switching [0, 1]', {'times': [0, 1.0]}),
                      ('harmonic order 1', {'order': 1})):
        name = f"chocolate D={D} ofstab {label}"
        plant_of[name] = choc
        K, info = ltp.ofstab(choc, maxiter=50, **kw)
        report(name, K, info)

w0 = 0.00103448
Tp = 2 * np.pi / w0
a = np.array([[0, 0, 5.318064566757217e-02, 0], [0, 0, 0, 5.318064566757217e-02],
              [-1.352134256362805e-03, 0, 0, -7.099273035392090e-02],
              [0, -7.557182037479544e-04, 3.781555288420663e-02, 0]])
b = lambda t: np.array([[0], [0], [0.1389735e-6 * np.sin(w0 * t)],  # noqa: E731
                        [-0.3701336e-7 * np.cos(w0 * t)]])
sat = ltp.sample_system(ltp.ltpss(a, b, np.eye(4)[:2], 0, period=Tp), Tp / 120)
Q, R = np.diag([2.0, 1, 0, 0]), np.array([[1e-11]])
for label, times in (('constant', None), ('2 pieces', np.array([0, 60]) * Tp / 120),
                     ('120 pieces', np.arange(120) * Tp / 120)):
    name = f"Pitelkau oflqr {label}"
    plant_of[name] = sat
    K, info = ltp.oflqr(sat, Q, R, times=times)
    report(name, K, info)
_, X, _ = ltp.dlqr(sat, Q, R)
print(f"periodic LQR (state feedback) cost, the lower bound: {np.trace(X(0.0)):.6g}")
