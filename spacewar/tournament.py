"""``spacewar.tournament``, kept: tournaments, now ``spacewar.arena.tournament``; re-exports only."""
from spacewar.arena.tournament import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.arena.tournament")
