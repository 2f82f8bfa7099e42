"""``spacewar new-bot NAME``: write a commented starter bot that runs as it is.

The starter turns towards the enemy by the nearest image on the torus, leads it by the
torpedo's flight time, fires when the torpedo would pass within the hit box, closes in
slowly, and keeps its coasting path clear of the star (``spacewar.bots.geometry.periapsis``).
It imports only what a confined bot may: the standard library, ``spacewar`` and
``spacewar.bots.geometry``.

The file is written atomically and never over an existing one (``write_starter``).
"""
import keyword
import os
import shlex
import secrets
import sys

from engine.atomic import check_output_path

#: the starter's source; __NAME__, __CLASS__ and __SPEC__ are filled in by ``starter_source``
TEMPLATE = '''r"""__NAME__: a Spacewar! bot, started from ``spacewar new-bot`` (edit it freely).

Try it:

    spacewar match --p1 __SPEC__ --p2 idle
    spacewar match --p1 __SPEC__ --p2 chaser --replay game.json
    spacewar check __SPEC__

Conventions (docs/game.md, "Writing a bot"):

* the arena is a torus of side 1: x and y in [-0.5, 0.5), y up, the star at the origin;
  a body leaving one edge comes back at the opposite one, so take differences by the
  nearest image: ``torus_delta(a, b)`` is the shortest vector from a to b;
* one time unit is one frame: velocities are arena units per frame;
* a heading is in radians from +x, anticlockwise positive, in (-pi, pi]; the ship thrusts
  and fires along ``(cos heading, sin heading)``;
* ``Action(turn=+1)`` turns anticlockwise (``turn_rate`` a frame), ``turn=-1`` clockwise.

A bot named by a file runs in its own confined process: it may import the standard
library, numpy, spacewar and engine, and nothing else it would need a file, a socket,
a thread or a child process for.
"""
import math

from spacewar import NOOP, Action
from spacewar.bots.geometry import (angle_diff, heading_after, periapsis, safest_heading,
                                    steer, torus_delta)


class __CLASS__:
    """Turns towards the enemy, fires when lined up, keeps clear of the star."""

    #: the closest approach to the star (arena units) its coasting path may have
    safe_periapsis = 0.06
    #: frames of thrust a burn away from the star is planned for
    escape_burn = 12
    #: fire only at an enemy nearer than this (a torpedo flies 4e-3 a frame for 96 frames)
    fire_range = 0.3
    #: fire when the torpedo would pass the enemy within this fraction of the hit box
    aim_margin = 0.8
    #: thrust towards the enemy only while farther than this and slower than cruise_speed
    standoff = 0.15
    cruise_speed = 1.0e-3
    #: fuel kept for escaping the star
    fuel_reserve = 300.0

    def __init__(self, seed=None):
        # a per-seat seed derived from the match's seed: use random.Random(seed) for any
        # randomness, so that the same match seed gives the same match
        self.seed = seed
        self.escaping = False

    def reset(self):
        """Called when a match starts: forget everything from an earlier match."""
        self.escaping = False

    def act(self, obs):
        """One frame's controls: called once per frame with what the ship sees."""
        me, enemy, rules = obs.me, obs.enemy, obs.rules
        if not me.alive or me.in_hyperspace:
            return NOOP  # nothing can be steered
        escape = self.keep_clear_of_star(obs)
        if escape is not None:
            return escape
        if not enemy.alive or enemy.in_hyperspace:
            return NOOP
        # aim where the enemy will be when a torpedo gets there (straight-line lead)
        d = torus_delta(me.pos, enemy.pos)  # nearest image, not enemy.pos - me.pos
        distance = math.hypot(d[0], d[1])
        flight = distance / rules.muzzle_speed  # frames, near enough
        lead_x = d[0] + (enemy.vel[0] - me.vel[0]) * flight
        lead_y = d[1] + (enemy.vel[1] - me.vel[1]) * flight
        aim = math.atan2(lead_y, lead_x)
        turn = steer(me, aim, rules)  # -1, 0 or +1, towards aim the short way round
        return Action(turn=turn, thrust=self.wants_to_close_in(me, aim, distance),
                      fire=self.lined_up(me, turn, aim, distance, rules))

    def keep_clear_of_star(self, obs):
        """An action that burns away from the star when the coasting path would pass too
        close to it (its periapsis, from the orbit's energy and angular momentum), else None.
        Once escaping, it keeps burning until the periapsis is 1.5 times the safe one."""
        me, rules = obs.me, obs.rules
        if obs.star_mu <= 0.0:
            return None  # no star in these rules
        from_star = torus_delta(obs.star_pos, me.pos)
        q = periapsis(from_star, me.vel, obs.star_mu)
        if q >= self.safe_periapsis * (1.5 if self.escaping else 1.0):
            self.escaping = False
            return None
        self.escaping = True
        burn, _ = safest_heading(from_star, me.vel, obs.star_mu, me.heading,
                                 self.escape_burn * rules.thrust)
        thrust = abs(angle_diff(burn, me.heading)) < 0.8 and me.fuel > 0.0
        return Action(turn=steer(me, burn, rules), thrust=thrust)

    def wants_to_close_in(self, me, aim, distance):
        """Thrust while pointing at the enemy, far from it, slow, with fuel to spare."""
        speed = math.hypot(me.vel[0], me.vel[1])
        return (abs(angle_diff(aim, me.heading)) < 0.3 and distance > self.standoff
                and speed < self.cruise_speed and me.fuel > self.fuel_reserve)

    def lined_up(self, me, turn, aim, distance, rules):
        """Fire if a torpedo leaving on the heading after this frame's turn would pass the
        aim point within ``aim_margin`` of the hit box, in range, loaded."""
        if me.torpedoes <= 0 or me.reload > 0 or distance > self.fire_range:
            return False
        error = angle_diff(aim, heading_after(me, turn, rules))
        miss = distance * math.sin(abs(error)) if abs(error) < math.pi / 2 else math.inf
        return miss < self.aim_margin * rules.hit_box
'''


