"""``spacewar.play``, a documented path kept: ``play`` and ``watch``. The code lives in
``spacewar.view.live``; this module only re-exports it (``docs/game.md``, "Layout"), and nothing
inside ``spacewar`` imports it."""
from spacewar.view import live as home
from spacewar.view.live import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.view.live``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.play' has no attribute {name!r}")
    return getattr(home, name)
