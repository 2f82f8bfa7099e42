"""``spacewar.timeline``, kept: ``ReplayTimeline``, now ``spacewar.replay.timeline``; re-exports
only."""
from spacewar.replay.timeline import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.replay.timeline")
