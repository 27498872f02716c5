"""Real-size sweep of the design and analysis functions (not part of run.py).

``python benchmarks/size_sweep.py [n ...] [--only NAME ...] [--timeout S]``

Each call runs once in its own process (BLAS on one thread, address space
capped at 6 GB, killed after ``--timeout`` seconds, default 120) on a random
stable periodic plant of n states (default n = 100):

* continuous: ``A(t) = -P + K(t)`` with P symmetric positive definite whose
  eigenvalues are log-spaced in [0.5, 300] (stiff) plus a small constant
  non-normal part, and K(t) skew-symmetric with harmonics 1..3, period 1,
  2 inputs, 2 outputs, harmonics in B(t) and C(t) too;
* discrete: N = 7 and N = 8 steps of ``A_k = 0.9 U_k diag(s_k) V_kᵀ``
  (``s_k ≤ 1``, so every step is a contraction), 2 inputs, 2 outputs.

It prints the time, the tracemalloc peak and a relative residual of the
equation each function solves (or an independent check of its result).
"""

import json
import os
import resource
import subprocess
import sys
import time
import tracemalloc

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def continuous_plant(n, seed=0, m=2, p=2, harmonics=3):
    import ltpcontrol as ltp
    rng = np.random.default_rng(seed)
    Q0, _ = np.linalg.qr(rng.normal(size=(n, n)))
    P = Q0 @ np.diag(np.geomspace(0.5, 300.0, n)) @ Q0.T
    N0 = 0.3 * np.triu(rng.normal(size=(n, n)), 1) / np.sqrt(n)
    c = np.zeros((2 * harmonics + 1, n, n), complex)
    c[harmonics] = -P + N0 - N0.T          # skew part: still contractive
    for h in range(1, harmonics + 1):
        S = rng.normal(size=(n, n)) + 1j * rng.normal(size=(n, n))
        S = 2.0 / h * (S - S.T) / 2 / np.sqrt(n)   # complex skew: cos/sin skew parts
        c[harmonics + h], c[harmonics - h] = S, S.conj()
    A = ltp.PeriodicMatrix(c, 1.0)

    def pm(rows, cols):
        cc = np.zeros((3, rows, cols), complex)
        cc[1] = rng.normal(size=(rows, cols))
        cc[2] = 0.3 * (rng.normal(size=(rows, cols)) + 1j * rng.normal(size=(rows, cols)))
        cc[0] = cc[2].conj()
        return ltp.PeriodicMatrix(cc, 1.0)
    return ltp.ltpss(A, pm(n, m), pm(p, n), 0, period=1.0)


def discrete_plant(n, N, seed=0, m=2, p=2):
    import ltpcontrol as ltp
    rng = np.random.default_rng(seed)
    A = np.empty((N, n, n))
    for k in range(N):
        U, _ = np.linalg.qr(rng.normal(size=(n, n)))
        V, _ = np.linalg.qr(rng.normal(size=(n, n)))
        A[k] = 0.9 * U @ np.diag(rng.uniform(0.05, 1.0, n)) @ V.T
    B = rng.normal(size=(N, n, m))
    C = rng.normal(size=(N, p, n))
    return ltp.ltpss(A, B, C, 0, period=float(N), dt=1.0)


def rel(r, *scale):
    return float(np.linalg.norm(r) / max(sum(np.linalg.norm(s) for s in scale), 1e-300))


def cont_lyap_residual(A, Q, X, ts, h=1e-6, adjoint=False):
    worst = 0.0
    for t in ts:
        dX = (X(t + h) - X(t - h)) / (2 * h)
        a, x, q = A(t), X(t), Q(t)
        if adjoint:
            r = dX + a.T @ x + x @ a + q
            worst = max(worst, rel(r, a.T @ x, q, dX))
        else:
            r = dX - (a @ x + x @ a.T + q)
            worst = max(worst, rel(r, a @ x, q, dX))
    return worst


def cont_riccati_residual(A, B, Q, R, X, ts, h=1e-6):
    worst = 0.0
    Ri = np.linalg.inv(R)
    for t in ts:
        dX = (X(t + h) - X(t - h)) / (2 * h)
        a, b, x = A(t), B(t), X(t)
        r = dX + a.T @ x + x @ a - x @ b @ Ri @ b.T @ x + Q
        worst = max(worst, rel(r, a.T @ x, x @ b @ Ri @ b.T @ x, Q, dX))
    return worst


