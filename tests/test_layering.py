"""The package is layered, and its import graph has no cycle.

The layer map and the graph are defined once, in ``tools/import_graph.py``
(the script anyone can rerun: ``python tools/import_graph.py``); the
Developer notes page shows that map.  Every import counts, including imports
inside functions, so a lazy import can neither hide a dependency on a higher
layer nor close a cycle.  A new module must sit in a layer folder before the
suite passes.
"""

import ast
import functools
import pathlib
import re
import subprocess
import sys

import pytest

from tools.import_graph import (LAYERS, PACKAGE, TOP, cycles, layer_index, package_graph,
                                package_imports, package_paths, violations)

ROOT = PACKAGE.parent


@functools.cache
def graph():
    """The package's import graph, built once for the tests of this module."""
    return package_graph()


@functools.cache
def parsed(path):
    """The syntax tree of a package module, parsed once for the tests of this module."""
    return ast.parse(path.read_text())


def _tree(source):
    return source if isinstance(source, ast.AST) else ast.parse(source)


def test_package_respects_layers():
    errors = violations(graph())
    assert not errors, "\n".join(errors)


def test_import_graph_has_no_cycle():
    found = cycles(graph())
    assert not found, "import cycles: " + "; ".join(" <-> ".join(c) for c in found)


def test_every_module_sits_in_a_layer_folder():
    top_level = {name for members in LAYERS.values() for name in members
                 if not name.startswith('_')}
    for key, path in package_paths().items():
        head = key.split('.')[0]
        if key == TOP:
            continue
        if '.' in key or path.name == '__init__.py':
            assert head.startswith('_') and head in layer_index(LAYERS), key
        else:
            assert key in top_level, (f"{key} is a top-level module; put it in the folder "
                                      "of its layer")


def test_import_graph_script_reports_layers_and_no_cycle():
    run = subprocess.run([sys.executable, str(ROOT / 'tools' / 'import_graph.py')],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "Import cycles (every import, inside functions too): none" in run.stdout
    assert "Modules without a layer: none" in run.stdout
    for key in package_paths():
        if key != TOP:
            assert re.search(rf"^    {re.escape(key)} +imports", run.stdout, re.M), key


def private_names(source, package='ltpcontrol'):
    """Private names of the package that `source` imports or reaches by attribute.

    A name is private when it, or a module on its dotted path, starts with one
    underscore (``ltpcontrol._core.ltpsys``, ``from ltpcontrol.interop import
    _wrap``, ``ltp._x``).
    """
    def private(parts):
        return [p for p in parts if p.startswith('_') and not p.startswith('__')]

    found, aliases = set(), set()
    tree = ast.parse(source)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split('.')
                if parts[0] == package:
                    if private(parts):
                        found.add(alias.name)
                    elif len(parts) == 1:
                        aliases.add(alias.asname or package)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module and \
                node.module.split('.')[0] == package:
            parts = node.module.split('.')
            for alias in node.names:
                if private(parts + [alias.name]):
                    found.add(f"{node.module}.{alias.name}")
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute):
            chain, value = [node.attr], node.value
            while isinstance(value, ast.Attribute):
                chain.insert(0, value.attr)
                value = value.value
            if isinstance(value, ast.Name) and value.id in aliases and private(chain):
                found.add('.'.join([value.id] + chain))
    return sorted(found)


TESTS = ROOT / 'tests'


@pytest.mark.parametrize('path', sorted(p.relative_to(TESTS).as_posix()
                                        for p in TESTS.rglob('*.py')
                                        if 'internals' not in p.parts))
def test_tests_use_public_names(path):
    """Tests outside ``tests/internals/`` import only the public names of ltpcontrol."""
    found = private_names((TESTS / path).read_text())
    assert not found, (f"{path} uses private names {found}: use the public namespace, or "
                       "move the test of internals to tests/internals/")


def test_private_names_are_found():
    source = ("import ltpcontrol as ltp\nimport ltpcontrol._core.ltpsys\n"
              "from ltpcontrol import htf, _x\nfrom ltpcontrol.interop import refusal, _wrap\n"
              "from ltpcontrol._core import floquet\nltp.htf\nltp._y\nltp.interop._z\n"
              "other._w\n")
    assert private_names(source) == ['ltp._y', 'ltp.interop._z', 'ltpcontrol._core.floquet',
                                     'ltpcontrol._core.ltpsys', 'ltpcontrol._x',
                                     'ltpcontrol.interop._wrap']


#: python-control's system keywords, documented where they are passed on to the result
SYSTEM_KEYWORDS = {'name', 'inputs', 'outputs', 'states', 'params'}


def hidden_options(source):
    """Documented parameters of public functions taking ``**kwargs`` missing from the signature
    (`source`: text or syntax tree).

    Such an option is read out of ``**kwargs`` (``kwargs.pop``) instead of
    being a keyword parameter.  Overloaded call forms (``*args``, as
    python-control's ``ss``) and the system keywords passed on to a result
    are exempt; ``__init__`` is checked against its class's docstring.
    """
    found = []
    tree = _tree(source)
    scopes = [(None, tree.body)] + [(node, node.body) for node in ast.walk(tree)
                                    if isinstance(node, ast.ClassDef)]
    for cls, body in scopes:
        for func in body:
            if (not isinstance(func, ast.FunctionDef) or func.args.kwarg is None
                    or func.args.vararg is not None
                    or (func.name.startswith('_') and func.name != '__init__')):
                continue
            doc = ast.get_docstring(cls if func.name == '__init__' and cls else func) or ''
            section = re.search(r'Parameters\n\s*-+\n(.*?)(?:\n\s*\n\s*\w[\w ]*\n\s*-+\n|\Z)',
                                doc, re.S)
            if not section:
                continue
            documented = {name.strip() for line in
                          re.findall(r'^ {0,4}([\w, ]+?) :', section.group(1), re.M)
                          for name in line.split(',')}
            args = func.args
            signature = {a.arg for a in args.posonlyargs + args.args + args.kwonlyargs}
            hidden = sorted(documented - signature - SYSTEM_KEYWORDS)
            if hidden:
                found.append(f"{func.name}: {', '.join(hidden)}")
    return found


