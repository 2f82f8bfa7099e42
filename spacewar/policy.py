"""The trained-policy file and the bots that play it, at their documented path: the code lives
in ``spacewar.bots.policy`` (the ``.npz`` format, its safe loading, ``Policy``, ``PolicyBot``,
``PolicyBatch``) and ``spacewar.learn.evaluate`` (``evaluate``); this module only re-exports them.
Nothing inside ``spacewar`` imports it."""
from spacewar.bots import policy as home
from spacewar.bots.policy import *  # noqa: F401,F403
from spacewar.kept_paths import forward
from spacewar.learn.evaluate import evaluate  # noqa: F401

__all__ = list(home.__all__) + ["evaluate"]

__getattr__ = forward(__name__, "spacewar.bots.policy")
