"""``spacewar.look``, kept: colours, shapes, durations, now ``spacewar.view.look``; re-exports
only."""
from spacewar.view.look import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.view.look")
