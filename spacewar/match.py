"""``spacewar.match``, kept: one match between two bots (``play_match``), now
``spacewar.arena.match``; re-exports only."""
from spacewar.arena.match import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.arena.match")
