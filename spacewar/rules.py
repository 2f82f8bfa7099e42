"""The rules of Spacewar! (1962), in float units, with the original's ratios kept.

Units: the arena is a torus of side 1 (x and y in [-0.5, 0.5)), one time unit is one frame.
The PDP-1 screen was 1024 points across, so one point is 1/1024 of the arena. Each frame the
ships move as in the original: velocity += thrust + gravity, then position += velocity, which
is the engine's ``symplectic_euler`` with dt = 1 frame.

Frame counts come from the original program: Spacewar! version 3.1 for the PDP-1 (Steve
Russell et al., MIT, listing dated 24 September 1962), as run and explained by Norbert
Landsteiner's emulation and write-up at https://www.masswerk.at/spacewar/ (reload 16, torpedo
life 96, 32 torpedoes, 8 hyperspace jumps of 32 frames with 128 to recharge, break-up risk k/8
on jump k, 192 frames after a round, about 100 frames for a full turn, about 1000 frames of
fuel, a diamond hit test of 12 and 18 points). Accelerations and speeds are chosen in the same
proportions as the original's play: the heavy star out-pulls full thrust only close in, a
torpedo crosses a third of the arena in its lifetime.

Sense-switch options: ``star`` heavy / light (1/4) / none, ``star_kills`` (else the ship is
moved to the corner at rest), ``angular_momentum``, ``single_shot``. Modes beyond 1962:
``newtonian`` (torpedoes feel the star, ships attract each other and the torpedoes, N-body
through the engine) and ``electric`` (charged ships and torpedoes, Coulomb forces, polarity flip).
"""
import dataclasses
import math
from dataclasses import dataclass

import numpy as np

POINT = 1.0 / 1024.0
MODES = ("classic", "newtonian", "electric")
STARS = ("heavy", "light", "none")


#: the longest span a frame-count field may give: 2^30 frames (about 5 hours at 60 frames
#: a second). A match's frame counter then stays under (rounds + extra rounds) x (round
#: frames + delay + 1) < 2^31 x 2^31 = 2^62 for any replay's rounds (< 2^31): int64 holds it,
#: and every count is exact in the float64 rules vector the compiled game reads.
FRAMES_MAX = 1 << 30

#: every number's inclusive range, chosen so that each compiled expression stays finite and
#: in range: counts are exact in float64 and their products fit in int64; a frame's speed
#: and thrust changes are at most an arena side (beyond it the torus wraps them to nothing
#: new); masses and softening radii are bounded away from 0 so that forces divided by them
#: stay finite (at most about 1e21 a frame, and speeds summed over 2^62 frames far below
#: 1e308); turning at most a quarter turn a frame keeps the heading's one-step wrap (and the
#: four-times-faster spin limit) within (-pi, pi]; the star's capture radius is at most
#: 1/16, so that the re-entry point drawn outside 6 radii (<= 0.375) is found in a few
#: draws instead of never.
RANGES = {
    "star_mu": (0.0, 1.0),
    "star_capture": (1e-6, 1.0 / 16.0),
    "turn_rate": (0.0, math.pi / 4.0),
    "angular_accel": (0.0, math.pi / 4.0),
    "thrust": (0.0, 1.0),
    "fuel": (0.0, float(FRAMES_MAX)),
    "fuel_burn_min": (0.0, float(FRAMES_MAX)),
    "fuel_burn_max": (0.0, float(FRAMES_MAX)),
    "ship_mass": (1e-6, 1e6),
    "start_distance": (1e-6, 0.5),
    "torpedoes": (1, 64),
    "reload": (0, FRAMES_MAX),
    "torpedo_life": (0, FRAMES_MAX),
    "muzzle_speed": (0.0, 1.0),
    "launch_offset": (0.0, 1.0),
    "torpedo_mass": (1e-6, 1e6),
    "hyperspace_jumps": (0, FRAMES_MAX),
    "hyperspace_frames": (0, FRAMES_MAX),
    "hyperspace_recharge": (0, FRAMES_MAX),
    "hyperspace_risk": (0.0, 1.0),
    "reentry_speed": (0.0, 1.0),
    "hit_box": (1e-6, 0.5),
    "hit_diamond": (0.0, 1.0),
    "post_round_delay": (0, FRAMES_MAX),
    "max_round_frames": (0, FRAMES_MAX),
    "max_extra_rounds": (0, 1 << 20),
    "ship_gravity": (0.0, 1.0),
    "coulomb_k": (0.0, 1e3),
    "charge": (0.0, 1.0),
    "flip_cooldown": (0, FRAMES_MAX),
}


