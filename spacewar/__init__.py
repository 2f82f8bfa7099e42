"""spacewar: Spacewar! (1962) on the engine, for bots: matches, tournaments, replays.

``Game`` (the compiled game) is imported on first use, so a bot's process, which needs only
the protocol, starts without loading compiled code.
"""
from .protocol import Action, Observation, Ship, Torpedo, NOOP
from .rules import Rules

__all__ = ["Action", "Observation", "Ship", "Torpedo", "NOOP", "Rules", "Game"]


def __getattr__(name):
    if name == "Game":
        from .game import Game

        return Game
    raise AttributeError(f"module 'spacewar' has no attribute {name!r}")
