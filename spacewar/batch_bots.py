"""``spacewar.batch_bots``, a documented path kept: the ``act_batch`` protocol. The code lives in
``spacewar.bots.batch``; this module only re-exports it (``docs/game.md``, "Layout"), and
nothing inside ``spacewar`` imports it."""
from spacewar.bots import batch as home
from spacewar.bots.batch import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.bots.batch``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.batch_bots' has no attribute {name!r}")
    return getattr(home, name)