def run_case(name, n):
    import control as ct
    import ltpcontrol as ltp
    csys = continuous_plant(n)
    dsys = {7: discrete_plant(n, 7), 8: discrete_plant(n, 8)}
    ts = [0.0, 0.237, 0.61]
    I = np.eye(n)
    out = {}

    def timed(f):
        tracemalloc.start()
        t0 = time.perf_counter()
        r = f()
        out['time'] = time.perf_counter() - t0
        out['peak_MB'] = tracemalloc.get_traced_memory()[1] / 1e6
        tracemalloc.stop()
        return r

    if name == 'lyap':
        Q = csys.B @ csys.B.T
        X = timed(lambda: ltp.lyap(csys.A, Q))
        out['residual'] = cont_lyap_residual(csys.A, Q, X, ts)
    elif name == 'lyap_adjoint':
        Q = csys.C.T @ csys.C
        X = timed(lambda: ltp.lyap(csys.A, Q, adjoint=True))
        out['residual'] = cont_lyap_residual(csys.A, Q, X, ts, adjoint=True)
    elif name.startswith('dlyap'):
        s = dsys[int(name[-1])]
        A, B = s.A.sample(s.nsteps), s.B.sample(s.nsteps)
        Q = B @ np.swapaxes(B, 1, 2)
        X = timed(lambda: ltp.dlyap(A, Q))
        Xn = np.roll(X, -1, axis=0)
        out['residual'] = rel(Xn - A @ X @ np.swapaxes(A, 1, 2) - Q, Xn, Q)
    elif name == 'care':
        X, L, G = timed(lambda: ltp.care(csys.A, csys.B, I, np.eye(2)))
        out['residual'] = cont_riccati_residual(csys.A, csys.B, I, np.eye(2), X, ts)
        out['stable'] = bool(np.all(L.real < 0))
    elif name.startswith('dare'):
        s = dsys[int(name[-1])]
        A, B = s.A.sample(s.nsteps), s.B.sample(s.nsteps)
        X, L, G = timed(lambda: ltp.dare(A, B, I, np.eye(2)))
        Xn = np.roll(X, -1, axis=0)
        At = np.swapaxes(A, 1, 2)
        BXA = np.swapaxes(B, 1, 2) @ Xn @ A
        r = X - (At @ Xn @ A - np.swapaxes(BXA, 1, 2) @ np.linalg.solve(
            np.eye(2) + np.swapaxes(B, 1, 2) @ Xn @ B, BXA) + I)
        out['residual'] = rel(r, X, At @ Xn @ A)
        out['stable'] = bool(np.all(np.abs(L) < 1))
    elif name == 'lqr':
        K, X, E = timed(lambda: ltp.lqr(csys, I, np.eye(2)))
        out['residual'] = cont_riccati_residual(csys.A, csys.B, I, np.eye(2), X, ts)
        out['stable'] = bool(np.all(E.real < 0))
    elif name.startswith('dlqr'):
        s = dsys[int(name[-1])]
        K, X, E = timed(lambda: ltp.dlqr(s, I, np.eye(2)))
        out['stable'] = bool(np.all(np.abs(E) < 1))
    elif name == 'lqe':
        L, P, E = timed(lambda: ltp.lqe(csys, np.eye(2), np.eye(2), G=csys.B))
        out['stable'] = bool(np.all(E.real < 0))
    elif name.startswith('dlqe'):
        s = dsys[int(name[-1])]
        L, P, E = timed(lambda: ltp.dlqe(s, np.eye(2), np.eye(2), G=s.B))
        out['stable'] = bool(np.all(np.abs(E) < 1))
    elif name in ('h2', 'h2_d7', 'h2_d8'):
        s = csys if name == 'h2' else dsys[int(name[-1])]
        v = timed(lambda: ltp.norm(s, 2))
        # independent: the dual gramian (observability) gives the same norm
        if s.isdtime():
            N = s.nsteps
            A, B, C = s.A.sample(N), s.B.sample(N), s.C.sample(N)
            Qo = ltp.dlyap(A, np.swapaxes(C, 1, 2) @ C, adjoint=True)
            Qn = np.roll(Qo, -1, axis=0)
            v2 = np.sqrt(np.trace(np.swapaxes(B, 1, 2) @ Qn @ B, axis1=1, axis2=2).sum() / N)
        else:
            Qo = ltp.lyap(s.A, s.C.T @ s.C, adjoint=True)
            tq = np.linspace(0, 1, 401)
            vals = [np.trace(s.B(t).T @ Qo(t) @ s.B(t)) for t in tq]
            v2 = np.sqrt(np.trapezoid(vals, tq))
        out['value'] = float(v)
        out['residual'] = abs(v - v2) / v2
    elif name in ('linf', 'linf_d7', 'linf_d8', 'hinfnorm'):
        s = dsys[int(name[-1])] if name.startswith('linf_d') else csys
        if name == 'hinfnorm':
            v = timed(lambda: ltp.hinfnorm(s))[0]
        else:
            v = timed(lambda: ltp.norm(s, 'inf'))
        out['value'] = float(v)
    elif name in ('hsvd', 'hsvd_d7', 'hsvd_d8'):
        s = csys if name == 'hsvd' else dsys[int(name[-1])]
        h = timed(lambda: ltp.hsvd(s))
        out['max'] = float(np.max(h))
    elif name in ('balred', 'balred_d7', 'balred_d8'):
        s = csys if name == 'balred' else dsys[int(name[-1])]
        r, bound = timed(lambda: ltp.balred(s, min(10, n - 1), return_bound=True))
        out['bound'] = float(bound)
        out['reduced_stable'] = bool(ltp.is_stable(r))
    elif name in ('minreal', 'minreal_d7', 'minreal_d8'):
        s = csys if name == 'minreal' else dsys[int(name[-1])]
        r = timed(lambda: ltp.minreal(s))
        out['nstates'] = int(r.nstates) if np.ndim(r.nstates) == 0 else str(r.nstates)
    elif name == 'htf':
        H = timed(lambda: ltp.htf(csys, 3)(1j * np.linspace(0.1, 10, 20)))
        out['shape'] = str(np.shape(H))
    elif name in ('is_stable', 'is_stable_d7', 'is_stable_d8'):
        s = csys if name == 'is_stable' else dsys[int(name[-1])]
        out['stable'] = bool(timed(lambda: ltp.is_stable(s)))
    elif name in ('c2d_zoh', 'c2d_tustin'):
        sd = timed(lambda: ltp.c2d(csys, 1 / 64, method=name[4:]))
        out['nsteps'] = int(sd.nsteps)
    elif name.startswith('lift_'):
        method, N = name.split('_')[1], int(name[-1])
        r = timed(lambda: ltp.lift(dsys[N], method=method))
        out['type'] = type(r).__name__
    else:
        raise ValueError(name)
    return out


