"""The import graph of a package read from its source, every ``import`` and ``from ... import``
included, those inside functions too; and the three rules the layer test holds it to: no
import points up the layer order, no cycle, no private name taken from another module.

Used by ``tests/test_layers.py`` on ``spacewar/`` and ``validation/`` (and on a small package
made to break each rule, so the check is shown to fail when it should). What it cannot see:
``importlib.import_module`` with a computed name and module strings such as
``"spacewar.sandbox.bothost"``; the layer test checks the known ones by name.
"""
import ast
import os
from dataclasses import dataclass


@dataclass(frozen=True)
class Edge:
    """One import of a module of the package by another: ``source`` imports ``target``
    (dotted names), taking ``names`` from it (empty for ``import x``), at ``line``;
    ``local``: inside a function."""
    source: str
    target: str
    names: tuple
    line: int
    local: bool


def modules(root, package):
    """{dotted module name: file path} of every ``.py`` under ``root/package``."""
    found = {}
    base = os.path.join(root, package)
    for folder, dirs, files in os.walk(base):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(files):
            if not name.endswith(".py"):
                continue
            rel = os.path.relpath(os.path.join(folder, name), root)[:-3].split(os.sep)
            if rel[-1] == "__init__":
                rel = rel[:-1]
            found[".".join(rel)] = os.path.join(folder, name)
    return found


def _absolute(module, is_package, node):
    """The dotted name an ``ImportFrom`` node's module part refers to."""
    if not node.level:
        return node.module or ""
    parts = module.split(".")
    if not is_package:
        parts = parts[:-1]
    parts = parts[:len(parts) - (node.level - 1)]
    return ".".join(parts + ([node.module] if node.module else []))


def _inside_function(node, parents):
    while node in parents:
        node = parents[node]
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            return True
    return False


def _home(name, known):
    """The longest dotted prefix of ``name`` that is a module of the package, or None."""
    parts = name.split(".")
    while parts:
        candidate = ".".join(parts)
        if candidate in known:
            return candidate
        parts.pop()
    return None


def edges(root, package):
    """Every import between modules of ``package`` (under ``root``), as ``Edge``s. ``from a
    import b`` where ``a.b`` is a module counts as an import of ``a.b``."""
    known = modules(root, package)
    out = []
    for module, path in known.items():
        with open(path, encoding="utf-8") as f:
            tree = ast.parse(f.read(), path)
        parents = {child: node for node in ast.walk(tree) for child in ast.iter_child_nodes(node)}
        is_package = path.endswith("__init__.py")
        for node in ast.walk(tree):
            local = _inside_function(node, parents)
            if isinstance(node, ast.Import):
                for alias in node.names:
                    target = _home(alias.name, known)
                    if target and target != module:
                        out.append(Edge(module, target, (), node.lineno, local))
            elif isinstance(node, ast.ImportFrom):
                base = _absolute(module, is_package, node)
                plain = []
                for alias in node.names:
                    sub = f"{base}.{alias.name}"
                    if sub in known:
                        if sub != module:
                            out.append(Edge(module, sub, (), node.lineno, local))
                    else:
                        plain.append(alias.name)
                target = _home(base, known)
                if plain and target and target != module:
                    out.append(Edge(module, target, tuple(plain), node.lineno, local))
    return out


def cycles(graph_edges):
    """The strongly connected components of more than one module (Tarjan's algorithm), each a
    sorted list."""
    graph = {}
    for e in graph_edges:
        graph.setdefault(e.source, set()).add(e.target)
        graph.setdefault(e.target, set())
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


def private_attributes(root, package):
    """``(module, target, name, line)`` wherever a module of the package reads a ``_private``
    attribute of another module of it through the name it imported that module as
    (``from . import replay as r`` ... ``r._game``): a private import by another road."""
    known = modules(root, package)
    found = []
    for module, path in known.items():
        with open(path, encoding="utf-8") as f:
            tree = ast.parse(f.read(), path)
        is_package = path.endswith("__init__.py")
        aliases = {}
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.name in known and alias.asname:
                        aliases[alias.asname] = alias.name
            elif isinstance(node, ast.ImportFrom):
                base = _absolute(module, is_package, node)
                for alias in node.names:
                    sub = f"{base}.{alias.name}"
                    if sub in known:
                        aliases[alias.asname or alias.name] = sub
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and node.value.id in aliases and node.attr.startswith("_")
                    and not node.attr.startswith("__") and aliases[node.value.id] != module):
                found.append((module, aliases[node.value.id], node.attr, node.lineno))
    return found


def private_imports(graph_edges):
    """The edges that take a ``_private`` name from another module (``__dunder__`` names are
    not private)."""
    return [e for e in graph_edges
            if any(n.startswith("_") and not n.startswith("__") for n in e.names)]


def layer_of(module, layers):
    """The layer of ``module``: ``layers`` maps a dotted module or package name to a number;
    the longest matching prefix wins."""
    parts = module.split(".")
    while parts:
        name = ".".join(parts)
        if name in layers:
            return layers[name]
        parts.pop()
    raise KeyError(f"{module} has no layer")


def upward(graph_edges, layers):
    """The edges that point from a lower layer to a higher one (same layer: allowed)."""
    return [e for e in graph_edges if layer_of(e.source, layers) < layer_of(e.target, layers)]


def summary(root, package):
    """The figures the layer issue's note quotes: imports between the package's modules, how
    many inside functions, the cycles, the private imports, and the largest files."""
    found = edges(root, package)
    sizes = {}
    for module, path in modules(root, package).items():
        with open(path, encoding="utf-8") as f:
            sizes[module] = sum(1 for _ in f)
    return {"imports": len(found), "local": sum(e.local for e in found),
            "cycles": cycles(found), "private": private_imports(found),
            "largest": sorted(sizes.items(), key=lambda kv: -kv[1])[:6]}
