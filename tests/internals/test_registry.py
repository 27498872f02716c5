"""The registry of functions behind the methods of `LTPStateSpace` and `HTF`.

Tests of internals: they import private names (see the Developer notes).
"""

import ast

import pytest

import ltpcontrol
import ltpcontrol as ltp
from ltpcontrol._core.registry import aliased, method_alias, registered
from tools.import_graph import package_paths


def test_method_aliases_are_registered():
    """Every function a method looks up in the registry is registered by its module."""
    wanted = {node.args[0].value for path in package_paths().values()
              for node in ast.walk(ast.parse(path.read_text()))
              if isinstance(node, ast.Call) and getattr(node.func, 'id', '') == 'aliased'
              and node.args and isinstance(node.args[0], ast.Constant)}
    assert wanted and wanted <= set(registered())
    assert all(getattr(ltpcontrol, name) is not None for name in registered())


def test_methods_reach_the_public_functions():
    sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    assert sys.monodromy() == pytest.approx(ltp.monodromy(sys))
    assert sys.is_stable() and sys.zeros().size == 0
    assert sys.sample(0.1).dt == 0.1
    assert type(sys.htf(1)).__name__ == 'HTFModel'
    for name in ('monodromy', 'floquet_multipliers', 'floquet_exponents', 'is_stable', 'zeros',
                 'htf', 'sample_system', 'bode_htf'):
        assert aliased(name) is getattr(ltp, name)


def test_two_functions_of_one_name_are_refused():
    def zeros():
        pass
    with pytest.raises(RuntimeError, match="two functions named 'zeros'"):
        method_alias(zeros)
    assert aliased('zeros') is ltp.zeros
