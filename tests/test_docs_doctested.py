"""Every documentation page with runnable examples is collected by pytest."""

import pathlib

import pytest

tomllib = pytest.importorskip('tomllib')      # Python >= 3.11

ROOT = pathlib.Path(__file__).resolve().parent.parent


def test_pages_with_examples_are_in_testpaths():
    config = tomllib.loads((ROOT / 'pyproject.toml').read_text())
    testpaths = set(config['tool']['pytest']['ini_options']['testpaths'])
    pages = {f"docs/{p.name}" for p in (ROOT / 'docs').glob('*.rst')
             if '>>>' in p.read_text(encoding='utf-8')}
    assert pages, "no documentation page with examples found"
    assert pages <= testpaths, f"add to [tool.pytest.ini_options] testpaths: {sorted(pages - testpaths)}"
