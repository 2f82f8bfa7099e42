"""The game's code keeps its one-way layers: every import of ``spacewar`` (inside functions
too) points down the order declared once in pyproject.toml's ``[tool.importlinter]``; no
module of ``spacewar`` or ``validation`` is in an import cycle or takes a private name from
another; and the check is shown to catch each of these on a package made to break them."""
import ast
import importlib
import os
import re
import subprocess
import sys
import textwrap
import tomllib

import pytest

from tests import import_graph

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def declared_layers(pyproject=os.path.join(ROOT, "pyproject.toml"), package="spacewar"):
    """{module: layer number, 0 at the bottom} from the layers contract of ``package`` in
    ``pyproject``'s import-linter configuration (listed top to bottom, ``a : b`` sharing one)."""
    with open(pyproject, "rb") as f:
        contracts = tomllib.load(f)["tool"]["importlinter"]["contracts"]
    (layers,) = [c["layers"] for c in contracts
                 if c["type"] == "layers" and c["layers"][0].startswith(package + ".")]
    table = {}
    for depth, line in enumerate(reversed(layers)):
        for name in line.replace("|", ":").split(":"):
            table[name.strip()] = depth
    return table


def layer_violations(root, package, layers):
    """What the walk finds against the three rules: upward edges, cycles, private imports,
    and modules the table does not place."""
    found = import_graph.edges(root, package)
    unplaced = [m for m in import_graph.modules(root, package)
                if m != package and not _placed(m, layers)]
    placed = [e for e in found if _placed(e.source, layers) and _placed(e.target, layers)]
    return {"upward": import_graph.upward(placed, layers), "cycles": import_graph.cycles(found),
            "private": import_graph.private_imports(found),
            "private_attributes": import_graph.private_attributes(root, package),
            "unplaced": unplaced}


def _placed(module, layers):
    try:
        import_graph.layer_of(module, layers)
        return True
    except KeyError:
        return False


def test_every_spacewar_import_points_down_and_none_is_private_or_circular():
    layers = declared_layers()
    problems = layer_violations(ROOT, "spacewar", layers)
    assert problems == {"upward": [], "cycles": [], "private": [], "private_attributes": [],
                        "unplaced": []}


def test_every_validation_import_points_down_and_none_is_private_or_circular():
    layers = declared_layers(package="validation")
    problems = layer_violations(ROOT, "validation", layers)
    assert problems == {"upward": [], "cycles": [], "private": [], "private_attributes": [],
                        "unplaced": []}


def test_the_import_linter_contracts_hold():
    out = subprocess.run([sys.executable, "-c", "from importlinter.cli import lint_imports; "
                          "raise SystemExit(lint_imports())"], cwd=ROOT, capture_output=True,
                         text=True)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "0 broken" in out.stdout


def test_what_a_bots_process_needs_loads_no_numba_and_no_engine():
    code = ("import sys\n"
            "import spacewar.codes, spacewar.rules, spacewar.protocol, spacewar.wire, "
            "spacewar.faults, spacewar.builtin_bots, spacewar.bots\n"
            "print(sorted(m for m in ('numba', 'engine') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"


#: a string in the code that names a module, or a name in one: ``pkg.module`` or
#: ``pkg.module:attribute`` (a bot's process is ``-m spacewar.sandbox.bothost``, a cluster
#: worker's warm-up ``spacewar.arena.jobs:warm_up_game``, a compile task ``module:function``)
MODULE_STRING = re.compile(r"^(spacewar|engine|validation)(\.[A-Za-z_]\w*)+(:[A-Za-z_]\w*)?$")


def module_strings(root=ROOT):
    """Every string constant of ``spacewar/``, ``validation/``, ``engine/`` and the top-level
    conftest that is a module string, with where it is."""
    found = []
    paths = [os.path.join(ROOT, "conftest.py")]
    for package in ("spacewar", "validation", "engine"):
        for folder, _, files in os.walk(os.path.join(root, package)):
            paths += [os.path.join(folder, f) for f in files if f.endswith(".py")]
    for path in paths:
        with open(path, encoding="utf-8") as f:
            tree = ast.parse(f.read())
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) \
                    and MODULE_STRING.match(node.value):
                found.append((node.value, f"{os.path.relpath(path, root)}:{node.lineno}"))
    return found


def resolves(text):
    """Whether ``text`` (``a.b.c`` or ``a.b:c``) names a module, or a name in one."""
    dotted = text.replace(":", ".")
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            target = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        try:
            for name in parts[cut:]:
                target = getattr(target, name)
        except AttributeError:
            return False
        return True
    return False


def test_module_strings_name_what_is_there():
    # names given as strings are no imports the walk sees: each must resolve where the code
    # now lives (found in the code, so a string left behind by a move fails here)
    strings = module_strings()
    wanted = {"spacewar.sandbox.bothost", "spacewar.arena.jobs:warm_up_game",
              "spacewar.sandbox.probe:Probe"}
    assert wanted <= {text for text, _ in strings}
    assert [(text, where) for text, where in strings if not resolves(text)] == []


def test_a_module_string_left_behind_is_found():
    assert resolves("spacewar.arena.jobs:warm_up_game") and resolves("spacewar.bots.chaser")
    assert not resolves("spacewar.jobs_moved:warm_up_game")
    assert not resolves("spacewar.arena.jobs:gone")


