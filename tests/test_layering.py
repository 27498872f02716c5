"""The package is layered: a module may import only from its own layer or below.

The layer map below is the one place the layers are defined; the Developer
notes page of the documentation shows it.  Every import counts, including
imports inside functions, so a lazy import cannot hide a dependency on a
higher layer.  A new module must be given a layer here before the suite
passes.
"""

import ast
import functools
import pathlib
import re

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / 'ltpcontrol'

# layer map
#: Layers from the bottom up, one folder of ``ltpcontrol/`` each (top-level
#: modules named explicitly); a module may import from its own layer and the
#: layers listed before it.
LAYERS = {
    # configuration
    'config': ['config'],
    # systems, periodic matrices, simulation, Floquet theory, discretization, lifting
    'core': ['_core'],
    # harmonic transfer functions, their plots, the harmonic state space
    'frequency': ['_frequency'],
    # analysis and synthesis on LTP models
    'analysis': ['_analysis'],
    # rhythmic (hybrid) plants, their periodic orbits and closed loops
    'orbits': ['_orbits'],
    # experiments and identification from data
    'identification': ['_identification'],
    # rotors and wind turbines: multi-blade coordinates, OpenFAST files, Campbell diagrams
    'rotors': ['_rotors'],
    # python-control's entry points
    'interop': ['interop'],
    # portable files of systems, periodic matrices and HTFs
    'storage': ['storage'],
}

#: Method aliases: methods of a class that call a public function of a higher
#: layer (python-control's ``lti.py`` does the same), e.g. ``sys.zeros()``
#: for ``ltp.zeros(sys)``, so that python-control's own function dispatches.
METHOD_ALIASES = {'_core.ltpsys': {'_frequency.htf', '_analysis.zeros', 'interop'},
                  '_core.interconnect': {'interop'}}
# end of layer map

#: Modules exempt from the layering: the public namespace imports everything.
TOP = {'__init__'}


def module_key(path):
    """Dotted name of a package module relative to the package: ``_core.ltpsys``."""
    parts = path.relative_to(PACKAGE).with_suffix('').parts
    if parts[-1] == '__init__' and len(parts) > 1:
        parts = parts[:-1]
    return '.'.join(parts)


def layer_of(module, layers):
    """The layer whose folder (or top-level module) holds `module`."""
    head = module.split('.')[0]
    for name, members in layers.items():
        if head in members:
            return name
    return None


def layer_index(layers):
    """Map each folder or top-level module to the rank of its layer (0 = bottom)."""
    rank = {}
    for i, members in enumerate(layers.values()):
        for mod in members:
            assert mod not in rank, f"{mod} is assigned to two layers"
            rank[mod] = i
    return rank


def package_imports(source, here='', package='ltpcontrol'):
    """Package modules (dotted, relative to the package) imported anywhere in `source`.

    `here` is the dotted folder of the importing module ('' at the top).
    ``from .x import y`` names module ``x`` (or ``x.y`` when `y` is a module
    of the package); ``from . import x`` names ``x``.
    """
    found = set()
    base = here.split('.') if here else []

    def resolve(level, module):
        parts = base[:len(base) - (level - 1)] if level > 1 else list(base)
        return '.'.join(parts + (module.split('.') if module else []))

    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom):
            if node.level >= 1:
                target = resolve(node.level, node.module)
            elif node.module and node.module.startswith(package + '.'):
                target = node.module[len(package) + 1:]
            else:
                continue
            for alias in node.names:
                candidate = f"{target}.{alias.name}" if target else alias.name
                found.add(candidate if _is_module(candidate) or not target else target)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith(package + '.'):
                    found.add(alias.name[len(package) + 1:])
    return {mod for mod in found if mod}


def _is_module(dotted):
    path = PACKAGE.joinpath(*dotted.split('.'))
    return path.with_suffix('.py').is_file() or (path / '__init__.py').is_file()


def violations(graph, layers, top=frozenset(), aliases=None):
    """Layering errors of a module graph ``{module: set of imported modules}``."""
    aliases = aliases or {}
    members = layer_index(layers)
    rank = {mod: members[mod.split('.')[0]] for mod in set(graph).union(*graph.values())
            if mod.split('.')[0] in members}
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


def package_paths():
    """Every module of the package, by its dotted key."""
    return {module_key(path): path for path in sorted(PACKAGE.rglob('*.py'))}


def package_source_imports(key, source):
    here = key if PACKAGE.joinpath(*key.split('.'), '__init__.py').is_file() else \
        key.rpartition('.')[0]
    return package_imports(source, here)


def package_graph():
    return {key: package_source_imports(key, path.read_text())
            for key, path in package_paths().items()}


def _module_level(source):
    """The module-level statements of `source` (imports inside functions excluded)."""
    body = ast.parse(source).body
    return '\n'.join(ast.unparse(node) for node in body
                     if not isinstance(node, (ast.FunctionDef, ast.ClassDef)))


def lazy_imports(source, here=''):
    """Package modules imported inside functions and methods of `source`."""
    return package_imports(source, here) - package_imports(_module_level(source), here)