def _shown(value, limit=40):
    """``repr(value)``, cut short (a forged file's int may have thousands of digits)."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 128:
        return f"an int of {value.bit_length()} bits"
    text = repr(value)
    return text if len(text) <= limit else text[:limit] + "..."


def _check_number(name, value, kind):
    """Raise ValueError naming the field, the value and its range unless ``value`` is of
    ``kind`` ("float": an int or a float; "int": an int, not a bool) and within
    ``RANGES[name]``. Compared as given: a huge int is never converted to a float."""
    low, high = RANGES[name]
    if kind == "int":
        ok = not isinstance(value, bool) and isinstance(value, (int, np.integer))
        what = "an int"
    else:
        ok = not isinstance(value, bool) and isinstance(value, (int, float))
        what = "a number"
    if not ok:
        raise ValueError(f"{name} must be {what} in [{low!r}, {high!r}], got {_shown(value)}")
    if not low <= value <= high:  # False for NaN too
        raise ValueError(f"{name} must be in [{low!r}, {high!r}], got {_shown(value)}")


def count_at_least(name, value, minimum):
    """``value`` as an int if it is one (not a bool) of at least ``minimum``, else a
    ValueError naming the field and the value (seeds, rounds, frame caps, env counts)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} must be an int >= {minimum}, got {value!r}")
    return int(value)


