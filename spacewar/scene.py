"""``spacewar.scene``, a documented path kept: a frame as drawing primitives. The code lives in
``spacewar.view.scene``; this module only re-exports it (``docs/game.md``, "Layout"), and
nothing inside ``spacewar`` imports it."""
from spacewar.view import scene as home
from spacewar.view.scene import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.view.scene``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.scene' has no attribute {name!r}")
    return getattr(home, name)
