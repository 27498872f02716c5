"""P10: any time grid at the speed of a grid whose step divides the period.

The peer is ltpcontrol itself on the aligned grid: the same plant, the same
number of samples over the same span, with a step ``T/50`` that divides the
period (transition data of one period, reused).  Ours is the same call on
grids whose step does not divide the period:

* **P10a** ``np.linspace(0, 100 T, 5000)`` (step ``100 T/4999``: the phase
  pattern never repeats within the record; one-period cell table);
* **P10b** a step ``3 T/50`` (the phases repeat every 50 steps, three
  periods; the record is three times longer in time);
* **P10c** a jittered non-uniform grid (random steps within ±20 % of T/50);
* **P10d** ``np.linspace(0, 1000 T, 50000)`` against the aligned grid with
  as many samples: a record ten times longer, where the per-sample work of
  assembling every step's data weighs more than the one-period table.

The plant is a 6-state, 1-input, 1-output plant with periodic A, B, C, D
(``p6_limit.big_plant``), Floquet stable; the input a sum of two cosines,
one trace.  Accuracy: every grid's outputs against the same exact
discretization computed step by step (every step integrated on its own,
no table, no reuse) on a window of the record, to 1e-11 relative; the
aligned run against the same reference.  The target is a time ratio of at
most 2 (ours / aligned).
"""

import numpy as np

from _common import median_time, row

import ltpcontrol as ltp
import ltpcontrol._core.gridmarch as gridmarch
from p6_limit import big_plant

TOL = 1e-11
FULL = dict(periods=100, samples=5000, window=600, repeats=3, long=(1000, 50000))
QUICK = dict(periods=10, samples=500, window=120, repeats=1, long=(40, 2000))


def _per_step(sys, t, u):
    """The exact discretization with every step integrated on its own."""
    table, repeat = gridmarch._table_steps, gridmarch._repeat_length
    gridmarch._table_steps = lambda *a: None
    gridmarch._repeat_length = lambda *a: None
    try:
        return np.asarray(ltp.forced_response(sys, t, u).outputs)
    finally:
        gridmarch._table_steps, gridmarch._repeat_length = table, repeat


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    sys = big_plant(n=6, m=1, p=1, T=2 * np.pi, seed=2)
    T, L = sys.period, cfg['samples']
    rng = np.random.default_rng(0)

    def inputs(t):
        return np.cos(1.3 * t) + 0.5 * np.cos(0.37 * t)

    grids = {
        'aligned': T / 50 * np.arange(L),
        'P10a': np.linspace(0, cfg['periods'] * T, L),
        'P10b': 3 * T / 50 * np.arange(L),
        'P10c': np.cumsum(np.concatenate([[0.0], T / 50 * rng.uniform(0.8, 1.2, L - 1)])),
    }
    periods, Llong = cfg['long']
    grids['aligned long'] = T / 50 * np.arange(Llong)
    grids['P10d'] = np.linspace(0, periods * T, Llong)
    times, errs = {}, {}
    for name, t in grids.items():
        log(f"P10: {name}, {len(t)} samples")
        u = inputs(t)
        times[name], _, resp = median_time(lambda _: ltp.forced_response(sys, t, u),
                                           cfg['repeats'], setup=lambda: None)
        w = cfg['window']
        ref = _per_step(sys, t[:w], u[:w])
        y = np.asarray(resp.outputs)[:w]
        errs[name] = float(np.abs(y - ref).max() / np.abs(ref).max())
    rows = []
    labels = {'P10a': 'linspace(0, 100T, 5000): phases never repeat',
              'P10b': 'step 3T/50: phases repeat every 50 steps',
              'P10c': 'non-uniform grid, steps T/50 +- 20%',
              'P10d': f'linspace(0, {periods}T, {Llong}): a long record'}
    for name in ('P10a', 'P10b', 'P10c', 'P10d'):
        peer = 'aligned long' if name == 'P10d' else 'aligned'
        ratio = times[name] / times[peer]
        ok = errs[name] <= TOL and errs[peer] <= TOL
        rows.append(row(
            name, f"n=6 plant, {len(grids[name])} samples, {labels[name]}",
            ours='ltp.forced_response on this grid',
            peer='ltp.forced_response on the aligned grid (step T/50)',
            t_ours=times[name], t_peer=times[peer], metric='slowdown', value=ratio,
            target='<= 2x the aligned grid', target_met=ratio <= 2,
            err_ours=errs[name], err_peer=errs[peer], tol=TOL,
            checks={'ours <= tol': errs[name] <= TOL, 'aligned <= tol': errs[peer] <= TOL},
            matched=ok, notes='error against the same discretization, step by step',
            extra=dict(window=cfg['window'])))
    return rows
