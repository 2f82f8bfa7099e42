"""How a documented path that moved keeps working: its module star-imports the new home and
sets ``__getattr__ = forward(__name__, home, ...)``, which hands out every other public name of
the homes (their constants and helpers outside ``__all__``). Nothing below this layer imports a
kept path (``docs/game.md``, "Layout", lists them)."""
import importlib


def forward(old, *homes):
    """A module ``__getattr__`` (PEP 562) for the kept path ``old``: a public name of the first
    of ``homes`` (dotted module names) that has it; anything else is an AttributeError."""
    modules = [importlib.import_module(home) for home in homes]

    def __getattr__(name):
        if not name.startswith("_"):
            for module in modules:
                if hasattr(module, name):
                    return getattr(module, name)
        raise AttributeError(f"module {old!r} has no attribute {name!r}")

    return __getattr__
