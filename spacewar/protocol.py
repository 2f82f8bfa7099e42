"""The bot protocol: what a bot sees (Observation) and what it answers (Action).

A bot is any object with ``act(self, obs) -> Action``. It may also define ``reset(self)``,
called at the start of every match. Built-in bots take an optional ``seed`` argument.

An observation also exists as a flat float64 array of fixed length (``raw_layout``): that is
what crosses from the match to a bot's own process (see ``spacewar.wire``), and
``observation_from_raw`` turns it back into the same ``Observation`` on either side, so an
isolated bot and an inline one see identical numbers. This module imports no compiled code.
"""
from dataclasses import dataclass, field

import numpy as np

from spacewar import codes


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
        return action_code(self)

    @classmethod
    def from_code(cls, code):
        code = int(code)
        if not 0 <= code < codes.N_ACTIONS:
            raise ValueError(f"action code must be in [0, {codes.N_ACTIONS}), got {code!r}")
        return cls(turn=code % 3 - 1, thrust=bool((code // 3) % 2), fire=bool((code // 6) % 2),
                   hyperspace=bool((code // 12) % 2), flip=bool((code // 24) % 2))


NOOP = Action()


def action_code(action):
    """The code of ``action``, checked field by field whatever its class says of itself.

    Raises ``ValueError`` naming the field for anything a genuine ``Action`` could not hold
    (a forged ``turn`` set with ``object.__setattr__``, a subclass overriding ``code``).
    """
    if not isinstance(action, Action):
        raise ValueError(f"not an Action: {type(action).__name__}")
    if type(action) is Action:
        # the common case, every seat every frame: Action itself has no descriptor that
        # could stand in for a field, so its fields are its instance dict's entries
        fields = action.__dict__
        try:
            turn, thrust, fire = fields["turn"], fields["thrust"], fields["fire"]
            hyperspace, flip = fields["hyperspace"], fields["flip"]
        except KeyError:  # a field deleted: read as a subclass's are
            turn, thrust, fire, hyperspace, flip = _looked_up_fields(action)
    else:
        turn, thrust, fire, hyperspace, flip = _looked_up_fields(action)
    if type(turn) not in _TURN_TYPES or turn not in (-1, 0, 1):
        raise ValueError(f"turn must be -1, 0 or 1, got {short_repr(turn)}")
    if type(thrust) not in _BOOL_TYPES:
        _not_a_bool("thrust", thrust)
    if type(fire) not in _BOOL_TYPES:
        _not_a_bool("fire", fire)
    if type(hyperspace) not in _BOOL_TYPES:
        _not_a_bool("hyperspace", hyperspace)
    if type(flip) not in _BOOL_TYPES:
        _not_a_bool("flip", flip)
    return (int(turn) + 1 + (3 if thrust else 0) + (6 if fire else 0)
            + (12 if hyperspace else 0) + (24 if flip else 0))


_BOOL_TYPES = (bool, np.bool_)
_FIELDS = ("turn", "thrust", "fire", "hyperspace", "flip")


def _looked_up_fields(action):
    """The five fields of an ``Action`` subclass (or of a forged instance) as the instance
    holds them, whatever its class says of itself."""
    get = object.__getattribute__
    return tuple(get(action, name) for name in _FIELDS)


def _not_a_bool(name, value):
    raise ValueError(f"{name} must be True or False, got {short_repr(value)}")


# exact types only: a subclass of int could answer anything to ``in`` and ``int()``
_TURN_TYPES = (int, float, np.int8, np.int16, np.int32, np.int64, np.float32, np.float64)


def short_repr(value):
    """A repr that cannot raise and is at most 80 characters."""
    try:
        text = repr(value)
    except BaseException:  # a hostile __repr__ must not escape
        text = f"<{type(value).__name__} with a failing repr>"
    if not isinstance(text, str):
        text = f"<{type(value).__name__}>"
    return text if len(text) <= 80 else text[:77] + "..."


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
    _raw: np.ndarray = field(repr=False, default=None, compare=False)
    _scales: tuple = field(repr=False, default=None, compare=False)

    def raw(self):
        """The flat raw observation this one was made from (``raw_layout``), read-only."""
        return object.__getattribute__(self, "_raw")

    def __getattr__(self, name):
        # Reached only for a field not decoded yet: ``observation_from_raw`` decodes the
        # ships, torpedoes and header from the raw numbers when one of them is first read,
        # so a frame costs the match nothing for what its bot never looks at.
        fields = object.__getattribute__(self, "__dict__")
        if name in _DECODED and name not in fields and fields.get("_raw") is not None:
            fields.update(_decode(fields["_raw"]))
            return fields[name]
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def vector(self):
        """A flat float64 vector of fixed length (see ``vector_layout``), for learning code."""
        if self._vector is None and self._raw is not None:  # made on first use only
            object.__setattr__(self, "_vector", _vector_from_raw(self._raw, self._scales))
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


# -- the observation as a flat array ------------------------------------------------------
HEADER_FIELDS = ("frame", "round_frame", "round", "score_me", "score_enemy", "seat",
                 "star_mu", "star_capture", "star_x", "star_y")
RAW_SHIP_FIELDS = ("x", "y", "vx", "vy", "heading", "angular_velocity", "fuel", "torpedoes",
                   "hyperspace", "alive", "in_hyperspace", "reload", "hyperspace_recharge",
                   "charge", "flip_cooldown")
RAW_TORPEDO_FIELDS = ("present", "x", "y", "vx", "vy", "mine", "ttl", "charge")
_NH, _NS, _NT = len(HEADER_FIELDS), len(RAW_SHIP_FIELDS), len(RAW_TORPEDO_FIELDS)


def raw_length(rules):
    """Length of the raw observation array for these rules."""
    return _NH + 2 * _NS + 2 * rules.torpedoes * _NT


def raw_layout(rules):
    """Names of the raw observation array's entries: header, me, enemy, then the torpedo
    slots (own ones first), each slot with a presence flag."""
    names = list(HEADER_FIELDS)
    names += [f"me.{f}" for f in RAW_SHIP_FIELDS] + [f"enemy.{f}" for f in RAW_SHIP_FIELDS]
    for k in range(2 * rules.torpedoes):
        names += [f"torpedo{k}.{f}" for f in RAW_TORPEDO_FIELDS]
    return names


def _made(cls, fields):
    """An instance of the frozen dataclass ``cls`` holding ``fields`` (all of them), without
    its generated ``__init__``, which sets each field through ``object.__setattr__`` and was
    most of the cost of an observation (one is made per seat per frame)."""
    obj = object.__new__(cls)
    obj.__dict__.update(fields)
    return obj


def _ship_from_raw(r):
    """A Ship from its 15 raw numbers ``r`` (a read-only array: pos and vel are views of it)."""
    x = r.tolist()
    return _made(Ship, {"pos": r[0:2], "vel": r[2:4], "heading": x[4], "angular_velocity": x[5],
                        "fuel": x[6], "torpedoes": int(x[7]), "hyperspace": int(x[8]),
                        "alive": bool(x[9]), "in_hyperspace": bool(x[10]), "reload": int(x[11]),
                        "hyperspace_recharge": int(x[12]), "charge": x[13],
                        "flip_cooldown": int(x[14])})


def _ship_vector(x, scales):
    """One ship's part of ``Observation.vector()`` from its raw numbers (a list)."""
    fuel, torpedoes, jumps, reload, flip = scales[:5]
    return [x[0], x[1], x[2], x[3], np.cos(x[4]), np.sin(x[4]), x[5], x[6] / fuel,
            x[7] / torpedoes, x[8] / jumps, x[9], x[10], x[11] / reload, float(np.sign(x[13])),
            x[14] / flip]


def observation_from_raw(raw, rules, shown_rules=None):
    """The ``Observation`` a raw array describes (arrays in it are read-only copies).
    ``rules`` decode it; ``shown_rules`` (default ``rules``) is what ``obs.rules`` holds. Its
    fields are decoded from its own copy of the raw numbers when one is first read."""
    raw = np.asarray(raw, dtype=np.float64)
    if raw.shape != (raw_length(rules),):
        raise ValueError(f"raw observation must have shape ({raw_length(rules)},), got {raw.shape}")
    return observation_of_copy(raw.copy(), rules, shown_rules)


def observation_of_copy(raw, rules, shown_rules=None):
    """``observation_from_raw`` for a caller that hands over a fresh float64 copy of the
    right shape, which the observation keeps (read-only): the match loop's, every frame."""
    raw.setflags(write=False)  # the bot's own copy: pos, vel and star_pos are views of it
    obj = object.__new__(Observation)
    obj.__dict__.update({"rules": rules if shown_rules is None else shown_rules,
                         "_vector": None, "_raw": raw, "_scales": _scales(rules)})
    return obj


#: the fields ``_decode`` makes (every field of an Observation but the rules)
_DECODED = frozenset({"me", "enemy", "torpedoes", "star_pos", "star_mu", "star_capture",
                      "frame", "round_frame", "round", "score", "seat"})


def _decode(raw):
    """The fields of the observation whose raw numbers are ``raw`` (read-only)."""
    h = raw[:_NH].tolist()
    first = _NH + 2 * _NS
    torpedoes = []
    for k in np.nonzero(raw[first::_NT])[0].tolist():  # the live slots, in slot order
        a = first + k * _NT
        x = raw[a:a + _NT].tolist()
        torpedoes.append(_made(Torpedo, {"pos": raw[a + 1:a + 3], "vel": raw[a + 3:a + 5],
                                         "mine": bool(x[5]), "ttl": int(x[6]), "charge": x[7]}))
    return {"me": _ship_from_raw(raw[_NH:_NH + _NS]),
            "enemy": _ship_from_raw(raw[_NH + _NS:first]), "torpedoes": tuple(torpedoes),
            "star_pos": raw[8:10], "star_mu": h[6], "star_capture": h[7], "frame": int(h[0]),
            "round_frame": int(h[1]), "round": int(h[2]), "score": (int(h[3]), int(h[4])),
            "seat": int(h[5])}


def _scales(rules):
    """``_scale_numbers(rules)``, kept for the last few rules objects asked about (each seat
    of a match asks with its own every frame; hashing the rules costs more than the numbers,
    so they are known by identity, the object kept alive with its numbers)."""
    kept = _SCALES.get(id(rules))
    if kept is None or kept[0] is not rules:
        if len(_SCALES) >= 16:
            _SCALES.clear()
        kept = _SCALES[id(rules)] = (rules, _scale_numbers(rules))
    return kept[1]


_SCALES = {}


def _scale_numbers(rules):
    """The numbers of the rules that scale the learning vector: plain floats, so that an
    observation holds no reference to the rules that decoded it."""
    return (max(rules.fuel, 1e-300), float(rules.torpedoes), float(max(rules.hyperspace_jumps, 1)),
            float(max(rules.reload, 1)), float(max(rules.flip_cooldown, 1)),
            float(max(rules.torpedo_life, 1)), max(rules.star_mu, 1e-300),
            float(rules.max_round_frames))


def _vector_from_raw(raw, scales):
    """``Observation.vector()`` from the raw observation (see ``vector_layout``)."""
    numbers = raw[_NH:_NH + 2 * _NS].tolist()
    slots = raw[_NH + 2 * _NS:].reshape(-1, _NT)
    present = slots[:, 0] != 0.0
    vec_t = np.zeros((slots.shape[0], 7))
    vec_t[:, :6] = slots[:, :6]
    vec_t[:, 6] = slots[:, 6] / scales[5]
    vec_t[~present] = 0.0
    return np.concatenate((_ship_vector(numbers[:_NS], scales) + _ship_vector(numbers[_NS:], scales)
                           + [raw[6] / scales[6], raw[1] / scales[7]], vec_t.ravel()))
