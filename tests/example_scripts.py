"""Gallery scripts in tests: imported or run as sphinx-gallery runs them, from ``examples/``.

The shared models are a package (``from examples.hopper import ...``); the
gallery scripts import them by module name, so they run with ``examples/``
first on the path for that call only.  A script imported as a module keeps
``examples/`` on the path: joblib's worker processes import it by name to
run its functions.
"""

import contextlib
import importlib
import pathlib
import runpy
import sys

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / 'examples'


@contextlib.contextmanager
def in_examples():
    """``examples/`` first on ``sys.path`` for the duration of the block."""
    sys.path.insert(0, str(EXAMPLES))
    try:
        yield
    finally:
        sys.path.remove(str(EXAMPLES))


def import_script(name):
    """Import the gallery script `name` (without ``.py``) as a module."""
    if str(EXAMPLES) not in sys.path:
        sys.path.insert(0, str(EXAMPLES))
    return importlib.import_module(name)


def run_script(filename, **kwargs):
    """Run the gallery script `filename` as ``runpy.run_path`` does."""
    with in_examples():
        return runpy.run_path(str(EXAMPLES / filename), **kwargs)
