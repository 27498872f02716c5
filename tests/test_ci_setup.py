"""The continuous-integration command runs everything it claims."""

import os
import pathlib
import re

import pytest
from hypothesis import settings

ROOT = pathlib.Path(__file__).resolve().parents[1]
IN_CI = os.environ.get('CI', '').lower() in ('true', '1')


def readme_commands():
    return re.findall(r"^```bash\n(.*?)\n```", (ROOT / 'README.md').read_text(), re.M | re.S)


def test_readme_opens_with_two_commands():
    text = (ROOT / 'README.md').read_text()
    commands = readme_commands()
    assert len(commands) >= 2
    assert text.index(commands[1]) < text.index('## ')     # both before the first section


def test_ci_command_installs_the_cluster_extra_and_prints_the_import_graph():
    ci = readme_commands()[1]
    extras = re.search(r'-e "\.\[([\w,]+)\]"', ci).group(1).split(',')
    assert {'test', 'docs', 'cluster'} <= set(extras)
    assert ci.endswith('.venv/bin/python tools/check.py')
    assert 'CI=' in (ROOT / '.ci' / 'run').read_text()


def _check_script():
    import importlib.util
    spec = importlib.util.spec_from_file_location('check', ROOT / 'tools' / 'check.py')
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_check_script_runs_the_import_graph_the_suite_and_the_strict_docs_build():
    checks = _check_script().CHECKS
    assert checks['imports'][1:] == ['tools/import_graph.py']
    assert checks['tests'][1:3] == ['-m', 'pytest']
    # spread over the cores with test files kept whole (module fixtures computed once)
    assert checks['tests'][3:] in ([], ['-n', str(_check_script().cores()), '--dist', 'loadfile'])
    assert checks['docs'][0].endswith('sphinx-build') and '-W' in checks['docs']


def test_check_script_reports_a_failing_check(monkeypatch, capsys):
    check = _check_script()
    monkeypatch.setattr(check, 'CHECKS', {
        'good': [check.PYTHON, '-c', 'print("fine")'],
        'bad': [check.PYTHON, '-c', 'import sys; print("broken"); sys.exit(3)']})
    with pytest.raises(SystemExit, match="failed checks: bad"):
        check.main([])
    out = capsys.readouterr().out
    assert 'fine' in out and 'broken' in out and 'FAILED, exit 3' in out
    with pytest.raises(SystemExit, match="unknown check"):
        check.main(['nothing'])


@pytest.mark.skipif(not IN_CI, reason="checks the CI settings (CI=true)")
def test_hypothesis_is_derandomized_in_ci():
    assert settings.default.derandomize


@pytest.mark.skipif(not IN_CI, reason="checks the CI settings (CI=true)")
def test_cluster_extra_is_installed_in_ci():
    import dask.distributed       # the Dask test is run, not skipped
    assert callable(dask.distributed.LocalCluster)
