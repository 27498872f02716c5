"""Smoke test of the benchmark suite: ``benchmarks/run.py --quick``.

Speed is not judged here; the test checks that the command runs, prints
the table, writes the JSON file and that every accuracy check passed.
"""

import json
import os
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WORKLOADS = ['P1a', 'P1b', 'P2a', 'P2b', 'P3', 'P4a', 'P4b', 'P5a', 'P5b', 'P5c',
             'P6a', 'P6b', 'P6c',
             'P8a', 'P8b']
WORKLOADS += ['P7-4']
WORKLOADS += ['P10a', 'P10b', 'P10c', 'P10d']
WORKLOADS += ['P12a', 'P12b']


@pytest.fixture(scope='module')
def quick_run(tmp_path_factory):
    path = tmp_path_factory.mktemp('bench') / 'results.json'
    proc = subprocess.run(
        [sys.executable, os.path.join(ROOT, 'benchmarks', 'run.py'), '--quick',
         '--json', str(path)],
        capture_output=True, text=True, timeout=300, cwd=ROOT)
    return proc, path


def test_command_succeeds(quick_run):
    proc, _ = quick_run
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]


def test_table_printed(quick_run):
    proc, _ = quick_run
    out = proc.stdout
    assert 'quick mode' in out
    header = next(line for line in out.splitlines() if line.startswith('id '))
    for column in ('workload', 'ours s', 'peer s', 'result', 'target', 'accuracy'):
        assert column in header
    for rid in WORKLOADS:
        assert any(line.startswith(rid + ' ') for line in out.splitlines()), rid


def test_json_written_and_checks_pass(quick_run):
    _, path = quick_run
    result = json.loads(path.read_text())
    assert result['mode'] == 'quick'
    rows = {r['id']: r for r in result['rows']}
    assert set(WORKLOADS) <= set(rows)      # P3, P6a/b may be 'not available'
    assert result['all_checks_passed'], result['failed_checks']
    for r in result['rows']:
        if r['status'] != 'ok':
            continue
        assert r['checks'], r['id']
        assert all(r['checks'].values()), (r['id'], r['checks'])
        assert r['t_ours'] is not None and r['t_ours'] > 0, r['id']
        if r['metric'] == 'ratio' and r['peer'] is not None:
            assert r['t_peer'] is not None and r['t_peer'] > 0, r['id']
        # a ratio is claimed only at matched accuracy
        if r['matched']:
            assert r['err_peer'] is not None and r['err_peer'] <= r['tol'], r['id']
