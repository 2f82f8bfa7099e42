"""``spacewar.batch_match``, a documented path kept: many matches as the rows of one game
(``play_matches``). The code lives in ``spacewar.arena.batch_match``; this module only re-
exports it (``docs/game.md``, "Layout"), and nothing inside ``spacewar`` imports it."""
from spacewar.arena import batch_match as home
from spacewar.arena.batch_match import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.arena.batch_match``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.batch_match' has no attribute {name!r}")
    return getattr(home, name)
