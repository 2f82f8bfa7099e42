"""``spacewar.scene``, kept: a frame as drawing primitives, now ``spacewar.view.scene``; re-exports
only."""
from spacewar.view.scene import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.view.scene")
