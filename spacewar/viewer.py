"""``spacewar.viewer``, a documented path kept: the pygame window and the replay viewer. The code
lives in ``spacewar.view.window`` (the window, its pacing, its loop) and
``spacewar.view.replay_view`` (``view_replay``, ``ReplayView``); this module only re-exports
them (``docs/game.md``, "Layout"), and nothing inside ``spacewar`` imports it."""
from spacewar.view import replay_view, window
from spacewar.view.replay_view import *  # noqa: F401,F403
from spacewar.view.window import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of the two modules."""
    for home in (window, replay_view):
        if not name.startswith("_") and hasattr(home, name):
            return getattr(home, name)
    raise AttributeError(f"module 'spacewar.viewer' has no attribute {name!r}")
