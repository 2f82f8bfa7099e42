"""``spacewar.learning``, a documented path kept: the compiled learning batch and the observation's
names. The code lives in ``spacewar.learn.batch``; this module only re-exports it
(``docs/game.md``, "Layout"), and nothing inside ``spacewar`` imports it."""
from spacewar.learn import batch as home
from spacewar.learn.batch import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.learn.batch``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.learning' has no attribute {name!r}")
    return getattr(home, name)
