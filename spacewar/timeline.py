"""``spacewar.timeline``, a documented path kept: ``ReplayTimeline``. The code lives in
``spacewar.replay.timeline``; this module only re-exports it (``docs/game.md``, "Layout"), and
nothing inside ``spacewar`` imports it."""
from spacewar.replay import timeline as home
from spacewar.replay.timeline import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.replay.timeline``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.timeline' has no attribute {name!r}")
    return getattr(home, name)
