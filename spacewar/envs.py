"""``spacewar.envs``, kept: the Gymnasium and PettingZoo environments; importing it registers
``Spacewar-v0``, now ``spacewar.learn.envs``; re-exports only."""
from spacewar.learn.envs import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.learn.envs")
