"""P10: any time grid at the speed of a grid whose step divides the period.

The peer is ltpcontrol itself on the aligned grid: the same plant, the same
number of samples, with a step that divides the period (transition data of
one period, reused).  Ours is the same call on grids whose steps do not
divide the period.  Rows P10a-P10d: a 6-state, 1-input, 1-output plant
with periodic A, B, C, D (``p6_limit.big_plant``), 50 steps per period:

* **P10a** ``np.linspace(0, 100 T, 5000)`` (step ``100 T/4999``: the phase
  pattern never repeats within the record; one-period cell table);
* **P10b** a step ``3 T/50`` (the phases repeat every 50 steps, three
  periods; the record is three times longer in time);
* **P10c** a jittered non-uniform grid (random steps within ±20 % of T/50);
* **P10d** ``np.linspace(0, 1000 T, 50000)`` against the aligned grid with
  as many samples: a record ten times longer, where the per-sample work of
  assembling every step's data weighs more than the one-period table.

Rows P10e-P10j: fine grids of 400 steps per period (measured data: 80 Hz
over a 5 s rotor period, 20 kHz over a 50 Hz grid period), 12000 samples,
on a 2-state Mathieu-type plant ``ẍ + 0.6 ω ẋ + ω² (1 + 0.2 cos ωt) x = u``
(ω = 2π, T = 1) whose A is given as Fourier coefficients or as a Python
callable of scalar time (the two forms a user writes):

* **P10e/P10f** non-uniform: every inner sample moved by up to ±20 % of the
  step (steps 0.6-1.4 T/400), Fourier / callable A;
* **P10g** uniform step T/400 starting at an offset (0.37 of a step);
* **P10h** the aligned grid with a few irregular steps (5 samples dropped,
  5 moved by 30 % of a step), callable A;
* **P10i** a long non-uniform record, 60 periods (24000 samples), against
  the aligned grid with as many samples;
* **P10j** a 20-state, 2-input, 2-output plant (``big_plant``), non-uniform
  400 steps per period, 8000 samples;
* **P10k/P10l** a long non-uniform record, 480 periods (192 000 samples),
  against the aligned grid with as many samples: P10k with the default
  settings (the compiled cell march when numba is installed: the ``fast``
  extra; the row's label says which ran), P10l with the NumPy march
  (``timeresp.compiled=False``);
* **P10m** the same grid over 1920 periods (768 000 samples), default
  settings.

The input is a sum of two cosines, one trace.  Accuracy: every grid's
outputs against the same exact discretization computed step by step
(every step integrated on its own, no table, no reuse) on a window of the
record, to 1e-11 relative; the aligned run against the same reference.
The target is a time ratio of at most 2 (ours / aligned).

Timing: every grid's call alternates with its aligned peer's, ``pairs``
times, and the ratio is the median of the pairs' ratios, so that a burst
of load on a shared machine hits both sides of a pair alike.

Where the time goes on the non-uniform rows: the cell table of a jittered
grid (400 cells of a period, one sample each, Chebyshev-Lobatto lengths of
degree 6) integrates the D sub-intervals of every cell, where the aligned
grid integrates one sixth-order Magnus step of one to a few sub-steps per
sample of a period, so the table costs more than the aligned grid's step
data (P10a-P10c: about twice their whole call); the march then costs per sample about 0.06 µs compiled (the loop
specialised to the system's sizes) and 0.2-0.25 µs with NumPy, against
about 0.03-0.05 µs on the aligned grid, so without numba the ratio grows
with the record (P10i, P10l); for 20 states the table is
about two thirds of the call.
"""

import numpy as np

from _common import row, timed

import ltpcontrol as ltp
import ltpcontrol._core.cellkernel as cellkernel
import ltpcontrol._core.gridmarch as gridmarch
from p6_limit import big_plant

TOL = 1e-11
FULL = dict(periods=100, samples=5000, window=600, pairs=9, long=(1000, 50000),
            fine=12000, fine_long=24000, fine_mimo=8000, fine_longer=192000,
            fine_longest=768000)
QUICK = dict(periods=10, samples=500, window=120, pairs=1, long=(40, 2000),
             fine=1600, fine_long=2400, fine_mimo=1200, fine_longer=3200,
             fine_longest=4000)


def _per_step(sys, t, u):
    """The exact discretization with every step integrated on its own."""
    names = ('_table_steps', '_cell_table', '_repeat_length')
    saved = {name: getattr(gridmarch, name) for name in names}
    for name in names:
        setattr(gridmarch, name, lambda *a, **k: None)
    try:
        return np.asarray(ltp.forced_response(sys, t, u).outputs)
    finally:
        for name, fn in saved.items():
            setattr(gridmarch, name, fn)


