"""``spacewar.play``, kept: ``play`` and ``watch``, now ``spacewar.view.live``; re-exports only."""
from spacewar.view.live import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.view.live")
