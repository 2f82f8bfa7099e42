"""``spacewar.train``, a documented path kept: PPO training. The code lives in
``spacewar.learn.train``; this module only re-exports it (``docs/game.md``, "Layout"), and
nothing inside ``spacewar`` imports it."""
from spacewar.learn import train as home
from spacewar.learn.train import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.learn.train``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.train' has no attribute {name!r}")
    return getattr(home, name)
