"""Run python-control's own test suite without and with ltpcontrol's bridge.

Usage::

    python tools/control_suite.py [--subset] [extra pytest arguments]

runs ``python -m pytest --pyargs control.tests`` twice, plainly and with
ltpcontrol imported and its python-control bridge enabled (the pytest
plugin ``tools/ltp_bridge_plugin.py``), prints the two summary lines and
exits with status 1 unless the outcome counts (passed, failed, skipped,
xfailed, xpassed, errors) are equal.  Failures that python-control's suite
has in this environment without ltpcontrol are reported, not hidden: they
must simply be the same with the bridge.

``--subset`` runs only the test modules of the entry points the bridge
wraps (time responses, block diagrams, state feedback, estimation, matrix
equations, norms, model reduction, keyword and docstring checks), about a
seventh of the suite's time (about 35 s of CPU against 4 minutes).
"""

import os
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SUBSET = ('timeresp_test', 'statefbk_test', 'stochsys_test', 'mateqn_test', 'sysnorm_test',
          'modelsimp_test', 'minreal_test', 'bdalg_test', 'interconnect_test', 'kwargs_test',
          'docstrings_test', 'nlsys_test', 'matlab_test')
KINDS = ('passed', 'failed', 'skipped', 'xfailed', 'xpassed', 'errors', 'error', 'warnings')


def run(extra, bridge):
    env = dict(os.environ)
    env['MPLBACKEND'] = 'Agg'
    env['PYTHONPATH'] = os.pathsep.join(
        [os.path.join(ROOT, 'tools'), ROOT] + [p for p in [env.get('PYTHONPATH')] if p])
    targets = ['control.tests']
    if '--subset' in extra:
        extra = [a for a in extra if a != '--subset']
        targets = [f'control.tests.{name}' for name in SUBSET]
    cmd = [sys.executable, '-m', 'pytest', '--pyargs', *targets, '-q',
           '-p', 'no:cacheprovider', '-rN', *extra]
    if bridge:
        cmd += ['-p', 'ltp_bridge_plugin']
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as cwd:       # outside the repository's conftest
        proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    lines = [ln for ln in proc.stdout.splitlines() if ln.strip()]
    summary = lines[-1] if lines else proc.stderr[-2000:]
    return summary, counts(summary), elapsed


def counts(summary):
    found = dict((kind, int(n)) for n, kind in re.findall(r'(\d+) (\w+)', summary))
    found['errors'] = found.pop('error', 0) + found.get('errors', 0)
    found.pop('warnings', None)
    return {k: v for k, v in found.items() if k in KINDS and v}


def main(argv):
    results = []
    for bridge in (False, True):
        summary, found, elapsed = run(argv, bridge)
        label = 'with ltpcontrol bridge' if bridge else 'python-control alone  '
        print(f"{label}: {summary.strip('= ')}  [{elapsed:.0f} s]", flush=True)
        results.append(found)
    if not results[0] or results[0] != results[1]:
        print("outcome counts differ" if results[0] else "no test ran")
        return 1
    print("same outcome counts")
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
