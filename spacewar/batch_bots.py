"""``spacewar.batch_bots``, kept: the ``act_batch`` protocol, now ``spacewar.bots.batch``; re-
exports only."""
from spacewar.bots.batch import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.bots.batch")