@dataclass(frozen=True)
class Rules:
    """Every number the game uses. Frozen: make variants with ``rules.replace(...)``.

    Each number must lie in its range (``RANGES``, inclusive; why each bound: there), else
    ValueError names the field, the value and the range; rules read from replays, policy
    files and leagues come through ``from_dict`` and so through the same check:

    ==========================================================  =========================
    field                                                       range
    ==========================================================  =========================
    star_mu, thrust, muzzle_speed, reentry_speed, ship_gravity  [0, 1]
    hyperspace_risk, launch_offset, hit_diamond, charge         [0, 1]
    turn_rate, angular_accel (rad per frame, per frame^2)       [0, pi/4]
    star_capture                                                [1e-6, 1/16]
    hit_box, start_distance                                     [1e-6, 0.5]
    ship_mass, torpedo_mass                                     [1e-6, 1e6]
    coulomb_k                                                   [0, 1e3]
    fuel, fuel_burn_min, fuel_burn_max (<= fuel_burn_max)       [0, 2^30]
    reload, torpedo_life, hyperspace_jumps, hyperspace_frames   [0, 2^30] (ints)
    hyperspace_recharge, post_round_delay, max_round_frames     [0, 2^30] (ints)
    flip_cooldown                                               [0, 2^30] (int)
    max_extra_rounds                                            [0, 2^20] (int)
    torpedoes                                                   [1, 64] (int)
    ==========================================================  =========================
    """

    mode: str = "classic"
    # sense switches
    star: str = "heavy"
    star_kills: bool = True
    angular_momentum: bool = False
    single_shot: bool = False
    # the star
    # the heavy star's G M in arena^3 / frame^2, whatever ``star`` says: the one in play is
    # ``effective_star_mu`` (a quarter of it for a light star, 0 without one), which the
    # observations, ``in_play()`` and the repr show
    star_mu: float = 2.5e-7
    star_capture: float = 8 * POINT
    # ships
    turn_rate: float = 2.0 * math.pi / 100.0  # rad per frame: a full turn in 100 frames
    angular_accel: float = 2.0 * math.pi / 1600.0  # rad per frame^2 with angular momentum
    thrust: float = 2.0e-5  # arena / frame^2
    fuel: float = 1000.0  # frames of thrust on average
    fuel_burn_min: float = 0.5  # each thrusting frame burns uniform(min, max) frames of fuel
    fuel_burn_max: float = 1.5
    ship_mass: float = 1.0
    start_distance: float = 0.3  # from the star along the diagonal
    # torpedoes
    torpedoes: int = 32
    reload: int = 16
    torpedo_life: int = 96
    muzzle_speed: float = 4.0e-3  # arena / frame, added to the ship's velocity
    launch_offset: float = 20 * POINT  # ahead of the ship's nose, clear of its hit box
    torpedo_mass: float = 0.25
    # hyperspace
    hyperspace_jumps: int = 8
    hyperspace_frames: int = 32
    hyperspace_recharge: int = 128
    hyperspace_risk: float = 1.0 / 8.0  # break-up chance per jump already made (k/8 on jump k)
    reentry_speed: float = 2.0e-3  # re-entry speed is uniform in [0, reentry_speed]
    # collisions: diamond proximity test, as the original
    hit_box: float = 12 * POINT
    hit_diamond: float = 18 * POINT
    # rounds
    post_round_delay: int = 192
    max_round_frames: int = 6000
    max_extra_rounds: int = 5
    # newtonian mode
    ship_gravity: float = 2.0e-8  # G for ship-ship and ship-torpedo attraction (ship mass 1)
    # electric mode
    coulomb_k: float = 1.0
    charge: float = 4.0e-4
    flip_cooldown: int = 64

    def __post_init__(self):
        if self.mode not in MODES:
            raise ValueError(f"mode must be one of {', '.join(MODES)}, got {self.mode!r}")
        if self.star not in STARS:
            raise ValueError(f"star must be one of {', '.join(STARS)}, got {self.star!r}")
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.type in ("float", float):
                _check_number(f.name, value, "float")
            elif f.type in ("int", int):
                _check_number(f.name, value, "int")
            elif f.type in ("bool", bool) and not isinstance(value, bool):
                raise ValueError(f"{f.name} must be True or False, got {_shown(value)}")
        if self.fuel_burn_max < self.fuel_burn_min:
            raise ValueError(f"fuel_burn_max ({self.fuel_burn_max!r}) must be >= fuel_burn_min "
                             f"({self.fuel_burn_min!r})")

    @property
    def effective_star_mu(self):
        """The star's G M with the heavy / light / none switch applied."""
        return {"heavy": self.star_mu, "light": 0.25 * self.star_mu, "none": 0.0}[self.star]

    @property
    def torpedoes_feel_star(self):
        return self.mode == "newtonian"

    def in_play(self):
        """Every number as the game uses it: the fields, with ``star_mu`` the G M of the star
        in play (``effective_star_mu``: 0 with ``star="none"``) and whether torpedoes feel it.
        ``to_dict`` keeps the stored fields (replays and ``from_dict`` round-trip them)."""
        values = self.to_dict()
        values["star_mu"] = self.effective_star_mu
        values["torpedoes_feel_star"] = self.torpedoes_feel_star and self.effective_star_mu > 0
        return values

    def __repr__(self):
        """The dataclass repr, with the star's G M in play beside the stored heavy-star value
        when they differ (``Rules(star="none")`` plays without gravity from the star)."""
        parts = []
        for f in dataclasses.fields(self):
            text = f"{f.name}={getattr(self, f.name)!r}"
            if f.name == "star_mu" and self.effective_star_mu != self.star_mu:
                text += f" [heavy star's; in play: {self.effective_star_mu!r}]"
            parts.append(text)
        return f"Rules({', '.join(parts)})"

    def replace(self, **changes):
        return dataclasses.replace(self, **changes)

    def to_dict(self):
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data):
        """Rules from a dict (e.g. a replay file); unknown keys are an error."""
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - names)
        if unknown:
            raise ValueError(f"unknown rules field(s): {', '.join(unknown)}")
        return cls(**data)


OPTIONS_HELP = {
    "mode": "classic (1962), newtonian (N-body) or electric (Coulomb)",
    "star": "heavy, light (1/4) or none",
    "star_kills": "touching the star destroys the ship (else: moved to the corner at rest)",
    "angular_momentum": "turn keys change the angular velocity (sense switch 1)",
    "single_shot": "one torpedo per press of fire (sense switch 3)",
}