def mathieu_forms():
    """The 2-state plant of P10e-P10i with A as Fourier coefficients and as a callable."""
    w = 2 * np.pi
    coeffs = np.zeros((3, 2, 2), complex)
    coeffs[1] = [[0, 1], [-w ** 2, -0.6 * w]]
    coeffs[0] = coeffs[2] = [[0, 0], [-0.1 * w ** 2, 0]]

    def A(t):
        return np.array([[0.0, 1.0], [-(1 + 0.2 * np.cos(w * t)) * w ** 2, -0.6 * w]])

    forms = {'Fourier': ltp.PeriodicMatrix(coeffs, 1.0),
             'callable': ltp.PeriodicMatrix.from_function(A, 1.0)}
    return {form: ltp.ltpss(Af, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=1.0)
            for form, Af in forms.items()}


def _jittered(L, per_period, T, seed):
    t = T / per_period * np.arange(L)
    jitter = np.random.default_rng(seed).uniform(-0.2, 0.2, L) * T / per_period
    jitter[[0, -1]] = 0.0
    return t + jitter


def _irregular(L, per_period, T, seed):
    h = T / per_period
    rng = np.random.default_rng(seed)
    t = h * np.arange(L + 5)
    t = np.delete(t, rng.choice(np.arange(1, L), 5, replace=False))
    moved = rng.choice(np.arange(1, L - 1), 5, replace=False)
    t[moved] += 0.3 * h
    return t


