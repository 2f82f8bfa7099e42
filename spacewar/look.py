"""``spacewar.look``, a documented path kept: colours, shapes, durations. The code lives in
``spacewar.view.look``; this module only re-exports it (``docs/game.md``, "Layout"), and nothing
inside ``spacewar`` imports it."""
from spacewar.view import look as home
from spacewar.view.look import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.view.look``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.look' has no attribute {name!r}")
    return getattr(home, name)
