"""``spacewar.features``, kept: the learning observation, now ``spacewar.game.features``; re-
exports only."""
from spacewar.game.features import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.game.features")
