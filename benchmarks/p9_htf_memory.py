"""P9: memory and time of HTF evaluation for larger plants.

Workload: seeded random plants with a time-varying ``A(t) = A_0 + A_1 cos ω_p t``
(no Floquet structure to exploit), one input, one output, evaluated on a
grid of frequencies.  ``ltp.htf`` chooses its internal truncation (``K_i =
K + 10`` plus a convergence check at ``K_i + 8``), so the harmonic state
space has ``(2K_i + 1) n`` states: 820 for n = 20, K = 10.

* P9a: ``ltp.htf(sys, 10)`` and ``H(jω)`` (method 'auto') on 1000
  frequencies, n = 20, against the same request with ``method='modal'``;
  target: within 2x of the modal time with peak memory <= 1.5 GB.
* P9b: ``ltp.bode_htf`` of all 21 components on the same grid, against the
  modal evaluation of the full HTF; same targets.
* P9c: the dense path (``method='solve'``) on the same request: it must be
  chunked, not refused, with peak memory <= 1.5 GB (default budget
  ``ltp.config.defaults['htf.max_memory'] = 1 GB``).  It is timed on every
  10th frequency and extrapolated.
* P9d: ``htf`` + evaluation on 200 frequencies for n = 4, 20, 50 and
  K = 5, 10, 20 ('auto'); a request whose harmonic state space cannot fit
  the budget is refused with its estimated size (reported as such).

P9a-c run each in a fresh subprocess, which reports its CPU time, the
peak of `tracemalloc` (NumPy buffers; LAPACK workspace is not traced) and
the growth of the peak resident-set size (``ru_maxrss``) during the work.
The grid P9d (and ``--quick``) runs in this process and reports the
`tracemalloc` peak only.
Accuracy: the largest relative deviation from the other evaluation path
(dense resolvent solves for the modal results, the modal form for the
dense ones) at the same truncation, on 5 frequencies; tolerance 1e-8.
"""

import json
import os
import subprocess
import sys

from _common import row

TOL = 1e-8
LIMIT = 1.5e9
FULL = dict(n=20, K=10, npoints=1000, stride=10, grid_n=(4, 20, 50), grid_K=(5, 10, 20),
            grid_points=200)
QUICK = dict(n=4, K=3, npoints=100, stride=10, grid_n=(4,), grid_K=(5,), grid_points=50)


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    n, K, npts = cfg['n'], cfg['K'], cfg['npoints']
    work = f"HTF n={n} K={K}, {npts} freqs"
    log(f"P9: {work}: auto, modal, bode_htf, solve")
    fresh = not quick
    auto = _measure('htf', n, K, npts, 'auto', fresh=fresh)
    modal = _measure('htf', n, K, npts, 'modal', fresh=fresh)
    bode = _measure('bode', n, K, npts, 'auto', fresh=fresh)
    solve = _measure('htf', n, K, npts, 'solve', stride=cfg['stride'], fresh=fresh)
    rows = []
    for rid, res, ours in (('P9a', auto, "ltp.htf 'auto' + H(jω)"),
                           ('P9b', bode, 'ltp.bode_htf, all 2K+1 components')):
        ratio = res['time'] / modal['time']
        rows.append(row(
            rid, work, ours=ours, peer="ltp.htf method='modal' + H(jω)",
            t_ours=res['time'], t_peer=modal['time'], metric='time/modal', value=ratio,
            target='<= 2x modal, <= 1.5 GB', target_met=ratio <= 2 and _peak(res) <= LIMIT,
            err_ours=res['err'], err_peer=modal['err'], tol=TOL,
            checks={'ours <= tol': res['err'] <= TOL,
                    'peak memory <= 1.5 GB': _peak(res) <= LIMIT},
            notes=_mem_note(res), extra=dict(ours=res, peer=modal)))
    rows.append(row(
        'P9c', work, ours="ltp.htf method='solve' (dense, chunked)", t_ours=solve['time'],
        metric='peak GB', value=_peak(solve) / 1e9, target='chunked, <= 1.5 GB',
        target_met=_peak(solve) <= LIMIT and solve['chunks'] > 1, err_ours=solve['err'],
        tol=TOL, checks={'not refused': solve['status'] == 'ok',
                         'peak memory <= 1.5 GB': _peak(solve) <= LIMIT},
        notes=_mem_note(solve) + f", {solve['chunks']} chunks; timed on every "
        f"{cfg['stride']}th frequency, extrapolated", extra=solve))
    for nn in cfg['grid_n']:
        for KK in cfg['grid_K']:
            log(f"P9d: n={nn} K={KK}")
            res = _measure('htf', nn, KK, cfg['grid_points'], 'auto', fresh=False)
            wl = f"HTF n={nn} K={KK}, {cfg['grid_points']} freqs"
            if res['status'] != 'ok':
                rows.append(row(f"P9d n{nn} K{KK}", wl, ours="ltp.htf 'auto'",
                                metric='refused', value=res['estimate'] / 1e9,
                                target='fits or refused', target_met=True,
                                checks={'refusal names the size': 'GB' in res['status']},
                                notes=res['status'], extra=res))
                continue
            rows.append(row(
                f"P9d n{nn} K{KK}", wl, ours="ltp.htf 'auto'", t_ours=res['time'],
                metric='traced GB', value=res['traced'] / 1e9, target='<= 1.5 GB',
                target_met=res['traced'] <= LIMIT, err_ours=res['err'], tol=TOL,
                checks={'ours <= tol': res['err'] <= TOL}, notes=_mem_note(res), extra=res))
    return rows


