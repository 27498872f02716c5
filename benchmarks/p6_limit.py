"""P6: simulation against the machine's limit, a compiled scalar recurrence.

The peer is not another simulator but the fastest way this machine can run
the *same* exact discretization: the recurrence

    x[k+1] = Φ_k x[k] + Γ0_k u[k] + Γ1_k (u[k+1] - u[k]),   y[k] = C_k x[k] + D_k u[k]

(phase k mod N, step data from ``ltpcontrol._core.transition.step_transitions``)
written as a scalar loop and compiled with numba (``pip install numba``; the
rows are reported as not available without it).  It stores the outputs only,
and ours is `ltp.forced_response` with ``compute_states=False``, which
computes the outputs only; they are checked to agree to 1e-12 (and the
states of the default call against the states of the same loop).
Compilation happens before the timing.

Rows:

* **P6a** the thesis §4.2.9 data set of P1 (Mathieu plant, 400 cosines x
  200 s x 100 Hz);
* **P6b** a 20-state, 2-input, 2-output plant with periodic A(t), B(t), C(t)
  and D(t), 1000 random-input experiments of 2000 samples;
* **P6d** the P6a data set with the default call (states kept) against
  the loop that stores the states as well;
* **P6c** memory: peak traced allocation of `ltp.forced_response` on the
  Mathieu plant with 1000 experiments at 5000 and 20000 samples, divided by
  the size of the returned arrays (inputs, states, outputs); linear memory
  means the two quotients agree (the time shown is the longer run, slowed
  by the tracing).

"ours" is the whole public call, `ltp.forced_response`, including input
checks, the transition data of one period and the `control.TimeResponseData`
it returns (python-control copies the arrays there); the kernel alone is
stored in the JSON file.  The target is a ratio of at least 1/3: ours within
3x of the compiled loop.
"""

import tracemalloc

import numpy as np

from _common import median_time, not_available, row, timed

import ltpcontrol as ltp
from ltpcontrol._core.march import periodic_march
from ltpcontrol._core.transition import step_transitions
from systems import mathieu

TOL = 1e-12
FULL = dict(mathieu=dict(nexp=400, duration=200.0), big=dict(nexp=1000, samples=2000),
            memory=dict(nexp=1000, samples=(5000, 20000)), repeats=5)
QUICK = dict(mathieu=dict(nexp=40, duration=10.0), big=dict(nexp=20, samples=200),
             memory=dict(nexp=50, samples=(500, 2000)), repeats=1)


def _compiled_recurrence():
    try:
        import numba
    except ImportError:
        return None

    @numba.njit(cache=False)
    def recurrence(Phi, G0, G1, C, D, u, x0, keep_states):
        N, n, m = G0.shape
        p = C.shape[1]
        R, L = u.shape[1], u.shape[2]
        x = np.empty((n, R, L if keep_states else 0))
        y = np.empty((p, R, L))
        xk = np.empty(n)
        xn = np.empty(n)
        for r in range(R):
            for s in range(n):
                xk[s] = x0[s, r]
            for k in range(L):
                c = k % N
                if keep_states:
                    for s in range(n):
                        x[s, r, k] = xk[s]
                for o in range(p):
                    acc = 0.0
                    for s in range(n):
                        acc += C[c, o, s] * xk[s]
                    for i in range(m):
                        acc += D[c, o, i] * u[i, r, k]
                    y[o, r, k] = acc
                if k + 1 < L:
                    for s in range(n):
                        acc = 0.0
                        for q in range(n):
                            acc += Phi[c, s, q] * xk[q]
                        for i in range(m):
                            acc += G0[c, s, i] * u[i, r, k] \
                                + G1[c, s, i] * (u[i, r, k + 1] - u[i, r, k])
                        xn[s] = acc
                    for s in range(n):
                        xk[s] = xn[s]
        return x, y

    return recurrence


