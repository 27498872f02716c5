"""The package is layered: a module may import only from its own layer or below.

The layer map below is the one place the layers are defined; the Developer
notes page of the documentation shows it.  Every import counts, including
imports inside functions, so a lazy import cannot hide a dependency on a
higher layer.  A new module must be given a layer here before the suite
passes.
"""

import ast
import pathlib

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / 'ltpcontrol'

# layer map
#: Layers from the bottom up; a module may import from its own layer and the
#: layers listed before it.
LAYERS = {
    # systems, periodic matrices, simulation, Floquet theory, frequency domain
    'core': ['config', '_validation', '_transition', '_march', '_steps', '_periodic_matrix',
             '_ltpsys', '_timeresp', '_floquet', '_htf', '_htfplot', '_harmonic_ss',
             '_display', '_discretize', '_lifting', '_metrics',
             # python-control's entry points: reaches higher layers only by name,
             # through the public namespace, when called
             '_interop'],
    # analysis and synthesis on LTP models
    'analysis': ['_lyapunov', '_riccati', '_norms', '_zeros', '_design', '_place', '_lmi',
                 '_reduction', '_interconnect'],
    # rhythmic (hybrid) plants, their periodic orbits and closed loops
    'orbits': ['_hybrid', '_orbits', '_autonomous', '_continuation', '_closed_loop'],
    # experiments and identification from data
    'identification': ['_excitation', '_htf_estimate', '_htf_fit', '_fdsubspace',
                       '_hybrid_ls', '_realization', '_floquet_fit', '_canonical',
                       '_structure', '_ltp_subspace', '_refine', '_montecarlo', '_arx',
                       '_lifted_response'],
}

#: Method aliases: methods of a class that call a public function of a higher
#: layer (python-control's ``lti.py`` does the same), e.g. ``sys.zeros()``
#: for ``ltp.zeros(sys)``, so that python-control's own function dispatches.
METHOD_ALIASES = {'_ltpsys': {'_zeros'}}
# end of layer map

#: Modules exempt from the layering: the public namespace imports everything.
TOP = {'__init__'}


def layer_index(layers):
    """Map each module to the rank of its layer (0 = bottom)."""
    rank = {}
    for i, modules in enumerate(layers.values()):
        for mod in modules:
            assert mod not in rank, f"{mod} is assigned to two layers"
            rank[mod] = i
    return rank


def package_imports(source, package='ltpcontrol'):
    """Names of the package's modules imported anywhere in `source`."""
    found = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom):
            if node.level == 1 and node.module:            # from ._x import y
                found.add(node.module.split('.')[0])
            elif node.level == 1:                          # from . import _x
                found.update(alias.name for alias in node.names)
            elif node.level == 0 and node.module and node.module.startswith(package + '.'):
                found.add(node.module.split('.')[1])
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith(package + '.'):
                    found.add(alias.name.split('.')[1])
    return found


def violations(graph, layers, top=frozenset(), aliases=None):
    """Layering errors of a module graph ``{module: set of imported modules}``."""
    aliases = aliases or {}
    rank = layer_index(layers)
    names = list(layers)
    errors = []
    for mod in sorted(graph):
        if mod in top:
            continue
        if mod not in rank:
            errors.append(f"{mod} has no layer: add it to LAYERS in tests/test_layering.py "
                          f"(one of {names}); the Developer notes page shows that map")
            continue
        for dep in sorted(graph[mod]):
            if dep in top:
                errors.append(f"{mod} imports the package namespace; import the module")
            elif dep in rank and rank[dep] > rank[mod] and dep not in aliases.get(mod, ()):
                errors.append(f"{mod} ({names[rank[mod]]}) imports {dep} "
                              f"({names[rank[dep]]}), a higher layer")
    return errors


def package_graph():
    return {path.stem: package_imports(path.read_text())
            for path in sorted(PACKAGE.glob('*.py'))}


def test_package_respects_layers():
    errors = violations(package_graph(), LAYERS, TOP, METHOD_ALIASES)
    assert not errors, "\n".join(errors)


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


def test_method_alias_is_the_only_upward_exception():
    graph = {'_a': {'_d'}, '_b': {'_d'}, '_c': set(), '_d': set()}
    assert violations(graph, SYNTHETIC, aliases={'_a': {'_d'}}) == [
        "_b (low) imports _d (high), a higher layer"]


def test_unknown_module_fails_with_instructions():
    errors = violations({'_new': {'_a'}, '_a': set()}, SYNTHETIC)
    assert len(errors) == 1
    assert errors[0].startswith("_new has no layer: add it to LAYERS")


def test_module_in_two_layers_is_rejected():
    with pytest.raises(AssertionError, match="two layers"):
        layer_index({'low': ['_a'], 'high': ['_a']})


@pytest.mark.parametrize('source, expected', [
    ("from ._orbits import periodic_orbit", {'_orbits'}),
    ("from . import _hybrid", {'_hybrid'}),
    ("import ltpcontrol._htf as h", {'_htf'}),
    ("from ltpcontrol._floquet import monodromy", {'_floquet'}),
    ("def f():\n    from ._realization import floquet_realization\n", {'_realization'}),
    ("import numpy as np\nfrom scipy import linalg", set()),
])
def test_imports_are_found_everywhere(source, expected):
    assert package_imports(source) == expected


def test_upward_lazy_import_in_a_source_fails():
    graph = {'_a': package_imports("def f():\n    from ._d import g\n"), '_d': set()}
    assert violations(graph, SYNTHETIC) == ["_a (low) imports _d (high), a higher layer"]