def run(quick=False, log=print, only=None):
    """Rows of P10 (`only`: the ids to run, default all)."""
    cfg = QUICK if quick else FULL
    sys6 = big_plant(n=6, m=1, p=1, T=2 * np.pi, seed=2)
    T, L = sys6.period, cfg['samples']
    rng = np.random.default_rng(0)
    fine, fine_long = cfg['fine'], cfg['fine_long']
    plants = mathieu_forms()
    plants['6-state'] = sys6
    plants['20-state'] = big_plant(n=20, m=2, p=2, T=1.0, seed=4)
    periods, Llong = cfg['long']
    # name: (plant, grid, peer)
    cases = {
        'aligned': ('6-state', T / 50 * np.arange(L), None),
        'P10a': ('6-state', np.linspace(0, cfg['periods'] * T, L), 'aligned'),
        'P10b': ('6-state', 3 * T / 50 * np.arange(L), 'aligned'),
        'P10c': ('6-state', np.cumsum(np.concatenate(
            [[0.0], T / 50 * rng.uniform(0.8, 1.2, L - 1)])), 'aligned'),
        'aligned long': ('6-state', T / 50 * np.arange(Llong), None),
        'P10d': ('6-state', np.linspace(0, periods * T, Llong), 'aligned long'),
    }
    for form in ('Fourier', 'callable'):
        cases[f'aligned 400 {form}'] = (form, np.arange(fine) / 400, None)
    cases['P10e'] = ('Fourier', _jittered(fine, 400, 1.0, 3), 'aligned 400 Fourier')
    cases['P10f'] = ('callable', _jittered(fine, 400, 1.0, 3), 'aligned 400 callable')
    cases['P10g'] = ('Fourier', (np.arange(fine) + 0.37) / 400, 'aligned 400 Fourier')
    cases['P10h'] = ('callable', _irregular(fine, 400, 1.0, 5), 'aligned 400 callable')
    cases['aligned 400 long'] = ('Fourier', np.arange(fine_long) / 400, None)
    cases['P10i'] = ('Fourier', _jittered(fine_long, 400, 1.0, 6), 'aligned 400 long')
    cases['aligned 400 MIMO'] = ('20-state', np.arange(cfg['fine_mimo']) / 400, None)
    cases['P10j'] = ('20-state', _jittered(cfg['fine_mimo'], 400, 1.0, 7), 'aligned 400 MIMO')
    longer = cfg['fine_longer']
    cases['aligned 400 longer'] = ('Fourier', np.arange(longer) / 400, None)
    cases['P10k'] = ('Fourier', _jittered(longer, 400, 1.0, 8), 'aligned 400 longer')
    cases['P10l'] = ('Fourier', cases['P10k'][1], 'aligned 400 longer')
    longest = cfg['fine_longest']
    cases['aligned 400 longest'] = ('Fourier', np.arange(longest) / 400, None)
    cases['P10m'] = ('Fourier', _jittered(longest, 400, 1.0, 9), 'aligned 400 longest')
    compiled = {name: cellkernel.available() and len(cases[name][1]) >= cellkernel.MIN_SAMPLES
                for name in ('P10k', 'P10m')}

    def march(name):
        if compiled[name]:
            return 'compiled march (numba)'
        if not cellkernel.available():
            return 'NumPy march (numba not installed)'
        return 'NumPy march (too short for the compiled one)'

    if only:
        keep = {n for n, c in cases.items() if n in only}
        keep |= {cases[n][2] for n in keep if cases[n][2]}
        cases = {n: c for n, c in cases.items() if n in keep}

    def inputs(sys, t):
        w = 2 * np.pi / sys.period
        u = np.cos(0.21 * w * t) + 0.5 * np.cos(0.059 * w * t)
        m = sys.ninputs
        return u if m == 1 else np.array([u * (1 + 0.1 * i) for i in range(m)])

    # every grid's call alternates with its aligned peer's (pairs of runs on
    # the same machine state); the ratio is the median of the pairs' ratios
    calls, errs = {}, {}
    for name, (plant, t, _) in cases.items():
        sys = plants[plant]
        u = inputs(sys, t)
        # P10l: the NumPy march whether or not numba is installed
        settings = {'timeresp.compiled': name != 'P10l'}

        def call(sys=sys, t=t, u=u, settings=settings):
            with ltp.config.defaults_context(settings):
                return ltp.forced_response(sys, t, u)
        calls[name] = call
        log(f"P10: {name}, {plant}, {len(t)} samples")
        resp = calls[name]()
        w = cfg['window']
        ref = _per_step(sys, t[:w], u[..., :w])
        y = np.asarray(resp.outputs)[..., :w]
        errs[name] = float(np.abs(y - ref).max() / np.abs(ref).max())
        log(f"  error {errs[name]:.1e}")
    times, peer_times, ratios = {}, {}, {}
    for name, (_, _, peer) in cases.items():
        if peer is None:
            continue
        ours, theirs = [], []
        for _ in range(cfg['pairs']):
            ours.append(timed(calls[name])[0])
            theirs.append(timed(calls[peer])[0])
        times[name], peer_times[name] = float(np.median(ours)), float(np.median(theirs))
        ratios[name] = float(np.median(np.array(ours) / np.array(theirs)))
        log(f"  {name}: {times[name]:.3f} s, {peer}: {peer_times[name]:.3f} s, "
            f"ratio {ratios[name]:.2f}")
    labels = {'P10a': 'linspace(0, 100T, 5000): phases never repeat',
              'P10b': 'step 3T/50: phases repeat every 50 steps',
              'P10c': 'non-uniform grid, steps T/50 +- 20%',
              'P10d': f'linspace(0, {periods}T, {Llong}): a long record',
              'P10e': '400 steps/period, non-uniform (samples moved by +- 20% of a step), '
                      'Fourier A',
              'P10f': '400 steps/period, non-uniform (samples moved by +- 20% of a step), '
                      'callable A',
              'P10g': '400 steps/period, uniform step starting at an offset',
              'P10h': '400 steps/period, aligned but 5 samples dropped and 5 moved, '
                      'callable A',
              'P10i': f'400 steps/period, non-uniform, {fine_long // 400} periods',
              'P10j': '400 steps/period, non-uniform, 20 states, 2 inputs, 2 outputs',
              'P10k': f'400 steps/period, non-uniform, {longer // 400} periods, '
                      + march('P10k'),
              'P10m': f'400 steps/period, non-uniform, {longest // 400} periods, '
                      + march('P10m'),
              'P10l': f'400 steps/period, non-uniform, {longer // 400} periods, NumPy march '
                      '(timeresp.compiled=False)'}
    rows = []
    for name, (plant, t, peer) in cases.items():
        if peer is None:
            continue
        ratio = ratios[name]
        ok = errs[name] <= TOL and errs[peer] <= TOL
        rows.append(row(
            name, f"{plant} plant, {len(t)} samples, {labels[name]}",
            ours='ltp.forced_response on this grid',
            peer=f'ltp.forced_response on the aligned grid ({peer})',
            t_ours=times[name], t_peer=peer_times[name], metric='slowdown', value=ratio,
            target='<= 2x the aligned grid', target_met=ratio <= 2,
            err_ours=errs[name], err_peer=errs[peer], tol=TOL,
            checks={'ours <= tol': errs[name] <= TOL, 'aligned <= tol': errs[peer] <= TOL},
            matched=ok, notes='error against the same discretization, step by step; '
                              'ratio: median over alternating pairs of runs',
            extra=dict(window=cfg['window'], compiled=compiled.get(name, False))))
    return rows


if __name__ == '__main__':
    import sys as _sys
    args = set(_sys.argv[1:])
    for r in run(quick='quick' in args, only=args - {'quick'}):
        print(r['id'], f"{r['t_ours']:.3f}", f"{r['t_peer']:.3f}", f"{r['value']:.2f}",
              f"{r['err_ours']:.1e}", r['target_met'])