def big_plant(n=20, m=2, p=2, T=1.0, seed=0):
    """Random plant with A, B, C, D periodic (two harmonics), Floquet stable."""
    rng = np.random.default_rng(seed)

    def fourier(rows, cols, scale, center=0.0):
        coef = scale * rng.normal(size=(5, rows, cols)) / np.sqrt(max(rows, cols))
        coef[3:] = coef[1::-1].copy()              # real matrix: c_{-k} = c_k
        coef[2] = center + scale * rng.normal(size=(rows, cols))
        return ltp.PeriodicMatrix(coef, T)

    A = fourier(n, n, 0.5, center=-2.0 * np.eye(n))
    return ltp.ltpss(A, fourier(n, m, 1.0), fourier(p, n, 1.0), fourier(p, m, 0.3),
                     period=T, name='plant20')


def _step_data(sys, t):
    N = int(round(sys.period / (t[1] - t[0])))
    tk = t[0] + (t[1] - t[0]) * np.arange(N)
    Phi, G0, G1 = step_transitions(sys.A, sys.B, tk, t[1] - t[0])
    return Phi, G0, G1, sys.C(tk), sys.D(tk)


def _compare(rid, workload, sys, t, U, x0, repeats, recurrence, log):
    log(f"P6: {rid} {workload}")
    t_ours, times, resp = median_time(
        lambda _: ltp.forced_response(sys, t, U, x0, compute_states=False),
        repeats, setup=lambda: None)
    Phi, G0, G1, C, D = _step_data(sys, t)
    t_kernel, _, _ = median_time(
        lambda _: periodic_march(Phi, G0 - G1, G1, C, D, U, x0, states=False), repeats,
        setup=lambda: None)
    recurrence(Phi, G0, G1, C, D, U[:, :1, :3].copy(), x0[:, :1].copy(), True)  # compile
    t_peer, _, (_, yr) = median_time(lambda _: recurrence(Phi, G0, G1, C, D, U, x0, False),
                                     repeats, setup=lambda: None)
    y = np.asarray(resp.outputs)
    err = float(np.abs(y - yr).max() / np.abs(yr).max())
    del resp, y, yr
    # the states of the default call against the loop's states, on a few traces
    sub = slice(0, min(8, U.shape[1]))
    full = ltp.forced_response(sys, t, U[:, sub], x0[:, sub])
    xr, yr = recurrence(Phi, G0, G1, C, D, np.ascontiguousarray(U[:, sub]),
                        np.ascontiguousarray(x0[:, sub]), True)
    err = max(err, float(np.abs(np.asarray(full.states) - xr).max() / np.abs(xr).max()),
              float(np.abs(np.asarray(full.outputs) - yr).max() / np.abs(yr).max()))
    del full, xr, yr
    return row(rid, workload, ours='ltp.forced_response(compute_states=False), public call',
               peer='compiled scalar recurrence (numba), outputs only, same discretization',
               t_ours=t_ours, t_peer=t_peer, target='>= 0.33x (within 3x)',
               target_met=t_peer / t_ours >= 1 / 3, err_ours=err, err_peer=0.0, tol=TOL,
               checks={'agree <= 1e-12': err <= TOL}, matched=err <= TOL,
               notes='error: ours against the compiled recurrence',
               extra=dict(ours_times=times, kernel_s=t_kernel,
                          kernel_ratio=t_peer / t_kernel))


