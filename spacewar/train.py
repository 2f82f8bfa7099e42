"""``spacewar.train``, kept: PPO training, now ``spacewar.learn.train``; re-exports only."""
from spacewar.learn.train import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.learn.train")
