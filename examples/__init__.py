"""Gallery examples and the plant models they share.

The gallery scripts (``plot_*.py``) run as scripts from this folder and
import the shared models by module name (``from hopper import ...``); the
tests import the same models as a package (``from examples.hopper import
...``).
"""
