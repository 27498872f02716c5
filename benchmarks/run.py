"""Speed of ltpcontrol against the tools a user would pick instead.

Usage::

    python benchmarks/run.py [--quick] [--json PATH] [--only P1,P3] [--wall]
                             [--blas-threads N]

Runs the workloads P1-P11 (one module each, see their docstrings), prints a
table and writes the results as JSON (default ``benchmarks/results.json``).
Every workload checks the accuracy both sides reached against an
independent reference; a speed ratio is only claimed when both reached the
stated tolerance (ratios marked ``*`` in the table were not matched).
``--quick`` is a smoke mode for CI: small sizes, speed not judged.

Timings are medians of repeated runs of CPU time of this process (``--wall``
for wall time), with BLAS limited to one thread (``--blas-threads``): on a
shared machine other jobs inflate the wall time, and an oversubscribed
multi-threaded BLAS was measured 10-200x slower on small problems, which
would make the ratios depend on the load rather than on the code.  All
peers are single-threaded Python, so one thread is also the fair setting.
The exit status is 1 when an accuracy check failed.
"""

import argparse
import os
import sys


def _parse(argv):
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    p.add_argument('--quick', action='store_true', help='small sizes (CI smoke mode)')
    p.add_argument('--json', default=None, help='output file (default benchmarks/results.json)')
    p.add_argument('--only', default=None, help='comma-separated workloads, e.g. P1,P4')
    p.add_argument('--wall', action='store_true', help='time with the wall clock')
    p.add_argument('--blas-threads', type=int, default=1,
                   help='BLAS/OpenMP threads (default 1)')
    return p.parse_args(argv)


def main(argv=None):
    args = _parse(argv)
    for var in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS'):
        os.environ[var] = str(args.blas_threads)
    # imports after the thread settings, which BLAS reads when it is loaded
    import json
    import platform
    import time
    import warnings

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import _common
    import numpy as np
    import scipy
    import control as ct
    import ltpcontrol as ltp
    import p1_simulation, p2_htf, p3_realization, p4_scaling, p5_floquet, p6_limit
    import p7_riccati
    import p8_analysis
    import p9_htf_memory
    import p10_grids
    import p11_orbits
    import p12_chatter
    import p13_campbell
    import p15_harmonic_stability
    import p14_floquet_scale

    if args.wall:
        _common.use_wall_clock()
    suites = {'P1': p1_simulation, 'P2': p2_htf, 'P3': p3_realization,
              'P4': p4_scaling, 'P5': p5_floquet, 'P6': p6_limit}
    suites['P7'] = p7_riccati
    suites['P8'] = p8_analysis
    suites['P9'] = p9_htf_memory
    suites['P10'] = p10_grids
    suites['P11'] = p11_orbits
    suites['P12'] = p12_chatter
    suites['P13'] = p13_campbell
    suites['P15'] = p15_harmonic_stability
    suites['P14'] = p14_floquet_scale
    only = [s.strip().upper() for s in args.only.split(',')] if args.only else list(suites)
    unknown = set(only) - set(suites)
    if unknown:
        raise SystemExit(f"unknown workloads {sorted(unknown)}; choose from {list(suites)}")

    def log(msg):
        print(f"[{time.perf_counter() - start:7.1f} s] {msg}", file=sys.stderr, flush=True)

    start = time.perf_counter()
    load0 = os.getloadavg()
    rows, durations = [], {}
    for name in only:
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', UserWarning)
            rows += suites[name].run(quick=args.quick, log=log)
        durations[name] = time.perf_counter() - t0
    total = time.perf_counter() - start

    text = _common.table(rows)
    print(f"ltpcontrol benchmarks ({'quick' if args.quick else 'full'} mode, "
          f"{_common.CLOCK['name']} medians, BLAS threads {args.blas_threads})")
    print(text)
    print("* ratio not matched: the peer did not reach the tolerance (see notes)")
    for r in rows:
        if r['notes']:
            print(f"  {r['id']}: {r['notes']}")
    print(f"total {total:.1f} s wall")

    failed = [f"{r['id']}: {k}" for r in rows for k, v in r['checks'].items() if not v]
    result = {
        'mode': 'quick' if args.quick else 'full', 'clock': _common.CLOCK['name'],
        'blas_threads': args.blas_threads, 'total_wall_s': total,
        'workload_wall_s': durations, 'loadavg_start': load0,
        'loadavg_end': os.getloadavg(), 'all_checks_passed': not failed,
        'failed_checks': failed,
        'versions': {'python': platform.python_version(), 'numpy': np.__version__,
                     'scipy': scipy.__version__, 'control': ct.__version__,
                     'ltpcontrol': ltp.__version__},
        'machine': {'cpus': os.cpu_count(), 'platform': platform.platform()},
        'rows': rows, 'table': text,
    }
    path = args.json or os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                     'results.json')
    with open(path, 'w') as fh:
        json.dump(result, fh, indent=1, default=_common.jsonable)
    print(f"wrote {path}")
    if failed:
        print("FAILED accuracy checks: " + '; '.join(failed))
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