def _compare_states(rid, workload, sys, t, U, x0, repeats, recurrence, log):
    """The default call (states kept) against the loop that stores the states too."""
    log(f"P6: {rid} {workload}, default call (states kept)")
    t_ours, times, resp = median_time(lambda _: ltp.forced_response(sys, t, U, x0),
                                      repeats, setup=lambda: None)
    Phi, G0, G1, C, D = _step_data(sys, t)
    recurrence(Phi, G0, G1, C, D, U[:, :1, :3].copy(), x0[:, :1].copy(), True)  # compile
    t_peer, _, (xr, yr) = median_time(lambda _: recurrence(Phi, G0, G1, C, D, U, x0, True),
                                      repeats, setup=lambda: None)
    err = max(float(np.abs(np.asarray(resp.states) - xr).max() / np.abs(xr).max()),
              float(np.abs(np.asarray(resp.outputs) - yr).max() / np.abs(yr).max()))
    del resp, xr, yr
    return row(rid, workload + ', states kept',
               ours='ltp.forced_response(sys, t, u, x0), default call, public',
               peer='compiled scalar recurrence (numba), states and outputs, same '
                    'discretization', t_ours=t_ours, t_peer=t_peer,
               target='>= 0.33x (within 3x)', target_met=t_peer / t_ours >= 1 / 3,
               err_ours=err, err_peer=0.0, tol=TOL, checks={'agree <= 1e-12': err <= TOL},
               matched=err <= TOL, notes='error: states and outputs against the loop',
               extra=dict(ours_times=times))


def _memory(sys, nexp, samples, log):
    h = sys.period / 50
    quotients, peaks, seconds = [], [], []
    for L in samples:
        log(f"P6: P6c memory, {nexp} experiments x {L} samples")
        t = h * np.arange(L)
        U = np.cos(np.linspace(1, 20, nexp)[:, None] * t)[None]
        tracemalloc.start()
        el, resp = timed(ltp.forced_response, sys, t, U)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        seconds.append(el)
        size = sum(np.asarray(a).nbytes for a in (resp.inputs, resp.states, resp.outputs))
        del resp
        quotients.append(peak / size)
        peaks.append(peak)
    linear = abs(quotients[1] / quotients[0] - 1) <= 0.1
    return row('P6c', f"memory, Mathieu, {nexp} exp x {samples[0]} and {samples[1]} samples",
               ours='ltp.forced_response', metric='peak/result', t_ours=seconds[-1],
               value=max(quotients), target='linear (quotients within 10%), <= 3',
               target_met=linear and max(quotients) <= 3,
               checks={'linear in samples': linear},
               notes='peak traced allocation divided by the size of inputs, states, outputs',
               extra=dict(samples=list(samples), peak_bytes=peaks, quotients=quotients,
                          seconds_traced=seconds))


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    recurrence = _compiled_recurrence()
    rows = []
    spec = cfg['mathieu']
    work_a = f"Mathieu, {spec['nexp']} cosines x {spec['duration']:g} s x 100 Hz"
    spec_b = cfg['big']
    work_b = f"n=20, m=2, p=2 periodic plant, {spec_b['nexp']} exp x {spec_b['samples']} samples"
    if recurrence is None:
        reason = 'numba is not installed (pip install numba)'
        rows += [not_available('P6a', work_a, reason), not_available('P6b', work_b, reason)]
    else:
        t = np.arange(int(round(spec['duration'] * 100)) + 1) / 100
        f = 0.15 + 0.1 * np.arange(1, spec['nexp'] + 1)
        U = np.cos(2 * np.pi * f[:, None] * t[None, :])[None]
        rows.append(_compare('P6a', work_a, mathieu(), t, U, np.zeros((2, spec['nexp'])),
                             cfg['repeats'], recurrence, log))
        rows.append(_compare_states('P6d', work_a, mathieu(), t, U,
                                    np.zeros((2, spec['nexp'])), cfg['repeats'], recurrence,
                                    log))
        del U
        sys = big_plant()
        rng = np.random.default_rng(1)
        t = sys.period / 50 * np.arange(spec_b['samples'])
        U = rng.normal(size=(2, spec_b['nexp'], len(t)))
        x0 = rng.normal(size=(20, spec_b['nexp']))
        rows.append(_compare('P6b', work_b, sys, t, U, x0, cfg['repeats'], recurrence, log))
        del U
    spec = cfg['memory']
    rows.append(_memory(mathieu(), spec['nexp'], spec['samples'], log))
    return rows
