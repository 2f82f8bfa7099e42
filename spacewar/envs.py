"""``spacewar.envs``, a documented path kept: the Gymnasium and PettingZoo environments; importing
it registers ``Spacewar-v0``. The code lives in ``spacewar.learn.envs``; this module only re-
exports it (``docs/game.md``, "Layout"), and nothing inside ``spacewar`` imports it."""
from spacewar.learn import envs as home
from spacewar.learn.envs import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.learn.envs``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.envs' has no attribute {name!r}")
    return getattr(home, name)
