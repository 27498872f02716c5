"""P12: stability lobe diagram of 1-DOF milling (Insperger-Stépán's benchmark).

Workload: ``m x'' + c x' + k x = -a_p h(t) (x(t) - x(t - τ))``, up-milling,
2 teeth, 5 % radial immersion, f_n = 922 Hz, ζ = 0.011, m = 0.03993 kg,
K_t = 6e8, K_n = 2e8 N/m²; τ = 60/(N Ω) is the period.  The lobe diagram is
the critical depth a_p at 200 spindle speeds Ω in [5000, 25000] rpm: at
each speed ``max|μ|`` on a grid of depths, then the lowest crossing of
``|μ| = 1`` refined by Brent's method.

* ours: ``ltp.stability_chart`` of ``ltp.ltpdss`` models (spectral-element
  monodromy, degree 12 during the sweep, boundary checked at degree 20),
  serial (P12a); P12b is the wall-clock speed-up of two joblib workers
  over one in the same run (the workers' CPU time is not the suite's
  process's, and on a loaded machine the speed-up is what the load leaves),
  on the warm pool, with the first call's time (worker start-up included)
  and the per-task overhead in its notes.  The model is
  ``examples/milling_models.py``, shared with the gallery's lobe diagram.
* peer: zeroth-order semi-discretization (Insperger & Stépán 2004): m steps
  per period, the delayed term ``(x_{i-m} + x_{i-m+1})/2`` on each step,
  exact exponentials of the averaged coefficients, the monodromy built with
  the shift structure (O(m) per step and column, a ring buffer for the
  delayed positions) and its dominant eigenvalues (LAPACK up to 200
  coordinates, ARPACK above); the same depth grid and Brent refinement.
  Its error falls as 1/m²: m is predicted from the errors at m = 50 and 100
  so that the lobes reach ``ACC`` (untimed), and the timed run reports the
  error it reached.

Accuracy: relative error of the critical depths against a reference from
the library at degree 20 and tolerance 1e-10 (cross-checked against an
independent method-of-steps monodromy in the tests); both sides must reach
``ACC`` at the check speeds for the ratio to count.  The peer's time is
measured on every 50th speed and extrapolated to 200.
"""

import os
import pathlib
import sys
import time

import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq
from scipy.sparse.linalg import eigs

from _common import median_time, row

import ltpcontrol as ltp

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
# the model, shared with the gallery's lobe diagram
from examples.milling_models import WN, ZETA, MASS, cut, h_mean  # noqa: E402
from examples.milling_models import milling as model  # noqa: E402

ACC = 1e-4
DEPTHS = np.linspace(1e-5, 5e-3, 21)
FULL = dict(speeds=200, repeats=1, peer_every=50, acc=ACC)
QUICK = dict(speeds=2, repeats=1, peer_every=2, acc=5e-2)


class SemiDiscretization:
    """Zeroth-order semi-discretization of the milling model at one speed."""

    def __init__(self, rpm, m):
        h, t_ex, T = cut(rpm)
        self.m, self.dt = m, T / m
        self.hbar = np.array([h_mean(rpm, i * self.dt, (i + 1) * self.dt) for i in range(m)])

    def radius(self, ap):
        m, dt = self.m, self.dt
        size = m + 2
        xv = np.zeros((2, size))
        xv[0, 0] = xv[1, 1] = 1.0
        ring = np.zeros((m + 1, size))          # positions x_{i-1}, ..., x_{i-m-1}
        ring[np.arange(m), 2 + np.arange(m)] = 1.0
        head = 0                                 # ring[head] is x_{i-1}
        A0 = np.array([[0.0, 1.0], [-WN**2, -2 * ZETA * WN]])
        P0 = expm(A0 * dt)
        for i in range(m):
            hb = ap * self.hbar[i] / MASS
            if hb == 0:
                new = P0 @ xv
            else:
                Ai = A0 + np.array([[0.0, 0.0], [-hb, 0.0]])
                Pi = expm(Ai * dt)
                Ri = (Pi - np.eye(2)) @ np.linalg.solve(Ai, np.array([0.0, hb]))
                # x(t - τ) ≈ (x_{i-m} + x_{i-m+1}) / 2 on [t_i, t_{i+1}]
                x_im = ring[(head + m - 1) % (m + 1)]
                x_im1 = ring[(head + m - 2) % (m + 1)] if m > 1 else xv[0]
                new = Pi @ xv + np.outer(Ri, 0.5 * (x_im + x_im1))
            head = (head - 1) % (m + 1)
            ring[head] = xv[0]
            xv = new
        rows = [xv[0], xv[1]] + [ring[(head + k) % (m + 1)] for k in range(m)]
        Phi = np.array(rows)
        if size <= 200:
            return float(np.max(np.abs(np.linalg.eigvals(Phi))))
        # dominant multipliers only (ARPACK), as a large semi-discretization would
        return float(np.max(np.abs(eigs(Phi, k=4, which='LM', return_eigenvectors=False,
                                        tol=1e-12))))


