"""Any time grid against the aligned grid over the model size (not part of run.py).

``python benchmarks/grid_sweep.py [n:L ...] [--compiled] [--repeats R]``

For each ``n:L`` (default ``4:16000 16:16000 32:8000 64:4000``) a random
stable periodic plant of n states (`size_sweep.continuous_plant`: stiff,
harmonics in A, B and C, 2 inputs, 2 outputs, period 1) is simulated by
`forced_response` on L samples of three grids of 400 steps per period:

* aligned: step T/400;
* jittered: every inner sample moved by up to ±20 % of a step;
* unaligned: uniform step T/400.37 (the phases never repeat).

Each call runs R times (default 2; the best time counts), with states kept
and without, in one process with one BLAS thread, and the march is the
NumPy one unless ``--compiled`` (the `fast` extra) is given.  The rows
print the aligned grid's time and the other grids' times as multiples of
it.

On a jittered or unaligned grid every sample has its own phase: its state
costs D + 1 products with the cells' Chebyshev data (D + 1 = 13 for
these plants) against one on the aligned grid, and the cells' data cost D
sub-interval integrations per cell against one sixth-order step per
sample of the aligned grid's period.
"""

import argparse
import os
import sys
import time

# one BLAS thread (before numpy loads its BLAS)
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
os.environ.setdefault('OMP_NUM_THREADS', '1')

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from size_sweep import continuous_plant  # noqa: E402

PER_PERIOD = 400


def grids(L, seed=1):
    """The aligned, jittered and unaligned grids of L samples (period 1)."""
    h = 1.0 / PER_PERIOD
    jitter = np.random.default_rng(seed).uniform(-0.2, 0.2, L) * h
    jitter[[0, -1]] = 0.0
    return {'aligned': h * np.arange(L), 'jittered': h * np.arange(L) + jitter,
            'unaligned': np.arange(L) / (PER_PERIOD + 0.37)}


def sweep(n, L, repeats=2, log=print):
    """Best times ``{(grid, states kept): seconds}`` of one plant of n states."""
    import ltpcontrol as ltp
    sys_ = continuous_plant(n)
    times = {}
    for _ in range(repeats):
        for name, t in grids(L).items():
            u = np.vstack([np.cos(2.3 * t), np.sin(1.1 * t)])
            for states in (True, False):
                start = time.perf_counter()
                ltp.forced_response(sys_, t, u, compute_states=states)
                elapsed = time.perf_counter() - start
                times[name, states] = min(times.get((name, states), np.inf), elapsed)
    for states in (True, False):
        aligned = times['aligned', states]
        log(f"n={n:4d} L={L:7d} states {'kept' if states else 'not kept'}: aligned "
            f"{aligned:.3f} s, jittered {times['jittered', states] / aligned:.2f}x, "
            f"unaligned {times['unaligned', states] / aligned:.2f}x")
    return times


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument('cases', nargs='*', default=['4:16000', '16:16000', '32:8000', '64:4000'],
                   help='n:L pairs (states:samples)')
    p.add_argument('--compiled', action='store_true', help='the compiled march (numba)')
    p.add_argument('--repeats', type=int, default=2)
    args = p.parse_args(argv)
    import ltpcontrol as ltp
    ltp.config.set_defaults('timeresp', compiled=args.compiled)
    for case in args.cases:
        n, L = (int(v) for v in case.split(':'))
        sweep(n, L, args.repeats)


if __name__ == '__main__':
    main()
