"""``spacewar.learning``, kept: the compiled learning batch and the observation's names, now
``spacewar.learn.batch``; re-exports only."""
from spacewar.learn.batch import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.learn.batch")
