"""spacewar: Spacewar! (1962) on the engine, for bots: matches, tournaments, replays."""
from .protocol import Action, Observation, Ship, Torpedo, NOOP
from .rules import Rules
from .game import Game

__all__ = ["Action", "Observation", "Ship", "Torpedo", "NOOP", "Rules", "Game"]