def _critical(radius, depths, tol):
    """Lowest depth with radius 1 from a grid and Brent's method (NaN if none)."""
    prev = radius(depths[0])
    if not prev < 1:
        return np.nan
    for a, b in zip(depths[:-1], depths[1:]):
        cur = radius(b)
        if cur >= 1:
            return brentq(lambda x: np.log(radius(x)), a, b, xtol=tol * b)
        prev = cur
    return np.nan


def peer_lobes(speeds, m):
    return np.array([_critical(SemiDiscretization(r, m).radius, DEPTHS, 1e-9)
                     for r in speeds])


def ours_lobes(speeds, n_jobs=1, order=12, tol=1e-7, backend=None):
    chart = ltp.stability_chart(model, speeds, DEPTHS, n_jobs=n_jobs, order=order, tol=tol,
                                progress=False, on_error='keep', backend=backend)
    return chart.critical()


def _rel(a, b):
    ok = np.isfinite(b)
    if not np.array_equal(ok, np.isfinite(a)):
        return np.inf
    return float(np.max(np.abs(a[ok] / b[ok] - 1), initial=0.0))


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    speeds = np.linspace(5000, 25000, cfg['speeds'])
    check = speeds[::cfg['peer_every']]
    log(f"P12: milling lobes, {len(speeds)} speeds: reference")
    ref = ours_lobes(speeds, order=16 if quick else 20, tol=1e-8 if quick else 1e-10)
    ref_check = ref[::cfg['peer_every']]
    log("P12: semi-discretization resolution")
    # the error falls as 1/m² (first-order method on a second-order quantity): m from the
    # errors at m = 50 and 100, then the timed run reports the error it reached
    e1, e2 = (_rel(peer_lobes(check, mm), ref_check) for mm in (50, 100))
    rate = max(np.log2(e1 / e2), 1.0) if np.isfinite(e1 / e2) and e2 > 0 else 2.0
    m = int(np.ceil(100 * (1.6 * e2 / cfg['acc']) ** (1 / rate))) if e2 > cfg['acc'] else 100
    m = min(max(m, 50), 4000)
    log(f"P12: peer with m = {m}; timing")
    t_peer, ptimes, peer_check = median_time(lambda: peer_lobes(check, m), cfg['repeats'])
    err_peer = _rel(peer_check, ref_check)
    t_peer *= len(speeds) / len(check)
    log("P12: ours, serial")
    t_ours, times, lobes = median_time(lambda: ours_lobes(speeds), cfg['repeats'])
    err = _rel(lobes, ref)
    rows = [row(
        'P12a', f'1-DOF milling lobe diagram, {len(speeds)} speeds x refined depth',
        ours='ltp.stability_chart of ltpdss models (serial)',
        peer=f'zeroth-order semi-discretization, m={m}, same grid and Brent refinement',
        t_ours=t_ours, t_peer=t_peer, err_ours=err, err_peer=err_peer, tol=cfg['acc'],
        target=10.0, target_met=(t_peer / t_ours >= 10) if not quick else None,
        checks={'ours <= tol': err <= cfg['acc']}, matched=err_peer <= cfg['acc'],
        notes=(f'peer timed on {len(check)} speeds, extrapolated; m from its '
               f'convergence rate so that its lobes reach {cfg["acc"]:g}'),
        extra=dict(ours_times=times, peer_times=ptimes, m=m, speeds=speeds.tolist(),
                   critical_depth=[float(x) for x in lobes]))]
    # parallel: wall clock on both sides (the workers' CPU time is not this process's)
    rows.append(_parallel_row(speeds, ref, cfg, quick, log))
    return rows


