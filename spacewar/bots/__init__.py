"""Bots: built-in ones by name, others by ``package.module:Class`` or ``path/to/file.py:Class``;
a trained policy by its ``.npz`` file (``spacewar.policy.PolicyBot``).

A bot is any class with ``act(self, obs) -> spacewar.Action``; it may define ``reset(self)``
(called when a match starts) and accept a ``seed`` keyword (built-in bots do).

How a specification is looked up, in this order (``locate``):

1. a built-in name (``available()``): ``idle``, ``random``, ``chaser``, ``sniper``, ``dodger``;
2. a name ending in ``.npz``: a trained policy file;
3. ``where:Class`` with ``where`` ending in ``.py`` or holding a path separator: that file
   (relative to the current directory);
4. ``module:Class`` or ``package.module:Class``: the top-level module or package is looked
   for first in the current directory (as ``python -m`` would find it), then on this
   process's ``sys.path`` (installed packages, ``PYTHONPATH``); the bot's own process imports
   it from exactly the directory found here. A module in the current directory may not take
   the name of a standard-library module (it could not be told apart from it).

The helpers of ``spacewar.bots.geometry`` that a bot needs first are also reachable from here
(``from spacewar.bots import torus_delta, angle_diff``), loaded on first use: the engine they
import is not loaded by importing this package. The loader itself is ``spacewar.bots.loader``;
this package re-exports its names.
"""
from spacewar.bots.loader import (BUILTIN, BotLoadError, available, is_policy_file, is_builtin,
                                  split_spec, is_file_spec, locate, import_top_level,
                                  declares_act_batch, bots_in, check_one_spelling_each,
                                  bot_identity, absolute_spec, load_bot_class, make_bot,
                                  MAX_SOURCE_BYTES)

__all__ = ["BUILTIN", "BotLoadError", "available", "is_policy_file", "is_builtin", "split_spec",
           "is_file_spec", "locate", "import_top_level", "declares_act_batch", "bots_in",
           "check_one_spelling_each", "bot_identity", "absolute_spec", "load_bot_class",
           "make_bot", "MAX_SOURCE_BYTES"]

#: ``spacewar.bots.geometry`` helpers re-exported here, imported on first use
GEOMETRY_EXPORTS = ("wrap", "torus_delta", "torus_distance", "bearing", "angle_diff",
                    "turn_towards", "steer", "heading_after", "periapsis", "safest_heading")


def __getattr__(name):
    # the geometry module loads the engine (numba): only a bot that uses it pays for that
    if name in GEOMETRY_EXPORTS:
        from spacewar.bots import geometry

        return getattr(geometry, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