def reaches(graph, start, goal):
    """True when `start` imports `goal`, directly or through other modules."""
    seen, todo = set(), [start]
    while todo:
        mod = todo.pop()
        if mod == goal:
            return True
        if mod not in seen:
            seen.add(mod)
            todo.extend(graph.get(mod, ()))
    return False


def unforced_lazy_imports(sources, aliases=None):
    """Lazy imports ``(module, imported)`` that a module-level import could replace.

    A lazy import is forced when the imported module already imports the
    importer at module level (a top-level import would close a cycle), or
    when it serves a method alias.
    """
    aliases = aliases or {}
    def here(mod):
        return mod.rpartition('.')[0]
    top = {mod: package_imports(_module_level(src), here(mod)) for mod, src in sources.items()}
    return sorted((mod, dep) for mod, src in sources.items()
                  for dep in lazy_imports(src, here(mod)) - TOP
                  if dep not in aliases.get(mod, ()) and not reaches(top, dep, mod))


@functools.cache
def package_unforced():
    sources = {key: path.read_text() for key, path in package_paths().items()}
    return unforced_lazy_imports(sources, METHOD_ALIASES)


def test_package_respects_layers():
    errors = violations(package_graph(), LAYERS, TOP, METHOD_ALIASES)
    assert not errors, "\n".join(errors)


def modules(pending, reason):
    """The package's modules; those in `pending` must fail (strict xfail) until mended."""
    return [pytest.param(key, marks=pytest.mark.xfail(strict=True, reason=reason))
            if key in pending else key for key in package_paths()]


# modules whose lazy imports are not yet at module level
PENDING_LAZY = set()


@pytest.mark.parametrize('module', modules(PENDING_LAZY, "lazy imports without a cycle"))
def test_lazy_imports_only_where_a_cycle_forces_them(module):
    found = [dep for mod, dep in package_unforced() if mod == module]
    assert not found, f"{module} imports {found} inside functions; import at module top"


def test_unforced_lazy_import_is_found():
    sources = {'_a': "from ._b import g\n", '_b': "def f():\n    from ._a import h\n",
               '_c': "def f():\n    from ._b import g\n"}
    # _b -> _a is forced (_a imports _b at module level); _c -> _b is not
    assert unforced_lazy_imports(sources) == [('_c', '_b')]
    assert unforced_lazy_imports(sources, {'_c': {'_b'}}) == []


#: python-control's system keywords, documented where they are passed on to the result
SYSTEM_KEYWORDS = {'name', 'inputs', 'outputs', 'states', 'params'}


def hidden_options(source):
    """Documented parameters of public functions taking ``**kwargs`` missing from the signature.

    Such an option is read out of ``**kwargs`` (``kwargs.pop``) instead of
    being a keyword parameter.  Overloaded call forms (``*args``, as
    python-control's ``ss``) and the system keywords passed on to a result
    are exempt; ``__init__`` is checked against its class's docstring.
    """
    found = []
    tree = ast.parse(source)
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


# modules that still take documented options out of **kwargs
PENDING_OPTIONS = set()


@pytest.mark.parametrize('module', modules(PENDING_OPTIONS,
                                              "documented option in **kwargs"))
def test_documented_options_are_parameters(module):
    found = hidden_options(package_paths()[module].read_text())
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
                                ast.walk(ast.parse(path.read_text()))
                                if isinstance(node, (ast.Import, ast.ImportFrom))
                                for alias in ([ast.alias(node.module or '')]
                                              if isinstance(node, ast.ImportFrom)
                                              else node.names)}]
    assert users == []


def private_periodic_matrix_access(source):
    """Private `PeriodicMatrix` members (``_new``, ``_coeffs``, ...) used in `source`."""
    private = {'_new', '_init', '_coeffs', '_func', '_pieces', '_times', '_combine'}
    return sorted({node.attr for node in ast.walk(ast.parse(source))
                   if isinstance(node, ast.Attribute) and node.attr in private})


def test_periodic_matrix_is_used_through_public_methods():
    users = {key: found for key, path in package_paths().items()
             if key != '_core.periodic_matrix'
             and (found := private_periodic_matrix_access(path.read_text()))}
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
    ("from .._orbits.orbits import periodic_orbit", {'_orbits.orbits'}),
    ("from .._orbits import hybrid", {'_orbits.hybrid'}),
    ("from .floquet import monodromy", {'_core.floquet'}),
    ("from .. import config", {'config'}),
    ("import ltpcontrol._frequency.htf as h", {'_frequency.htf'}),
    ("from ltpcontrol._core.floquet import monodromy", {'_core.floquet'}),
    ("def f():\n    from .._identification.realization import floquet_realization\n",
     {'_identification.realization'}),
    ("import numpy as np\nfrom scipy import linalg", set()),
])
def test_imports_are_found_everywhere(source, expected):
    assert package_imports(source, '_core') == expected


def test_upward_lazy_import_in_a_source_fails():
    graph = {'_a': package_imports("def f():\n    from ._d import g\n"), '_d': set()}
    assert violations(graph, SYNTHETIC) == ["_a (low) imports _d (high), a higher layer"]
