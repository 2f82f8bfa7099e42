"""``spacewar.viewer``, kept: the pygame window (now ``spacewar.view.window``) and the replay
viewer (now ``spacewar.view.replay_view``); re-exports only."""
from spacewar.view.replay_view import *  # noqa: F401,F403
from spacewar.view.window import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.view.window", "spacewar.view.replay_view")
