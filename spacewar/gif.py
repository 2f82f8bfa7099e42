"""``spacewar.gif``, a documented path kept: a replay to a GIF. The code lives in
``spacewar.view.gif``; this module only re-exports it (``docs/game.md``, "Layout"), and nothing
inside ``spacewar`` imports it."""
from spacewar.view import gif as home
from spacewar.view.gif import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.view.gif``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.gif' has no attribute {name!r}")
    return getattr(home, name)
