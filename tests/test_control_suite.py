"""python-control's own tests pass with ltpcontrol's bridge enabled exactly as without.

Runs ``tools/control_suite.py --subset`` (the test modules of the entry
points the bridge wraps, about a minute of CPU, with the bridge; then each test
that did not pass, without it); ``python tools/control_suite.py`` runs the
whole suite (about 4 minutes).
"""

import os
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@pytest.mark.slow
def test_python_control_suite_counts_are_unchanged_by_the_bridge():
    proc = subprocess.run([sys.executable, os.path.join(ROOT, 'tools', 'control_suite.py'),
                           '--subset'], capture_output=True, text=True, timeout=1800)
    print(proc.stdout)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "same outcomes" in proc.stdout
