"""spacewar: Spacewar! (1962) on the engine, for bots: matches, tournaments, replays.

``Game`` (the compiled game), ``play_match`` (one match between two bots, see
``spacewar.arena.match``) and ``check_bot`` (a bot author's conformance check, see
``spacewar.author.check``) and ``Player`` (a replay's player page, in a notebook or saved:
``spacewar.view.player_page``) are imported on first use, so a bot's process, which needs only the
protocol, starts without loading compiled code.
"""
from spacewar.protocol import Action, Observation, Ship, Torpedo, NOOP
from spacewar.rules import Rules

__all__ = ["Action", "Observation", "Ship", "Torpedo", "NOOP", "Rules", "Game", "play_match",
           "check_bot", "CheckReport", "Player"]

#: name -> (module, attribute) of the names loaded on first use
_LAZY = {
    "Game": ("spacewar.game.game", "Game"),
    "play_match": ("spacewar.arena.match", "play_match"),
    "check_bot": ("spacewar.author.check", "check_bot"),
    "CheckReport": ("spacewar.author.check", "CheckReport"),
    "Player": ("spacewar.view.player_page", "Player"),
}


def __getattr__(name):
    if name in _LAZY:
        import importlib

        module, attribute = _LAZY[name]
        return getattr(importlib.import_module(module), attribute)
    raise AttributeError(f"module 'spacewar' has no attribute {name!r}")
