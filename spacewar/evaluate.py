"""``spacewar.evaluate``, kept: a policy file's evaluation, now ``spacewar.learn.evaluate``; re-
exports only."""
from spacewar.learn.evaluate import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.learn.evaluate")
