"""``spacewar.features``, a documented path kept: the learning observation. The code lives in
``spacewar.game.features``; this module only re-exports it (``docs/game.md``, "Layout"), and
nothing inside ``spacewar`` imports it."""
from spacewar.game import features as home
from spacewar.game.features import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.game.features``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.features' has no attribute {name!r}")
    return getattr(home, name)