CASES = ['lyap', 'lyap_adjoint', 'dlyap7', 'dlyap8', 'care', 'dare7', 'dare8', 'lqr',
         'dlqr7', 'dlqr8', 'lqe', 'dlqe7', 'dlqe8', 'h2', 'h2_d7', 'h2_d8', 'linf', 'linf_d7',
         'linf_d8', 'hinfnorm', 'hsvd', 'hsvd_d7', 'hsvd_d8', 'balred', 'balred_d7',
         'balred_d8', 'minreal', 'minreal_d7', 'minreal_d8', 'htf', 'is_stable', 'is_stable_d7',
         'is_stable_d8', 'c2d_zoh', 'c2d_tustin', 'lift_time_7', 'lift_time_8',
         'lift_frequency_7', 'lift_frequency_8', 'lift_cyclic_7', 'lift_stacked_8']


def _limit():
    resource.setrlimit(resource.RLIMIT_AS, (6 << 30, 6 << 30))


def _worker(cases, n):
    """Run `cases` in this process, one JSON line per case."""
    sys.path.insert(0, ROOT)
    import warnings
    for case in cases:
        try:
            with warnings.catch_warnings(record=True) as w:
                warnings.simplefilter('always')
                res = run_case(case, n)
            res['warnings'] = sorted({str(x.message)[:100] for x in w})
        except Exception as exc:                       # noqa: BLE001 - reported
            res = {'error': f'{type(exc).__name__}: {str(exc)[:200]}'}
        print(json.dumps({'case': case, **res}), flush=True)


def _run(cases, n, timeout, env):
    """Run the cases in worker processes; a case over `timeout` s is killed
    and the worker restarted on the remaining ones."""
    import selectors
    todo = list(cases)
    while todo:
        p = subprocess.Popen([sys.executable, __file__, '--worker', str(n)] + todo,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             preexec_fn=_limit, env=env)
        sel = selectors.DefaultSelector()
        sel.register(p.stdout, selectors.EVENT_READ)
        t0 = time.perf_counter()
        while todo:
            ready = sel.select(timeout=max(1.0, timeout + 60 - (time.perf_counter() - t0)))
            if not ready:                               # the current case ran over
                p.kill()
                p.wait()
                print(f"n={n:4d} {todo[0]:18s} " + json.dumps(
                    {'error': f'> {timeout} s (killed)'}), flush=True)
                todo.pop(0)
                break
            line = p.stdout.readline()
            if not line:                                # died (out of memory, ...)
                p.wait()
                err = (p.stderr.read().strip().splitlines() or ['?'])[-1]
                print(f"n={n:4d} {todo[0]:18s} " + json.dumps(
                    {'error': f'worker died: {err[:200]}'}), flush=True)
                todo.pop(0)
                break
            res = json.loads(line)
            case = res.pop('case')
            print(f"n={n:4d} {case:18s} " + json.dumps(res), flush=True)
            todo.remove(case)
            t0 = time.perf_counter()
        else:
            p.wait()


def main(argv):
    if argv and argv[0] == '--worker':
        _worker(argv[2:], int(argv[1]))
        return
    sizes = [int(a) for a in argv if a.isdigit()] or [100]
    only = argv[argv.index('--only') + 1:] if '--only' in argv else CASES
    only = [c for c in only if not c.startswith('--') and not c.isdigit()]
    timeout = 120
    env = dict(os.environ, OMP_NUM_THREADS='1', OPENBLAS_NUM_THREADS='1', MKL_NUM_THREADS='1',
               PYTHONPATH=ROOT)
    for n in sizes:
        _run(only, n, timeout, env)


if __name__ == '__main__':
    main(sys.argv[1:])
