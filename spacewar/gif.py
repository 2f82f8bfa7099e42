"""``spacewar.gif``, kept: a replay to a GIF, now ``spacewar.view.gif``; re-exports only."""
from spacewar.view.gif import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.view.gif")
