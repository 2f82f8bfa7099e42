"""``spacewar.match``, a documented path kept: one match between two bots (``play_match``). The
code lives in ``spacewar.arena.match``; this module only re-exports it (``docs/game.md``,
"Layout"), and nothing inside ``spacewar`` imports it."""
from spacewar.arena import match as home
from spacewar.arena.match import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.arena.match``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.match' has no attribute {name!r}")
    return getattr(home, name)
