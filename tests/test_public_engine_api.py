"""Code outside ``engine/`` uses the engine only through its public names.

The game, the validation suite and the tests build on the engine as any user's code would: no
import of a private module or name (``engine._validate``, ``from engine.x import _y``), and no
reach into a private attribute the engine's own classes define (``sim._current_model()``).
"""
import ast
import functools
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
OUTSIDE = sorted(p for package in ("spacewar", "validation", "tests")
                 for p in (ROOT / package).rglob("*.py"))


def _private(name):
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


@functools.lru_cache(maxsize=None)
def _engine_private_attributes():
    """Private attribute and method names that engine modules define (``self._x``, ``def _x``);
    the engine's files parsed once for all the files checked."""
    names = set()
    for path in (ROOT / "engine").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                    and node.value.id == "self" and _private(node.attr):
                names.add(node.attr)
            elif isinstance(node, ast.FunctionDef) and _private(node.name):
                names.add(node.name)
    return frozenset(names)


def _offences(path, private_attributes):
    tree = ast.parse(path.read_text())
    own = {node.attr for node in ast.walk(tree) if isinstance(node, ast.Attribute)
           and isinstance(node.value, ast.Name) and node.value.id in ("self", "cls")}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "engine":
            if any(_private(part) for part in node.module.split(".")):
                found.append(f"line {node.lineno}: from {node.module} import ...")
            found += [f"line {node.lineno}: from {node.module} import {a.name}"
                      for a in node.names if _private(a.name)]
        elif isinstance(node, ast.Import):
            found += [f"line {node.lineno}: import {a.name}" for a in node.names
                      if a.name.split(".")[0] == "engine"
                      and any(_private(part) for part in a.name.split("."))]
        elif isinstance(node, ast.Attribute) and node.attr in private_attributes \
                and node.attr not in own:
            if isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"):
                continue
            found.append(f"line {node.lineno}: .{node.attr}")
    return found


@pytest.mark.parametrize("path", OUTSIDE, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_private_engine_name_is_used_outside_the_engine(path):
    if path.name == Path(__file__).name:
        return
    assert _offences(path, _engine_private_attributes()) == []


def test_the_check_finds_a_private_use():
    import tempfile
    with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as f:
        f.write("from engine._validate import finite_float\nimport engine._cache\n"
                "from engine.forces.base import _sealing\nsim._current_model()\n")
    found = _offences(Path(f.name), _engine_private_attributes())
    Path(f.name).unlink()
    assert len(found) == 4, found
