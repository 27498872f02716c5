"""Run python-control's own test suite with ltpcontrol's bridge, and check it.

Usage::

    python tools/control_suite.py [--subset] [--full-baseline] [extra pytest arguments]

runs ``python -m pytest --pyargs control.tests`` with ltpcontrol imported and
its python-control bridge enabled (the pytest plugin
``tools/ltp_bridge_plugin.py``), then runs every test that did not pass
there once more with python-control alone, and exits with status 1 unless
each of those tests has the same outcome (skipped, xfailed, failed, ...)
without the bridge; a test whose outcome differs when run alone is judged
on the whole run without the bridge.  Failures that python-control's suite has in this
environment without ltpcontrol are reported, not hidden: they must simply
be the same with the bridge.  ``--full-baseline`` runs the whole suite
without the bridge as well and compares every test.

``--subset`` runs only the test modules of the entry points the bridge
wraps (time responses, block diagrams, state feedback, estimation, matrix
equations, norms, model reduction, keyword and docstring checks), about a
seventh of the suite's time.
"""

import json
import os
import subprocess
import sys
import tempfile
import time
from collections import Counter

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SUBSET = ('timeresp_test', 'statefbk_test', 'stochsys_test', 'mateqn_test', 'sysnorm_test',
          'modelsimp_test', 'minreal_test', 'bdalg_test', 'interconnect_test', 'kwargs_test',
          'docstrings_test', 'nlsys_test', 'matlab_test')


def run(targets, extra, bridge, pyargs=True):
    """Outcome of each test: ``({test: outcome}, seconds, summary line)``."""
    env = dict(os.environ)
    env['MPLBACKEND'] = 'Agg'
    env['PYTHONPATH'] = os.pathsep.join(
        [os.path.join(ROOT, 'tools'), ROOT] + [p for p in [env.get('PYTHONPATH')] if p])
    with tempfile.TemporaryDirectory() as cwd:       # outside the repository's conftest
        env['LTP_OUTCOMES'] = os.path.join(cwd, 'outcomes.json')
        cmd = [sys.executable, '-m', 'pytest', *(['--pyargs'] if pyargs else []), *targets,
               '-q', '-p', 'no:cacheprovider', '-p', 'outcome_recorder', '-rN', *extra]
        if bridge:
            cmd += ['-p', 'ltp_bridge_plugin']
        start = time.perf_counter()
        proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
        elapsed = time.perf_counter() - start
        lines = [ln for ln in proc.stdout.splitlines() if ln.strip()]
        summary = lines[-1] if lines else proc.stderr[-2000:]
        try:
            with open(env['LTP_OUTCOMES']) as f:
                record = json.load(f)
        except (OSError, ValueError):
            record = {'outcomes': {}}
    return record['outcomes'], elapsed, summary.strip('= ')


def main(argv):
    full_baseline = '--full-baseline' in argv
    extra = [a for a in argv if a not in ('--subset', '--full-baseline')]
    targets = ([f'control.tests.{name}' for name in SUBSET] if '--subset' in argv
               else ['control.tests'])
    bridged, seconds, summary = run(targets, extra, bridge=True)
    print(f"with ltpcontrol bridge: {summary}  [{seconds:.0f} s]", flush=True)
    if not bridged:
        print("no test ran")
        return 1
    if full_baseline:
        alone, seconds, summary = run(targets, extra, bridge=False)
        compared = sorted(set(bridged) | set(alone))
    else:
        # every test that did not pass with the bridge
        compared = sorted(k for k, v in bridged.items() if v != 'passed')
        alone, seconds, summary = {}, 0.0, 'nothing to run'
        if compared:
            alone, seconds, summary = run(compared, extra, bridge=False, pyargs=False)
    print(f"python-control alone  : {summary}  [{seconds:.0f} s, "
          f"{len(compared)} test(s) compared]", flush=True)
    differ = [k for k in compared if bridged.get(k) != alone.get(k)]
    if differ and not full_baseline:
        # a test run alone can behave otherwise than inside its module (fixtures,
        # order): confirm on the whole run without the bridge
        print(f"{len(differ)} outcome(s) differ when run alone; the whole run without "
              "the bridge decides", flush=True)
        alone, seconds, summary = run(targets, extra, bridge=False)
        print(f"python-control alone  : {summary}  [{seconds:.0f} s]", flush=True)
        differ = [k for k in compared if bridged.get(k) != alone.get(k)]
    for k in differ:
        print(f"  {k}: {bridged.get(k, 'not run')} with the bridge, "
              f"{alone.get(k, 'not run')} without")
    counts = Counter(bridged.values())
    print("outcomes with the bridge: " + ", ".join(f"{n} {k}" for k, n in sorted(counts.items())))
    if differ:
        print(f"{len(differ)} outcome(s) differ")
        return 1
    print("same outcomes")
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
