"""``spacewar.tournament``, a documented path kept: tournaments. The code lives in
``spacewar.arena.tournament``; this module only re-exports it (``docs/game.md``, "Layout"), and
nothing inside ``spacewar`` imports it."""
from spacewar.arena import tournament as home
from spacewar.arena.tournament import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.arena.tournament``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.tournament' has no attribute {name!r}")
    return getattr(home, name)
