"""``spacewar.evaluate``, a documented path kept: a policy file's evaluation. The code lives in
``spacewar.learn.evaluate``; this module only re-exports it (``docs/game.md``, "Layout"), and
nothing inside ``spacewar`` imports it."""
from spacewar.learn import evaluate as home
from spacewar.learn.evaluate import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.learn.evaluate``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.evaluate' has no attribute {name!r}")
    return getattr(home, name)
