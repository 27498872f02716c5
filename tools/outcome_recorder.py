"""pytest plugin: write each test's outcome to the JSON file named by ``LTP_OUTCOMES``.

Used by ``tools/control_suite.py`` (``-p outcome_recorder``) to compare
python-control's tests one by one with and without ltpcontrol's bridge.
The file holds ``{"outcomes": {test: outcome}}``, each test named by its
file's absolute path and its name in the file (``/path/x_test.py::Class::test``,
a valid pytest argument from any directory), each outcome one of ``passed``,
``failed``, ``error``, ``skipped``, ``xfailed``, ``xpassed``.
"""

import json
import os

import pytest

_outcomes = {}
_RANK = {'passed': 0, 'xpassed': 1, 'skipped': 2, 'xfailed': 3, 'failed': 4, 'error': 5}


def _outcome(report):
    if hasattr(report, 'wasxfail'):
        return 'xfailed' if report.skipped else 'xpassed'
    if report.failed:
        return 'failed' if report.when == 'call' else 'error'
    return 'skipped' if report.skipped else 'passed'


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    report = (yield).get_result()
    key = f"{item.path}::{item.nodeid.split('::', 1)[1]}" if '::' in item.nodeid else str(item.path)
    # the worst phase (setup, call, teardown) decides the test's outcome
    outcome = _outcome(report)
    if _RANK[outcome] >= _RANK[_outcomes.get(key, 'passed')]:
        _outcomes[key] = outcome


def pytest_sessionfinish(session, exitstatus):
    path = os.environ.get('LTP_OUTCOMES')
    if path:
        with open(path, 'w') as f:
            json.dump({'outcomes': _outcomes}, f)