def class_name_for(name):
    """The class name a bot called ``name`` gets: each ``_``-separated part capitalised
    (``hunter`` -> ``Hunter``, ``my_bot`` -> ``MyBot``, ``bot2`` -> ``Bot2``); ``Bot`` when
    nothing is left (``_``)."""
    parts = [p for p in name.split("_") if p]
    return "".join(p[0].upper() + p[1:] for p in parts) or "Bot"


def check_bot_name(name):
    """``name`` if it can name a bot module and its class, else a ValueError naming it: a
    Python identifier, not a keyword, not a standard-library module's name (a module of that
    name in the current directory could not be loaded as ``name:Class``)."""
    if not isinstance(name, str) or not name.isidentifier():
        raise ValueError(f"NAME must be a Python identifier (letters, digits and _, not "
                         f"starting with a digit), got {name!r}")
    if keyword.iskeyword(name):
        raise ValueError(f"NAME must not be a Python keyword, got {name!r}")
    if name in sys.stdlib_module_names:
        raise ValueError(f"NAME {name!r} is the name of a standard-library module, which a bot "
                         "module cannot take: choose another (e.g. "
                         f"{name}_bot)")
    return name


def starter_source(name, spec=None):
    """The starter bot's source for bot ``name`` (checked), whose specification the text
    suggests trying (default ``NAME.py:Class``)."""
    check_bot_name(name)
    cls = class_name_for(name)
    spec = f"{name}.py:{cls}" if spec is None else spec
    # the commands in the docstring, as a shell takes them; the docstring is raw, so a
    # backslash in a path (C:\\Users) is text, not an escape
    shown = shlex.quote(spec)
    if '"""' in shown or not shown.isprintable():
        raise ValueError(f"the bot's path {spec!r} cannot be written into its docstring: "
                         "choose a path without newlines, control characters or \"\"\"")
    return TEMPLATE.replace("__NAME__", name).replace("__CLASS__", cls).replace("__SPEC__", shown)


def starter_path(name, out=None):
    """Where ``new-bot`` writes: ``out`` (a ``.py`` file, or an existing directory to put
    ``NAME.py`` in), default ``NAME.py`` in the current directory."""
    if out is None:
        return f"{name}.py"
    out = os.fspath(out)
    if os.path.isdir(out):
        return os.path.join(out, f"{name}.py")
    if not out.endswith(".py"):
        raise ValueError(f"--out must be a .py file or an existing directory, got {out!r}")
    return out


def write_starter(name, out=None):
    """Write the starter bot ``name`` and return ``(path, spec)``: the file written and the
    specification that loads it (``path:Class``).

    Checked before anything is written: ``name`` (``check_bot_name``), the path
    (``starter_path``, ``engine.atomic.check_output_path``), and that no file is there
    already (``FileExistsError`` naming it: an existing bot is never replaced). The file is
    written to a temporary name, synced, and linked into place, which fails rather than
    replace a file made meanwhile."""
    check_bot_name(name)
    path = starter_path(name, out)
    if os.path.lexists(path):
        raise FileExistsError(f"refusing to overwrite {path!r}: it exists (choose another "
                              "NAME or --out, or remove the file)")
    check_output_path(path, "text")
    spec = f"{path}:{class_name_for(name)}"
    _write_new_file(path, starter_source(name, spec))
    return path, spec


def _write_new_file(path, text):
    """Write ``text`` to ``path`` whole or not at all, never over an existing file: a synced
    temporary file in the same directory, hard-linked to ``path`` (the link fails if
    ``path`` exists), then unlinked. Where hard links are not supported, ``path`` is made
    with O_EXCL and written in place."""
    directory = os.path.dirname(os.path.abspath(path))
    tmp = os.path.join(directory, f".{os.path.basename(path)}.{secrets.token_hex(6)}.tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        try:
            os.link(tmp, path)
        except FileExistsError:
            raise FileExistsError(f"refusing to overwrite {path!r}: it appeared while the bot "
                                  "was being written") from None
        except OSError:  # no hard links on this file system
            _write_exclusive(path, text)
    finally:
        os.unlink(tmp)


def _write_exclusive(path, text):
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())


__all__ = ["TEMPLATE", "class_name_for", "check_bot_name", "starter_source", "starter_path",
           "write_starter"]