def _noop(factory):
    return None


def _burn(n):
    s = 0
    for i in range(n):
        s += i * i
    return s


def _control_speedup(backend, n, tasks=8):
    """Speed-up of two workers on pure-Python tasks of equal size: what the machine allows."""
    import joblib
    t0 = time.perf_counter()
    for _ in range(tasks):
        _burn(n)
    serial = time.perf_counter() - t0
    with joblib.parallel_config(backend=backend, n_jobs=2):
        t0 = time.perf_counter()
        joblib.Parallel()(joblib.delayed(_burn)(n) for _ in range(tasks))
    return serial / (time.perf_counter() - t0)


def _parallel_row(speeds, ref, cfg, quick, log):
    """P12b: two workers against one, wall clock; the pool's start-up and per-task cost.

    The chart runs in a few chunks of columns per worker (the factory is
    pickled once per chunk); loky's pool is started by the first parallel
    call and reused by the next ones, so the start-up is reported apart
    from the warm speed-up.  The per-task overhead is the round trip of an
    empty task carrying the factory, on the warm pool; the speed-up of
    pure-Python tasks of equal size on the same pool tells what the machine
    allows (on a machine loaded by other sessions it can be near 1).
    """
    import joblib
    backend = 'threading' if quick else 'loky'   # quick: no worker start-up in the smoke run
    log("P12: ours, serial and two workers (wall clock)")
    t0 = time.perf_counter()
    lobes1 = ours_lobes(speeds, n_jobs=1)
    wall1 = time.perf_counter() - t0
    t0 = time.perf_counter()
    lobes_cold = ours_lobes(speeds, n_jobs=2, backend=backend)
    cold = time.perf_counter() - t0
    t0 = time.perf_counter()
    lobes2 = ours_lobes(speeds, n_jobs=2, backend=backend)
    wall2 = time.perf_counter() - t0
    ntask = 40
    with joblib.parallel_config(backend=backend, n_jobs=2):
        joblib.Parallel()(joblib.delayed(_noop)(model) for _ in range(2))
        t0 = time.perf_counter()
        joblib.Parallel()(joblib.delayed(_noop)(model) for _ in range(ntask))
        per_task = (time.perf_counter() - t0) / ntask
    control = _control_speedup(backend, 20_000 if quick else 2_000_000)
    err2 = max(_rel(lobes2, ref), _rel(lobes_cold, ref))
    load = os.getloadavg()[0]
    return row(
        'P12b', f'1-DOF milling lobe diagram, {len(speeds)} speeds, parallel speed-up',
        ours=f'ltp.stability_chart, n_jobs=2 ({backend}, 8 chunks, warm pool)',
        peer='the same, n_jobs=1', t_ours=wall2, t_peer=wall1, metric='speed-up',
        value=wall1 / wall2, err_ours=err2, err_peer=_rel(lobes1, ref), tol=cfg['acc'],
        checks={'ours <= tol': err2 <= cfg['acc']}, matched=True,
        notes=(f'wall clock; first parallel call (pool start-up included) {cold:.2f} s '
               f'= {wall1 / cold:.2f}x; per-task overhead {1e3 * per_task:.1f} ms; '
               f'pure-Python control tasks {control:.2f}x; load average {load:.1f} on '
               f'{os.cpu_count()} cores'),
        extra=dict(wall_serial=wall1, wall_parallel_warm=wall2, wall_parallel_cold=cold,
                   per_task_overhead=per_task, control_speedup=control, load_average=load))
