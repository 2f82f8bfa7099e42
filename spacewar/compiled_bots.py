"""``spacewar.compiled_bots``, a documented path kept: the built-in bots as compiled functions. The
code lives in ``spacewar.game.compiled_bots``; this module only re-exports it (``docs/game.md``,
"Layout"), and nothing inside ``spacewar`` imports it."""
from spacewar.game import compiled_bots as home
from spacewar.game.compiled_bots import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.game.compiled_bots``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.compiled_bots' has no attribute {name!r}")
    return getattr(home, name)
