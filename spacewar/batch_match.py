"""``spacewar.batch_match``, kept: many matches as the rows of one game (``play_matches``), now
``spacewar.arena.batch_match``; re-exports only."""
from spacewar.arena.batch_match import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.arena.batch_match")