@pytest.mark.parametrize('module', sorted(package_paths()))
def test_documented_options_are_parameters(module):
    found = hidden_options(parsed(package_paths()[module]))
    assert not found, f"{module}: make these keyword-only parameters: {found}"


def test_hidden_option_is_found():
    doc = ('"""Do.\n\n    Parameters\n    ----------\n    x : int\n    rtol, atol : float\n'
           '    name : str\n\n    Returns\n    -------\n    y : int\n    """')
    source = (f'def f(x, *, rtol=1, **kwargs):\n    {doc}\n'
              f'def g(*args, **kwargs):\n    {doc}\n'
              f'class C:\n    {doc}\n    def __init__(self, x, **kwargs):\n        pass\n')
    assert hidden_options(source) == ["f: atol", "__init__: atol, rtol"]


def test_library_does_not_patch_with_unittest():
    users = [key for key, path in package_paths().items()
             if {'unittest'} & {alias.name.split('.')[0] for node in
                                ast.walk(parsed(path))
                                if isinstance(node, (ast.Import, ast.ImportFrom))
                                for alias in ([ast.alias(node.module or '')]
                                              if isinstance(node, ast.ImportFrom)
                                              else node.names)}]
    assert users == []


def private_periodic_matrix_access(source):
    """Private `PeriodicMatrix` members (``_new``, ``_coeffs``, ...) used in `source`
    (text or syntax tree)."""
    private = {'_new', '_init', '_coeffs', '_func', '_pieces', '_times', '_combine'}
    return sorted({node.attr for node in ast.walk(_tree(source))
                   if isinstance(node, ast.Attribute) and node.attr in private})


def test_periodic_matrix_is_used_through_public_methods():
    users = {key: found for key, path in package_paths().items()
             if key != '_core.periodic_matrix'
             and (found := private_periodic_matrix_access(parsed(path)))}
    assert users == {}


def test_private_periodic_matrix_access_is_found():
    assert private_periodic_matrix_access("P = PeriodicMatrix._new(1.0, (1, 1))\n"
                                          "c = P._coeffs") == ['_coeffs', '_new']


#
# The check itself, on synthetic module graphs
#

SYNTHETIC = {'low': ['_a', '_b'], 'mid': ['_c'], 'high': ['_d']}


def test_upward_import_fails():
    graph = {'_a': {'_b'}, '_b': set(), '_c': {'_a'}, '_d': {'_c', '_a'}}
    assert violations(graph, SYNTHETIC) == []
    graph['_a'] = {'_d'}
    assert violations(graph, SYNTHETIC) == ["_a (low) imports _d (high), a higher layer"]
    graph['_a'], graph['_c'] = set(), {'_d'}
    assert violations(graph, SYNTHETIC) == ["_c (mid) imports _d (high), a higher layer"]


def test_importing_the_namespace_fails():
    graph = {'_a': {TOP}, TOP: {'_a'}}
    assert violations(graph, SYNTHETIC) == ["_a imports the package namespace; import the module"]
    assert cycles(graph) == [sorted(['_a', TOP])]


def test_unknown_module_fails_with_instructions():
    errors = violations({'_new': {'_a'}, '_a': set()}, SYNTHETIC)
    assert len(errors) == 1
    assert errors[0].startswith("_new has no layer: put it in a layer folder")


def test_module_in_two_layers_is_rejected():
    with pytest.raises(ValueError, match="two layers"):
        layer_index({'low': ['_a'], 'high': ['_a']})


def test_cycle_through_a_lazy_import_is_found():
    # _a imports _b at the top; _b imports _a inside a function: still a cycle
    graph = {'_a': package_imports("from ._b import g\n"),
             '_b': package_imports("def f():\n    from ._a import h\n"),
             '_c': package_imports("from ._a import h\n")}
    assert cycles(graph) == [['_a', '_b']]
    assert cycles({'_a': {'_a'}}) == [['_a']]
    assert cycles({'_a': {'_b'}, '_b': {'_c'}, '_c': set()}) == []


@pytest.mark.parametrize('source, expected', [
    ("from .._orbits.orbits import periodic_orbit", {'_orbits.orbits'}),
    ("from .._orbits import hybrid", {'_orbits.hybrid'}),
    ("from .floquet import monodromy", {'_core.floquet'}),
    ("from .. import config", {'config'}),
    ("import ltpcontrol._frequency.htf as h", {'_frequency.htf'}),
    ("from ltpcontrol._core.floquet import monodromy", {'_core.floquet'}),
    ("def f():\n    from .._identification.realization import floquet_realization\n",
     {'_identification.realization'}),
    ("def f():\n    import ltpcontrol\n", {TOP}),
    ("from ltpcontrol import htf", {TOP}),
    ("from .. import htf", {TOP}),
    ("import numpy as np\nfrom scipy import linalg", set()),
])
def test_imports_are_found_everywhere(source, expected):
    assert package_imports(source, '_core') == expected


def test_upward_lazy_import_in_a_source_fails():
    graph = {'_a': package_imports("def f():\n    from ._d import g\n"), '_d': set()}
    assert violations(graph, SYNTHETIC) == ["_a (low) imports _d (high), a higher layer"]
