"""``spacewar.compiled_bots``, kept: the built-in bots as compiled functions, now
``spacewar.game.compiled_bots``; re-exports only."""
from spacewar.game.compiled_bots import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.game.compiled_bots")