def _peak(res):
    """Peak RSS growth when measured in a fresh process, else the traced peak."""
    return res['rss'] if res['rss'] is not None else res['traced']


def _mem_note(res):
    rss = f"peak RSS +{res['rss'] / 1e6:.0f} MB, " if res['rss'] is not None else ""
    return f"{rss}tracemalloc {res['traced'] / 1e6:.0f} MB, {res['states']} harmonic states"


def _measure(kind, n, K, npoints, method, stride=1, fresh=True):
    """Run one case, in a fresh interpreter (clean peak-RSS counter) if `fresh`."""
    if not fresh:
        return _case(kind, n, K, npoints, method, stride, rss=False)
    args = [sys.executable, os.path.abspath(__file__), kind, str(n), str(K), str(npoints),
            method, str(stride)]
    proc = subprocess.run(args, capture_output=True, text=True, timeout=1800)
    if proc.returncode != 0:
        raise RuntimeError(f"P9 case {args[2:]} failed:\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def make_system(n):
    from systems import random_periodic_plant
    return random_periodic_plant(n, name=f'random{n}')


def _case(kind, n, K, npoints, method, stride, rss=True):
    import resource
    import time
    import tracemalloc
    import warnings
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot
    import numpy as np
    import ltpcontrol as ltp
    from _common import CLOCK
    warnings.simplefilter('ignore', UserWarning)
    sys_ = make_system(n)
    omega = np.linspace(0.05, 4 * K, npoints) * sys_.omega_p
    pts = omega[::stride]
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    tracemalloc.start()
    t0 = CLOCK['fn']()
    out = dict(status='ok', chunks=1)
    try:
        H = ltp.htf(sys_, K, method=method)
        if kind == 'bode':
            cplt = ltp.bode_htf(H, omega, harmonics=range(-K, K + 1))
            G = np.array([[line.get_ydata() for line in cell] for cell in cplt.lines.flat])
            matplotlib.pyplot.close(cplt.figure)
            value = None
        else:
            value = H(1j * pts)
    except MemoryError as exc:
        tracemalloc.stop()
        out.update(status=str(exc), time=CLOCK['fn']() - t0, rss=0, traced=0, err=None,
                   states=None, estimate=float(str(exc).split('about ')[1].split(' GB')[0]) * 1e9)
        return out
    elapsed = (CLOCK['fn']() - t0) * len(omega) / len(pts)
    traced = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 - rss0 if rss else None
    nF = H._hss.F.shape[0]
    # accuracy against dense solves at the same truncation, on 5 frequencies
    check = np.linspace(0, len(omega) - 1, 5).astype(int)
    other = 'modal' if method == 'solve' else 'solve'
    ref = ltp.htf(sys_, K, method=other, internal_harmonics=H._hss.Ki)
    if kind == 'bode':
        _, comps = H.components(omega[check])
        refc = ref.components(omega[check])[1]
        err = np.abs(comps - refc).max() / np.abs(refc).max()
        del G
    else:
        got = value[..., np.searchsorted(pts, omega[check]).clip(0, len(pts) - 1)]
        want = ref(1j * pts[np.searchsorted(pts, omega[check]).clip(0, len(pts) - 1)])
        err = np.abs(got - want).max() / np.abs(want).max()
    if kind == 'htf':
        chunk = H._hss._plan(len(pts), 2 * K + 1, 2 * K + 1)[0]
        out['chunks'] = -(-len(pts) // chunk)
    out.update(time=elapsed, rss=None if rss is None else float(rss), traced=float(traced),
               err=float(err),
               states=int(nF), modal=H._hss.modal is not None)
    return out


if __name__ == '__main__':
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    kind, n, K, npoints, method, stride = sys.argv[1:7]
    print(json.dumps(_case(kind, int(n), int(K), int(npoints), method, int(stride))))
