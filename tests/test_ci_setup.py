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
    assert ci.index('tools/import_graph.py') < ci.index('-m pytest')
    assert 'CI=' in (ROOT / '.ci' / 'run').read_text()


@pytest.mark.skipif(not IN_CI, reason="checks the CI settings (CI=true)")
def test_hypothesis_is_derandomized_in_ci():
    assert settings.default.derandomize


@pytest.mark.skipif(not IN_CI, reason="checks the CI settings (CI=true)")
def test_cluster_extra_is_installed_in_ci():
    import dask.distributed  # noqa: F401  (the Dask test is run, not skipped)
