"""Periodic output feedback on the reference toolbox's test plants (not run in CI).

Run with ``PYTHONPATH=. python examples/output_feedback_reference_cases.py``
(a few minutes on a shared machine).  Every gain is checked on the loop
``feedback(sys, K)`` by its independently computed Floquet multipliers.

* Bittanti and Colaneri's Example 1.2 (period 2π): constant, switching and
  first-order harmonic output gains, stabilization and LQ.
* The chocolate plant (period 2): no constant output gain stabilizes it,
  a gain switching at t = 1 or a first-order harmonic gain does (D = 0); with
  D = 1 the harmonic family needs an unbounded gain and is refused.
* Pitelkau's satellite sampled K = 120, 40, 20 and 10 times per orbit,
  Q = diag(2, 1, 0, 0), R = 1e-11 (the reference toolbox's test): LQ
  output feedback with a gain switching every k steps (k = 1: one gain
  per step; k = K: constant), checked by a hand-made closed-loop product
  and cost; the periodic LQR cost is a lower bound.
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
continuous = ltp.ltpss(a, b, np.eye(4)[:2], 0, period=Tp)
Q, R = np.diag([2.0, 1, 0, 0]), np.array([[1e-11]])


def independent(sat, K):
    """Closed-loop multipliers from the hand-made product of the steps, and
    the cost tr P_0 summed over one period by hand and over all periods by
    doubling the series."""
    N = sat.nsteps
    A, B, C, Kk = (M.sample(N) for M in (sat.A, sat.B, sat.C, K))
    W, Phi = np.zeros((4, 4)), np.eye(4)
    for k in range(N):
        KC = Kk[k] @ C[k]
        W += Phi.T @ (Q + KC.T @ R @ KC) @ Phi
        Phi = (A[k] - B[k] @ KC) @ Phi
    S, Pm = W, Phi
    for _ in range(60):
        S, Pm = S + Pm.T @ S @ Pm, Pm @ Pm
    return np.abs(np.linalg.eigvals(Phi)).max(), np.trace(S)


# the toolbox's configurations: K steps per orbit, gains switching every k steps
# (k = 1: one gain per step, pdlqofc; k = K: a constant gain)
for K, ks in ((120, (1, 2, 3, 10, 60, 120)), (40, (1, 40)), (20, (1, 20)), (10, (1, 10))):
    sat = ltp.sample_system(continuous, Tp / K)
    _, X, _ = ltp.dlqr(sat, Q, R)
    print(f"Pitelkau, {K} steps per orbit: periodic LQR (state feedback) cost "
          f"{np.trace(X(0.0)):.6g}, a lower bound", flush=True)
    for k in ks:
        start = time.process_time()
        Kg, info = ltp.oflqr(sat, Q, R, times=np.arange(0, K, k) * Tp / K, maxiter=2000)
        cpu = time.process_time() - start
        rho, cost = independent(sat, Kg) if Kg is not None else (np.nan, np.nan)
        print(f"  k={k:3d}: success={info.success!s:5s} cost={info.cost:.8g} (independent "
              f"{cost:.8g}) max|mu|={rho:.4g} (info {np.abs(info.multipliers).max():.4g}) "
              f"nit={info.nit} cpu={cpu:.1f}s  {info.message[:60]}", flush=True)

# 10 steps per orbit, constant gain: the homotopy from zero does not find a
# stabilizing gain (oflqr then restarts from the projected periodic LQR gain);
# an independent check that one exists: a log-spaced grid of the two gains and
# Nelder-Mead from its ten best points
from scipy.optimize import minimize  # noqa: E402
sat = ltp.sample_system(continuous, Tp / 10)
A, B, C = (M.sample(10) for M in (sat.A, sat.B, sat.C))


def radius(F):
    M = np.broadcast_to(np.eye(4), (F.shape[0], 4, 4))
    for k in range(10):
        M = (A[k] - B[k] @ F @ C[k]) @ M
    return np.abs(np.linalg.eigvals(M)).max(-1)


v = np.concatenate([-np.logspace(0, 8, 97)[::-1], [0], np.logspace(0, 8, 97)])
grid = np.stack(np.meshgrid(v, v, indexing='ij'), -1).reshape(-1, 1, 2)
r = radius(grid)
runs = [minimize(lambda x: radius(x[None, None, :])[0], grid[i, 0], method='Nelder-Mead',
                 options={'xatol': 1e-3, 'fatol': 1e-14, 'maxiter': 4000})
        for i in np.argsort(r)[:10]]
best = min(runs, key=lambda res: res.fun)
print(f"10 steps, constant gain: best max|mu| on the grid {r.min():.4g}, after Nelder-Mead "
      f"{best.fun:.4g} at F = {best.x}")
Kg, info = ltp.oflqr(sat, Q, R)
print(f"  oflqr from zero: success={info.success} cost={info.cost:.8g} ({info.message[:70]})")
Kg, info = ltp.oflqr(sat, Q, R, K0=best.x[None, :])
print(f"  oflqr from that gain: success={info.success} cost={info.cost:.8g} "
      f"max|mu|={independent(sat, Kg)[0]:.4g} ({info.message[:40]})")