# -- the check itself, on a package made to break it ----------------------------------------

BROKEN = {
    "__init__.py": "",
    "low.py": """
        def helper():
            from .high import top  # upward, hidden in a function
            return top()

        def _secret():
            return 1
        """,
    "high.py": """
        from . import low as low_module
        from .low import _secret  # a private name of another module

        def top():
            return _secret()

        def peek():
            return low_module._secret()  # the same, through the module's name
        """,
    "ring_a.py": "from . import ring_b\n",
    "ring_b.py": "from . import ring_a\n",
}


@pytest.fixture
def broken(tmp_path):
    package = tmp_path / "broken"
    package.mkdir()
    for name, text in BROKEN.items():
        (package / name).write_text(textwrap.dedent(text))
    (tmp_path / "pyproject.toml").write_text(textwrap.dedent("""
        [tool.importlinter]
        root_packages = ["broken"]

        [[tool.importlinter.contracts]]
        name = "broken: high above low"
        type = "layers"
        layers = ["broken.high", "broken.low", "broken.ring_a : broken.ring_b"]
        """))
    return tmp_path


def test_the_walk_reports_an_upward_import_a_cycle_and_a_private_name(broken):
    layers = declared_layers(broken / "pyproject.toml", "broken")
    assert layers == {"broken.high": 2, "broken.low": 1, "broken.ring_a": 0, "broken.ring_b": 0}
    problems = layer_violations(str(broken), "broken", layers)
    (up,) = problems["upward"]
    assert (up.source, up.target, up.names, up.local) == ("broken.low", "broken.high", ("top",),
                                                          True)
    assert problems["cycles"] == [["broken.high", "broken.low"], ["broken.ring_a", "broken.ring_b"]]
    (private,) = problems["private"]
    assert (private.source, private.target, private.names) == ("broken.high", "broken.low",
                                                               ("_secret",))
    assert problems["private_attributes"] == [("broken.high", "broken.low", "_secret", 9)]
    assert problems["unplaced"] == []


def test_import_linter_reports_the_upward_import_too(broken):
    out = subprocess.run([sys.executable, "-c", "from importlinter.cli import lint_imports; "
                          "raise SystemExit(lint_imports())"], cwd=broken, capture_output=True,
                         text=True, env={**os.environ, "PYTHONPATH": str(broken)})
    assert out.returncode != 0
    assert "broken.low -> broken.high" in out.stdout, out.stdout


#: the documented paths that moved, and where their code lives now (docs/game.md, "Layout")
KEPT_PATHS = {
    "spacewar.match": ["spacewar.arena.match"], "spacewar.envs": ["spacewar.learn.envs"],
    "spacewar.learning": ["spacewar.learn.batch"], "spacewar.train": ["spacewar.learn.train"],
    "spacewar.evaluate": ["spacewar.learn.evaluate"], "spacewar.policy": ["spacewar.bots.policy"],
    "spacewar.timeline": ["spacewar.replay.timeline"],
    "spacewar.viewer": ["spacewar.view.window", "spacewar.view.replay_view"],
    "spacewar.play": ["spacewar.view.live"],
    "spacewar.render": ["spacewar.view.look", "spacewar.view.scene", "spacewar.view.paint_pil",
                        "spacewar.view.gif"],
    "spacewar.look": ["spacewar.view.look"], "spacewar.scene": ["spacewar.view.scene"],
    "spacewar.paint_pil": ["spacewar.view.paint_pil"], "spacewar.gif": ["spacewar.view.gif"],
    "spacewar.seats": ["spacewar.arena.seats", "spacewar.sandbox.limits",
                       "spacewar.sandbox.process"],
    "spacewar.tournament": ["spacewar.arena.tournament"], "spacewar.jobs": ["spacewar.arena.jobs"],
    "spacewar.batch_match": ["spacewar.arena.batch_match"],
    "spacewar.batch_bots": ["spacewar.bots.batch"],
    "spacewar.compiled_bots": ["spacewar.game.compiled_bots"],
    "spacewar.features": ["spacewar.game.features"],
}


@pytest.mark.parametrize("old", sorted(KEPT_PATHS))
def test_a_kept_path_gives_the_very_objects_of_its_new_home(old):
    kept = importlib.import_module(old)
    for home in map(importlib.import_module, KEPT_PATHS[old]):
        names = getattr(home, "__all__", [n for n in vars(home) if not n.startswith("_")])
        for name in names:
            if old == "spacewar.seats" and name not in ("open_seat", "bot_name", "InlineSeat",
                                                        "Limits", "TimeBank", "ProcessSeat",
                                                        "BatchProcessSeat"):
                continue
            assert getattr(kept, name) is getattr(home, name), (old, name)
    with pytest.raises(AttributeError):
        getattr(kept, "no_such_name")
    # a kept path holds no code of its own: imports, its docstring, ``__all__`` and the
    # forwarding ``__getattr__`` only
    tree = ast.parse(open(kept.__file__, encoding="utf-8").read())
    assert all(isinstance(node, (ast.Import, ast.ImportFrom, ast.Expr, ast.Assign))
               for node in tree.body), old


def test_importing_the_kept_envs_path_registers_the_environment():
    code = "import gymnasium, spacewar.envs; print('Spacewar-v0' in gymnasium.registry)"
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "True"
