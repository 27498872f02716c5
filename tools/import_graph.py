"""The layers of ltpcontrol and its module import graph.

Run from the repository root::

    python tools/import_graph.py

It prints the layer of every module of the package, each module's imports
of other package modules (every import counts, including imports inside
functions), the cycles of that graph and the imports that point up the
layers, and exits with status 1 when there is a cycle, an upward import or a
module without a layer.  ``tests/test_layering.py`` runs it and checks the
same rules; the layer map below is their one definition.
"""

import ast
import pathlib
import sys

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / 'ltpcontrol'

# layer map
#: Layers from the bottom up: the private folders of ``ltpcontrol/`` (and the
#: top-level modules) that each holds.  A module may import from its own
#: layer and the layers listed before it, never from a layer after it.
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
    # periodic systems with delays (uses core and frequency): monodromy operator, exact
    # delayed HTFs, responses with history, stability charts of any LTP family
    'delays': ['_delays'],
    # python-control's entry points
    'interop': ['interop'],
    # portable files of systems, periodic matrices and HTFs
    'storage': ['storage'],
}
# end of layer map

#: The public namespace, which imports every layer; no module may import it.
TOP = '__init__'


def module_key(path, package=PACKAGE):
    """Dotted name of a package module relative to the package: ``_core.ltpsys``."""
    parts = path.relative_to(package).with_suffix('').parts
    if parts[-1] == '__init__' and len(parts) > 1:
        parts = parts[:-1]
    return '.'.join(parts)


def package_paths(package=PACKAGE):
    """Every module of the package, by its dotted key."""
    return {module_key(path, package): path for path in sorted(package.rglob('*.py'))}


def is_module(dotted, package=PACKAGE):
    path = package.joinpath(*dotted.split('.'))
    return path.with_suffix('.py').is_file() or (path / '__init__.py').is_file()


def package_imports(source, here='', package_name='ltpcontrol', is_mod=is_module):
    """Package modules (dotted, relative to the package) imported anywhere in `source`.

    `here` is the dotted folder of the importing module ('' at the top).
    ``from .x import y`` names module ``x`` (or ``x.y`` when `y` is a module
    of the package); ``from . import x`` names ``x``; ``import ltpcontrol``
    and ``from ltpcontrol import f`` name the public namespace ``__init__``.
    Imports inside functions and methods count like any other.
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
            elif node.module == package_name:
                target = ''
            elif node.module and node.module.startswith(package_name + '.'):
                target = node.module[len(package_name) + 1:]
            else:
                continue
            for alias in node.names:
                candidate = f"{target}.{alias.name}" if target else alias.name
                found.add(candidate if is_mod(candidate) else (target or TOP))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name == package_name:
                    found.add(TOP)
                elif alias.name.startswith(package_name + '.'):
                    found.add(alias.name[len(package_name) + 1:])
    return {mod for mod in found if mod}


def package_graph(package=PACKAGE):
    """``{module: set of imported package modules}`` of the whole package."""
    graph = {}
    for key, path in package_paths(package).items():
        is_pkg = path.name == '__init__.py'
        here = key if is_pkg and key != TOP else key.rpartition('.')[0]
        if key == TOP:
            here = ''
        graph[key] = package_imports(path.read_text(), here,
                                     is_mod=lambda d: is_module(d, package))
    return graph


def layer_index(layers):
    """Map each folder or top-level module to the rank of its layer (0 = bottom)."""
    rank = {}
    for i, members in enumerate(layers.values()):
        for mod in members:
            if mod in rank:
                raise ValueError(f"{mod} is assigned to two layers")
            rank[mod] = i
    return rank


def layer_of(module, layers=LAYERS):
    """The layer of `module` (None when its folder or name is in no layer)."""
    head = module.split('.')[0]
    for name, members in layers.items():
        if head in members:
            return name
    return None


def violations(graph, layers=LAYERS, top=TOP):
    """Layering errors: modules without a layer, upward imports, imports of the namespace."""
    members = layer_index(layers)
    names = list(layers)

    def rank(mod):
        return members.get(mod.split('.')[0])

    errors = []
    for mod in sorted(graph):
        if mod == top:
            continue
        if rank(mod) is None:
            errors.append(f"{mod} has no layer: put it in a layer folder and, for a new "
                          f"folder, add it to LAYERS in tools/import_graph.py (layers: "
                          f"{names}); the Developer notes page shows that map")
            continue
        for dep in sorted(graph[mod]):
            if dep == top:
                errors.append(f"{mod} imports the package namespace; import the module")
            elif rank(dep) is not None and rank(dep) > rank(mod):
                errors.append(f"{mod} ({names[rank(mod)]}) imports {dep} "
                              f"({names[rank(dep)]}), a higher layer")
    return errors


def cycles(graph):
    """The import cycles of `graph`: its strongly connected components of more
    than one module, and modules importing themselves (Tarjan's algorithm)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1 or v in graph.get(v, ()):
                found.append(sorted(comp))

    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 10 * len(graph) + 100))
    try:
        for v in sorted(graph):
            if v not in index:
                visit(v)
    finally:
        sys.setrecursionlimit(limit)
    return sorted(found)


def report(graph, layers=LAYERS):
    """The printed report: layers, imports, cycles and layering errors."""
    lines = ["Layers (bottom up) and their modules:"]
    for name in layers:
        mods = sorted(m for m in graph if m != TOP and layer_of(m, layers) == name)
        lines.append(f"  {name}: {len(mods)} module(s)")
        for mod in mods:
            deps = ', '.join(sorted(graph[mod])) or '-'
            lines.append(f"    {mod:34s} imports {deps}")
    unlayered = sorted(m for m in graph if m != TOP and layer_of(m, layers) is None)
    lines.append(f"Modules without a layer: {', '.join(unlayered) or 'none'}")
    found = cycles(graph)
    lines.append(f"Import cycles (every import, inside functions too): "
                 f"{'none' if not found else len(found)}")
    lines.extend("  " + " <-> ".join(comp) for comp in found)
    errors = violations(graph, layers)
    lines.append(f"Layering errors: {'none' if not errors else len(errors)}")
    lines.extend("  " + err for err in errors)
    return '\n'.join(lines), bool(found or errors)


def main():
    text, failed = report(package_graph())
    print(text)
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
