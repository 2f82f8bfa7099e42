"""The bot protocol: what a bot sees (Observation) and what it answers (Action).

A bot is any object with ``act(self, obs) -> Action``. It may also define ``reset(self)``,
called at the start of every match. Built-in bots take an optional ``seed`` argument.
"""
from dataclasses import dataclass, field

import numpy as np

from . import core


@dataclass(frozen=True)
class Action:
    """One frame of controls: ``turn`` -1 (clockwise), 0 or +1 (anticlockwise), and buttons.

    ``flip`` reverses the ship's charge in the electric mode (ignored elsewhere).
    """

    turn: int = 0
    thrust: bool = False
    fire: bool = False
    hyperspace: bool = False
    flip: bool = False

    def __post_init__(self):
        if isinstance(self.turn, bool) or self.turn not in (-1, 0, 1):
            raise ValueError(f"turn must be -1, 0 or 1, got {self.turn!r}")
        for name in ("thrust", "fire", "hyperspace", "flip"):
            value = getattr(self, name)
            if not isinstance(value, (bool, np.bool_)):
                raise ValueError(f"{name} must be True or False, got {value!r}")

    def code(self):
        """The compact integer the compiled game takes (0 .. N_ACTIONS - 1)."""
        return ((self.turn + 1) + 3 * bool(self.thrust) + 6 * bool(self.fire)
                + 12 * bool(self.hyperspace) + 24 * bool(self.flip))

    @classmethod
    def from_code(cls, code):
        code = int(code)
        if not 0 <= code < core.N_ACTIONS:
            raise ValueError(f"action code must be in [0, {core.N_ACTIONS}), got {code!r}")
        return cls(turn=code % 3 - 1, thrust=bool((code // 3) % 2), fire=bool((code // 6) % 2),
                   hyperspace=bool((code // 12) % 2), flip=bool((code // 24) % 2))


NOOP = Action()


@dataclass(frozen=True)
class Ship:
    """A ship as a bot sees it. While a ship is in hyperspace its position and velocity are
    those it had when it vanished (it is invisible and cannot be hit)."""

    pos: np.ndarray
    vel: np.ndarray
    heading: float
    angular_velocity: float
    fuel: float
    torpedoes: int
    hyperspace: int  # jumps left
    alive: bool
    in_hyperspace: bool
    reload: int  # frames until the next torpedo may be fired
    hyperspace_recharge: int
    charge: float
    flip_cooldown: int  # frames until the polarity may be flipped again (electric mode)


@dataclass(frozen=True)
class Torpedo:
    pos: np.ndarray
    vel: np.ndarray
    mine: bool
    ttl: int  # frames left before it bursts
    charge: float


@dataclass(frozen=True)
class Observation:
    """Everything a bot may know at a frame, from its own side (``me`` and ``enemy``)."""

    me: Ship
    enemy: Ship
    torpedoes: tuple
    star_pos: np.ndarray
    star_mu: float  # 0 when there is no star
    star_capture: float
    frame: int  # frames since the match began
    round_frame: int
    round: int  # rounds already played
    score: tuple  # (mine, enemy's)
    seat: int  # 0 or 1
    rules: object = field(repr=False)
    _vector: np.ndarray = field(repr=False, default=None)

    def vector(self):
        """A flat float64 vector of fixed length (see ``VECTOR_LAYOUT``), for learning code."""
        return self._vector.copy()


#: names of the entries of ``Observation.vector()``, in order
SHIP_FIELDS = ("x", "y", "vx", "vy", "cos_heading", "sin_heading", "angular_velocity",
               "fuel_fraction", "torpedo_fraction", "hyperspace_fraction", "alive",
               "in_hyperspace", "reload_fraction", "charge_sign", "flip_cooldown_fraction")
TORPEDO_FIELDS = ("present", "x", "y", "vx", "vy", "mine", "ttl_fraction")


def vector_layout(rules):
    """Names of the observation vector's entries for these rules."""
    names = [f"me.{f}" for f in SHIP_FIELDS] + [f"enemy.{f}" for f in SHIP_FIELDS]
    names += ["star_mu_scaled", "round_time_fraction"]
    for k in range(2 * rules.torpedoes):
        names += [f"torpedo{k}.{f}" for f in TORPEDO_FIELDS]
    return names
