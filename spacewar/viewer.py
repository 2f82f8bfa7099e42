"""``spacewar.viewer``, a documented path kept: the pygame window and the replay viewer. The code
lives in ``spacewar.view.window``; this module only re-exports it (``docs/game.md``, "Layout"),
and nothing inside ``spacewar`` imports it."""
from spacewar.view import window as home
from spacewar.view.window import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.view.window``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.viewer' has no attribute {name!r}")
    return getattr(home, name)
