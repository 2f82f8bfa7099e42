"""Scenes for the compiled-versus-Python bot comparisons, and the branch coverage they reach.

A *scene* is a seeded set of matches: the ships scattered at random states (``scatter``), the
Python reference bots ``names`` playing them under ``rules`` for ``frames`` frames; at every
frame each compiled bot decides on the same state and must choose the Python bot's action
(``play``; ``tests/spacewar/test_compiled_bots.py`` runs the scenes).

Branch coverage of the compiled bots (``spacewar/game/compiled_bots/``): :func:`branch_table` lists the branches of
its functions from the source (each ``if`` / ``while`` true and false, each ``for`` entered and
left, coverage.py's notion of a branch); :func:`traced_arcs` runs code with the bots as plain
Python (``NUMBA_DISABLE_JIT=1``, in a subprocess) under a line tracer and collects the
(line, next line) arcs each branch is seen by. ``python -m tests.spacewar.compiled_bot_scenes``
measures the coverage of every frame of every scene (minutes: a plain-Python sniper decision
traced costs about 12 ms) and prints, per branch not reached, its line; with ``--probes`` it
also prints, for each branch, the first (scene, match, frame, seat) that reaches it: the
``PROBES`` table below, which the suite replays cheaply (``test_compiled_bots_branches.py``).
"""
import ast
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from engine.cache import jit_disabled
from spacewar.game import compiled_bots as cb
from spacewar.game import core
from spacewar.bots import chaser, dodger, random_bot, sniper
from spacewar.game.game import Game
from spacewar.rules import Rules

ROOT = Path(__file__).resolve().parents[2]
#: the compiled bots' modules (a package, one module per bot), each given a line-number base so
#: that a line of any of them is one number: module k's line n is ``k * LINES + n``
SOURCES = sorted(Path(cb.__file__).resolve().parent.glob("*.py"))
LINES = 100_000
PY = {"chaser": chaser.Chaser, "sniper": sniper.Sniper, "dodger": dodger.Dodger,
      "random": random_bot.RandomBot}


# -- scenes -----------------------------------------------------------------------------------
class Scene:
    """``matches`` matches seeded ``seed ..``, the Python bots ``names`` (seat 0, seat 1) for
    ``frames`` frames under ``rules`` (keyword arguments of ``Rules``); ``compare``: the seats
    whose compiled decisions are checked; ``spread``: the scatter's speed range, fuel and
    torpedoes (see :func:`scatter`); ``setup(game)``: a scripted start after the scatter."""

    def __init__(self, name, names, seed, matches, frames, rules=None, compare=(0,), setup=None,
                 **spread):
        self.name, self.names, self.seed, self.setup = name, tuple(names), seed, setup
        self.matches, self.frames, self.compare = matches, frames, tuple(compare)
        self.rules = dict(rules or {})
        self.spread = spread

    def make_rules(self):
        return Rules(**self.rules) if self.rules else None

    def __repr__(self):
        return f"Scene({self.name})"


def head_on(game):
    """Seat 0 and seat 1 closing along a line of constant y (exactly head-on in even matches,
    offset by up to 0.03 in odd ones): the chaser's ram dodge, head-on and not."""
    for m in range(game.n_matches):
        y = 0.3 + (0.0 if m % 2 == 0 else 0.005 * (m % 7))
        gap = 0.05 + 0.01 * (m % 5)
        game.pos[m, :, 0] = (-0.5 * gap, 0.3)
        game.pos[m, :, 1] = (0.5 * gap, y)
        game.vel[m, :, 0] = (1.0e-3, 0.0)
        game.vel[m, :, 1] = (-1.0e-3, 0.0)


def torpedo_coming(game):
    """An enemy torpedo (seat 1's slot 0) 2 to 12 frames from seat 0, aimed at it or a little
    off: the dodger's dodges (dead on and not) and, when it cannot clear, its hyperspace jump."""
    ntorp = game.rules.torpedoes
    for m in range(game.n_matches):
        frames = 2 + m % 11
        angle = 0.7 * m
        speed = 4.0e-3
        miss = 0.0 if m % 3 == 0 else 0.004 * (m % 3)
        x, y = game.pos[m, :, 0]
        ux, uy = math.cos(angle), math.sin(angle)
        b = 2 + ntorp
        game.pos[m, :, b] = (x - frames * speed * ux - miss * uy,
                             y - frames * speed * uy + miss * ux)
        game.vel[m, :, b] = game.vel[m, :, 0] + speed * np.array([ux, uy])
        game.active[m, b] = True
        game.torp_life[m, ntorp] = 60
        game.ship_counters[m, 1, core.TORPS] = ntorp - 1


def into_the_star(game):
    """Seat 1 falling straight at the star (zero angular momentum: its periapsis is 0)."""
    for m in range(game.n_matches):
        r = 0.06 + 0.02 * (m % 4)
        a = 0.9 * m
        game.pos[m, :, 1] = (r * math.cos(a), r * math.sin(a))
        game.vel[m, :, 1] = (-1.0e-3 * math.cos(a), -1.0e-3 * math.sin(a))


def torpedo_enemy_unseen(game):
    """``torpedo_coming``, and in odd matches the enemy (seat 1) in hyperspace: the dodger
    dodges a torpedo whose owner it cannot see (no shot is considered); in matches 2 and 6 the
    torpedo 0.01 from seat 0 moving exactly with it (a threat with no relative velocity)."""
    torpedo_coming(game)
    b = 2 + game.rules.torpedoes
    for m in range(2, game.n_matches, 4):
        game.pos[m, :, b] = game.pos[m, :, 0] + 0.01 * np.array([math.cos(m), math.sin(m)])
        game.vel[m, :, b] = game.vel[m, :, 0]
    for m in range(1, game.n_matches, 2):
        game.ship_counters[m, 1, core.IN_HYPER] = 1
        game.ship_counters[m, 1, core.HYPER_TIMER] = int(game.rules.hyperspace_frames)
        game.active[m, 1] = False


def side_by_side(game):
    """Seat 1 near seat 0, four cases by ``m % 4``: (0) 0.004 to 0.014 apart (within the launch
    offset, 0.0195) with the same velocity: the chaser's ram check on a zero relative velocity,
    its straight lead with no positive root, the sniper's intercept met at the first sampled
    frame; (1) as near, 0.005 a frame apart (faster than a torpedo): the lead's quadratic with
    roots of both signs; (2, 3) seat 0 at rest at (0.25, 0.25) and seat 1 moving (0.004, 0),
    exactly the muzzle speed, so the quadratic is linear (``|w|^2 - s^2`` is 0 in floating
    point): (2) seat 1 exactly the launch offset ahead (x + 0.01953125: no root at all), (3) 0.01
    ahead in match 3 (root negative), 0.05 behind in match 7 (root positive)."""
    for m in range(game.n_matches):
        a = 1.1 * m
        gap = 0.004 + 0.002 * (m % 6)
        v = (1.0e-3 * math.cos(2.0 * a), 1.0e-3 * math.sin(2.0 * a))
        case = m % 4
        if case < 2:
            game.pos[m, :, 0] = (0.2, -0.1)
            game.pos[m, :, 1] = (0.2 + gap * math.cos(a), -0.1 + gap * math.sin(a))
            game.vel[m, :, 0] = v
            game.vel[m, :, 1] = v
            if case == 1:
                game.vel[m, :, 1] += 5.0e-3 * np.array([math.cos(a + 2.0), math.sin(a + 2.0)])
        else:
            muzzle = game.rules.muzzle_speed
            dx = game.rules.launch_offset if case == 2 else (0.01 if m == 3 else -0.05)
            game.pos[m, :, 0] = (0.25, 0.25)
            game.pos[m, :, 1] = (0.25 + dx, 0.25)
            game.vel[m, :, 0] = (0.0, 0.0)
            game.vel[m, :, 1] = (muzzle, 0.0)


def grazing(game):
    """Seat 0 on a circular orbit of radius 0.065 to 0.075 (its periapsis above the chaser's
    q_min, 0.06, below the 1.3 q_min its pursuit burns must keep, and no burn of the chaser's
    size lifts it there): the pursuit's scan of safe directions runs out. Seat 1 far off."""
    mu = game.rules_vector[core.R_STAR]
    for m in range(game.n_matches):
        r = 0.065 + 0.002 * (m % 6)
        a = 0.8 * m
        v = math.sqrt(mu / r) * (1 if m % 2 else -1)
        game.pos[m, :, 0] = (r * math.cos(a), r * math.sin(a))
        game.vel[m, :, 0] = (-v * math.sin(a), v * math.cos(a))
        game.pos[m, :, 1] = (-0.4 * math.cos(a), -0.4 * math.sin(a))
        game.ship_gauges[m, 0, core.FUEL] = 1000.0


def at_the_star(game):
    """The compared ship exactly at the star's centre (the ``star_kills=False`` rules move it
    out at the step): seat 0 in even matches, seat 1 in odd ones. The periapsis at r = 0 and the
    escape burn's scan of directions there."""
    for m in range(game.n_matches):
        s = m % 2
        game.pos[m, :, s] = (0.0, 0.0)
        game.vel[m, :, s] = (1.0e-3 * math.cos(m), 1.0e-3 * math.sin(m))


def launch_at_star(game):
    """Under ``launch_offset=0.1`` (newtonian: torpedoes feel the star) the sniper (seat 0)
    at (-0.1, 0) leaving the star on the x axis, unbound (its periapsis is its distance, above
    q_min), and the enemy on the x axis beyond the star: the lead's heading is exactly 0, so
    the torpedo's launch point ``p + offset (cos 0, sin 0)`` is exactly the star's centre
    (the Kepler shift's fallback)."""
    mu = game.rules_vector[core.R_STAR]
    for m in range(game.n_matches):
        game.pos[m, :, 0] = (-0.1, 0.0)
        game.vel[m, :, 0] = (-1.2 * math.sqrt(2.0 * mu / 0.1) - 1.0e-4 * m, 0.0)
        game.pos[m, :, 1] = (0.03 + 0.01 * m, 0.0)
        game.vel[m, :, 1] = (0.0, 0.0)


#: the comparison scenes. The first three are the original tests' (the chaser's 100 matches,
#: the sniper's and the dodger's 30; their first 12 matches already reach the branches all 100
#: did); the others were added to reach the branches those never take (see
#: test_compiled_bots_branches.py): other sense switches and modes, a ram, a dodger's
#: hyperspace jump, the electric flip, the ships' starts near the star, and preset edge states
#: (no star with a torpedo coming, ships side by side, a grazing orbit, a ship at the star, a
#: torpedo launched from the star's centre).
SCENES = {s.name: s for s in (
    Scene("chaser", ("chaser", "random"), 11, 100, 120),
    Scene("sniper", ("sniper", "chaser"), 21, 30, 80, compare=(0, 1)),
    Scene("dodger", ("dodger", "sniper"), 31, 30, 80, compare=(0, 1)),
    Scene("no-star", ("dodger", "chaser"), 41, 12, 60, {"star": "none"}, compare=(0, 1)),
    Scene("no-star-sniper", ("sniper", "random"), 42, 8, 60, {"star": "none"}),
    Scene("spin", ("sniper", "chaser"), 43, 12, 60, {"angular_momentum": True},
          compare=(0, 1)),
    Scene("newtonian", ("dodger", "sniper"), 44, 12, 60, {"mode": "newtonian"},
          compare=(0, 1)),
    Scene("electric", ("dodger", "sniper"), 45, 12, 40, {"mode": "electric"}, compare=(0, 1),
          setup=torpedo_coming),
    Scene("ram", ("chaser", "random"), 46, 10, 20, {"star": "none"}, setup=head_on),
    Scene("torpedo", ("dodger", "random"), 47, 22, 40, setup=torpedo_coming),
    Scene("fast", ("sniper", "chaser"), 48, 12, 60, compare=(0, 1), speed=6e-3),
    Scene("doomed", ("sniper", "random"), 49, 8, 40, {"star_kills": False},
          setup=into_the_star),
    Scene("torpedo-no-star", ("dodger", "random"), 50, 8, 12, {"star": "none"},
          setup=torpedo_enemy_unseen),
    Scene("side-by-side", ("chaser", "sniper"), 51, 8, 3, {"star": "none"}, compare=(0, 1),
          setup=side_by_side),
    Scene("grazing", ("chaser", "random"), 52, 6, 6, setup=grazing),
    Scene("at-star", ("chaser", "sniper"), 53, 4, 2, {"star_kills": False}, compare=(0, 1),
          setup=at_the_star),
    Scene("launch-at-star", ("sniper", "random"), 54, 4, 3,
          {"launch_offset": 0.1, "mode": "newtonian"},
          setup=launch_at_star),
)}


def scatter(game, rng, speed=1.6e-3, fuel=(150.0, 1000.0), near_star=0.05):
    """Random ship states (at least ``near_star`` from the star), speeds up to ``speed``, fuel
    uniform in ``fuel`` (so the fuel reserve matters) and 1 to 32 torpedoes (so the sniper's
    shot time varies)."""
    for m in range(game.n_matches):
        for s in range(2):
            while True:
                x, y = rng.uniform(-0.5, 0.5, 2)
                if x * x + y * y > near_star ** 2:
                    break
            v, direction = rng.uniform(0.0, speed), rng.uniform(-math.pi, math.pi)
            game.pos[m, :, s] = (x, y)
            game.vel[m, :, s] = (v * math.cos(direction), v * math.sin(direction))
            game.ship_gauges[m, s, core.HEADING] = rng.uniform(-math.pi, math.pi)
            game.ship_gauges[m, s, core.FUEL] = rng.uniform(*fuel)
            game.ship_counters[m, s, core.TORPS] = rng.integers(1, game.rules.torpedoes + 1)


def arrays(game, memory, streams):
    return (game.pos, game.vel, game.charge, game.active, game.ship_gauges, game.ship_counters,
            game.torp_life, game.match_state, game.rules_vector, memory, streams)


class Disagreement(AssertionError):
    """A compiled bot chose another action than the Python bot (the first such frame)."""


def play(scene, on_frame=None, only=None, compiled=None, until=None):
    """Play ``scene``: the Python bots act, each compared seat's compiled bot decides on the
    same state first. Raises :class:`Disagreement` at the first frame where they differ (bot,
    scene, match, frame, both actions). Returns the number of compared decisions per seat and
    the Python bots. ``on_frame(f, bots, memory, game, codes, actions, live)`` is called after
    each frame's decisions (before the step); ``only``: play only these matches' Python bots
    (the others stand still; a match never touches another's rows); ``compiled``: a replacement for
    ``cb.decide_all`` (a planted bug); ``until``: stop before this frame."""
    decide_all = cb.decide_all if compiled is None else compiled
    matches = scene.matches
    game = Game(scene.make_rules(), seeds=list(range(scene.seed, scene.seed + matches)), rounds=3)
    scatter(game, np.random.default_rng(scene.seed), **scene.spread)
    if scene.setup is not None:
        scene.setup(game)
    playing = range(matches) if only is None else sorted(only)
    bots = {m: [PY[n](seed=1000 * m + s) for s, n in enumerate(scene.names)] for m in playing}
    memory = cb.new_memory(matches)
    streams = cb.new_streams(matches, scene.seed)
    codes = np.zeros((matches, 2), dtype=np.int64)
    actions = np.full((matches, 2), core.NOOP, dtype=np.int64)
    total = np.zeros(2, dtype=np.int64)
    for f in range(scene.frames if until is None else until):
        live = ~game.over
        for s in scene.compare:
            decide_all(cb.KINDS[scene.names[s]], s, *arrays(game, memory, streams), codes)
        for m in playing:
            if live[m]:
                for s in range(2):
                    actions[m, s] = bots[m][s].act(game.observe(m, s)).code()
        if on_frame is not None:
            on_frame(f, bots, memory, game, codes, actions, live)
        for s in scene.compare:
            check_frame(scene, f, s, codes, actions, live, playing)
            total[s] += sum(bool(live[m]) for m in playing)
        game.step(actions)
    return total, bots


def check_frame(scene, f, s, codes, actions, live, playing):
    """Every live match's compiled code for seat ``s`` is the Python bot's action, else
    :class:`Disagreement` naming the first differing match."""
    for m in playing:
        if live[m] and codes[m, s] != actions[m, s]:
            raise Disagreement(
                f"compiled {scene.names[s]} (seat {s}) differs from the Python bot in scene "
                f"{scene.name!r}, match {m}, frame {f}: compiled action {codes[m, s]}, Python "
                f"action {actions[m, s]}")


# -- branches ---------------------------------------------------------------------------------
EXIT = -1  # the arc target of leaving a function


def _successor(stmt, parents):
    """The line control reaches after ``stmt`` completes normally (EXIT: the function returns)."""
    block, index, owner = parents[id(stmt)]
    if index + 1 < len(block):
        return block[index + 1].lineno
    if isinstance(owner, (ast.For, ast.While)) and block is owner.body:
        return owner.lineno  # back to the loop's head
    if isinstance(owner, (ast.FunctionDef,)):
        return EXIT
    return _successor(owner, parents)


def branch_table(paths=SOURCES):
    """Every branch of the compiled bots' functions (line numbers on each module's base, as
    :data:`SOURCES`): dicts with ``function``, ``line``, ``kind``
    (if / while / for), ``outcome`` (True: taken / entered, False: not / left), ``sources``
    (the lines its condition spans) and ``target`` (the line it goes to; EXIT)."""
    out = []
    for base, path in enumerate(paths):
        out.extend(_branches_of(Path(path), base * LINES))
    return out


def _branches_of(path, base):
    tree = ast.parse(path.read_text())
    out = []
    for fn in tree.body:
        if not isinstance(fn, ast.FunctionDef):
            continue
        parents = {}

        def index(block, owner):
            for i, stmt in enumerate(block):
                parents[id(stmt)] = (block, i, owner)
                for field in ("body", "orelse"):
                    sub = getattr(stmt, field, None)
                    if isinstance(sub, list) and sub and isinstance(sub[0], ast.stmt):
                        index(sub, stmt)
        index(fn.body, fn)
        for node in ast.walk(fn):
            if isinstance(node, (ast.If, ast.While)):
                sources = list(range(node.lineno, node.test.end_lineno + 1))
            elif isinstance(node, ast.For):
                sources = [node.lineno]
            else:
                continue
            kind = type(node).__name__.lower()
            other = node.orelse[0].lineno if node.orelse else _successor(node, parents)
            for outcome, target in ((True, node.body[0].lineno), (False, other)):
                out.append({"function": fn.name, "line": base + node.lineno,
                            "def": base + fn.lineno, "kind": kind, "outcome": outcome,
                            "sources": [base + line for line in sources],
                            "target": target if target == EXIT else base + target})
    return out


def branch_id(b):
    """``function+offset:kind:T/F``, offset the lines from the ``def`` (stable under edits
    elsewhere in the module)."""
    return f"{b['function']}+{b['line'] - b['def']}:{b['kind']}:{'T' if b['outcome'] else 'F'}"


def reached(branches, arcs):
    """The ids of the branches seen among ``arcs`` (a set of (line, next line))."""
    return {branch_id(b) for b in branches
            if any((s, b["target"]) in arcs for s in b["sources"])}


#: (scene, match, frame, seat): for each branch, the first state of the scenes taking it (the
#: full run's ``--probes``, 12 matches of each scene; the scenes added for the last open
#: branches, torpedo-no-star .. launch-at-star, measured on their own and merged in)
PROBES = [
    ('at-star', 0, 0, 0), ('at-star', 0, 0, 1), ('at-star', 0, 1, 0), ('at-star', 0, 1, 1),
    ('at-star', 1, 0, 1), ('at-star', 2, 0, 1), ('at-star', 3, 0, 0), ('chaser', 0, 0, 0),
    ('chaser', 0, 13, 0), ('chaser', 1, 0, 0), ('chaser', 2, 0, 0), ('chaser', 3, 0, 0),
    ('chaser', 3, 25, 0), ('chaser', 4, 0, 0), ('chaser', 5, 0, 0), ('chaser', 5, 4, 0),
    ('chaser', 8, 0, 0), ('chaser', 11, 0, 0), ('dodger', 0, 0, 0), ('dodger', 1, 35, 0),
    ('dodger', 1, 36, 0), ('dodger', 1, 40, 0), ('dodger', 11, 64, 0), ('doomed', 0, 0, 0),
    ('doomed', 5, 13, 0), ('electric', 0, 0, 0), ('electric', 0, 33, 0), ('electric', 1, 0, 0),
    ('electric', 1, 39, 0), ('electric', 3, 0, 0), ('electric', 8, 37, 0), ('fast', 4, 0, 1),
    ('grazing', 0, 0, 0), ('launch-at-star', 0, 0, 0), ('launch-at-star', 0, 1, 0),
    ('launch-at-star', 1, 2, 0), ('launch-at-star', 3, 1, 0), ('newtonian', 0, 0, 0),
    ('newtonian', 2, 25, 0), ('newtonian', 6, 0, 0), ('newtonian', 6, 8, 0),
    ('newtonian', 6, 25, 0), ('newtonian', 6, 26, 0), ('newtonian', 6, 43, 0),
    ('newtonian', 8, 34, 1), ('no-star', 0, 0, 0), ('no-star', 0, 0, 1), ('no-star', 0, 1, 0),
    ('no-star', 1, 0, 0), ('no-star', 1, 0, 1), ('no-star', 1, 1, 0), ('no-star', 1, 17, 0),
    ('no-star', 2, 0, 0), ('no-star', 3, 0, 0), ('no-star', 4, 0, 0), ('no-star', 4, 0, 1),
    ('no-star', 4, 1, 0), ('no-star', 11, 1, 0), ('no-star', 11, 23, 0), ('no-star', 11, 23, 1),
    ('no-star-sniper', 0, 0, 0), ('ram', 0, 0, 0), ('ram', 0, 16, 0), ('ram', 1, 0, 0),
    ('ram', 5, 12, 0), ('side-by-side', 0, 0, 0), ('side-by-side', 0, 0, 1),
    ('side-by-side', 0, 1, 0), ('side-by-side', 1, 0, 0), ('side-by-side', 1, 0, 1),
    ('side-by-side', 2, 0, 0), ('side-by-side', 2, 0, 1), ('side-by-side', 2, 1, 1),
    ('side-by-side', 2, 2, 0), ('side-by-side', 2, 2, 1), ('side-by-side', 3, 0, 0),
    ('side-by-side', 3, 1, 1), ('side-by-side', 3, 2, 1), ('side-by-side', 5, 0, 1),
    ('side-by-side', 6, 0, 0), ('side-by-side', 6, 1, 0), ('side-by-side', 7, 0, 0),
    ('sniper', 0, 0, 0), ('sniper', 0, 1, 0), ('sniper', 1, 0, 0), ('sniper', 1, 18, 0),
    ('sniper', 1, 35, 0), ('sniper', 2, 21, 0), ('sniper', 2, 21, 1), ('sniper', 2, 46, 0),
    ('sniper', 3, 13, 0), ('sniper', 4, 28, 0), ('sniper', 5, 0, 0), ('sniper', 7, 0, 0),
    ('sniper', 7, 14, 0), ('sniper', 7, 15, 0), ('sniper', 7, 31, 0), ('spin', 0, 0, 0),
    ('spin', 0, 0, 1), ('spin', 1, 0, 1), ('spin', 5, 0, 0), ('spin', 5, 26, 0),
    ('spin', 6, 20, 0), ('spin', 9, 0, 1), ('spin', 9, 40, 1), ('spin', 9, 56, 0),
    ('spin', 10, 0, 1), ('torpedo-no-star', 0, 0, 0), ('torpedo-no-star', 0, 1, 0),
    ('torpedo-no-star', 1, 0, 0), ('torpedo-no-star', 2, 0, 0), ('torpedo-no-star', 5, 0, 0),
]


#: branches the scenes do not reach, with the reason (none OPEN: each is out of scope or proved
#: unreachable, or never seen where a proof would need the Kepler solver's);
#: the suite holds this list exact (a listed branch reached, or a new one not, fails the test)
_ONE_MATCH = ('decide, the one-match entry: the scenes go through decide_all; test_deterministic '
              'holds decide to decide_all for every kind')
_RANDOM = ("random / idle: not compared frame by frame (the random bot's stream is not numpy's); "
           "test_random_bot_frequencies, test_deterministic")
UNREACHABLE = {
    'decide+6:if:T':
        _ONE_MATCH,
    'decide+6:if:F':
        _ONE_MATCH,
    'decide+10:if:T':
        _ONE_MATCH,
    'decide+10:if:F':
        _ONE_MATCH,
    'decide+12:if:T':
        _ONE_MATCH,
    'decide+12:if:F':
        _ONE_MATCH,
    'decide_with+3:if:T':
        _RANDOM,
    'decide_with+7:if:F':
        _RANDOM,
    'reset_memory+3:for:T':
        'not a decision: test_reset_memory_is_a_fresh_bot',
    'reset_memory+3:for:F':
        'not a decision: test_reset_memory_is_a_fresh_bot',
    # DOT_FUSED is fixed per machine (numpy_dot_kind): the other way is dead code here (a
    # host whose numpy dot rounds once, such as an AVX-512 AMD EPYC, takes the fused way)
    f"dot_blas+3:if:{'F' if cb.DOT_FUSED else 'T'}":
        'DOT_FUSED is fixed per machine (numpy_dot_kind): one way is dead code here',
    'py_hypot+12:if:T':
        'inf: no game state; test_reference_arithmetic checks it against math.hypot',
    'py_hypot+14:if:T':
        'NaN: no game state; test_reference_arithmetic checks it',
    'py_hypot+20:if:T':
        'subnormal: no game state; test_reference_arithmetic checks it',
    'periapsis+2:if:T':
        'mu <= 0: every caller checks mu > 0 first',
    'safe_heading_near+22:if:T':
        ('a ship exactly at the star (r == 0) that is not escaping: unreachable. Both callers '
         '(chaser, sniper_decide) call safe_heading_near only after periapsis(...) >= q_min > 0, '
         'and periapsis at r == 0 is 0 (the at-star scene takes that: the escape burn instead)'),
    'enemy_point+9:if:T':
        "a Kepler point not finite (never seen; the module's docstring)",
    'predict_path+19:if:T':
        'a Kepler point not finite (never seen)',
    'predict_path+21:if:F':
        'a Kepler point not finite (never seen)',
    'skip_frames+6:if:T':
        'over 1e6 frames to a threshold: distances on the unit torus are < 0.71',
    'predict_at+13:if:F':
        ('a Kepler point not finite, as predict_path+19 (never seen): kepler_step gave finite '
         'points for all 72,844 random starts tried (r 1e-20 to 1, speeds 1e-8 to 0.03, 30% '
         'radial, t 1 to 95, mu 2.5e-7; measured on this machine), radial orbits '
         'through the star included. The launch-at-star scene takes the other fallback (r = 0)'),
    'safest_heading+36:if:T':
        ('no burn direction within 0.9 of the best periapsis: needs a NaN periapsis. For a '
         'finite state every q is finite and >= 0 (0 at r == 0, else r or h^2 / (mu (1 + e)), '
         'e >= 0), so qmax >= 0 and its own k has q >= 0.9 qmax; the second pass skips a k only '
         'once best >= 0, so the k of qmax sets best unless best is already set'),
}


# -- tracing (in a NUMBA_DISABLE_JIT=1 process) ---------------------------------------------
def traced_arcs(run):
    """Run ``run()`` under a line tracer; the arcs (line, next line; EXIT on return) of frames
    of the compiled bots' modules, lines on each module's base (:data:`SOURCES`)."""
    arcs = set()
    bases = {str(path): k * LINES for k, path in enumerate(SOURCES)}

    def local(frame, event, arg):
        if event == "line":
            line = bases[frame.f_code.co_filename] + frame.f_lineno
            arcs.add((last[frame], line))
            last[frame] = line
        elif event == "return":
            arcs.add((last.pop(frame, 0), EXIT))
        return local

    last = {}

    def world(frame, event, arg):
        if event == "call" and frame.f_code.co_filename in bases:
            last[frame] = bases[frame.f_code.co_filename] + frame.f_code.co_firstlineno
            return local
        return None

    sys.settrace(world)
    try:
        run()
    finally:
        sys.settrace(None)
    return arcs


def _replay(states_path, out_path):
    """Subprocess side: decide on every recorded state with the bots as plain Python, traced;
    check each decision is the recorded compiled one; write the arcs and, per arc, the first
    state reaching it."""
    if not jit_disabled():
        raise SystemExit("run with NUMBA_DISABLE_JIT=1")
    data = np.load(states_path, allow_pickle=False)
    meta = json.loads(str(data["meta"]))
    per_state = []
    mismatches = []
    for i, item in enumerate(meta):
        state = [data[f"s{i}_{k}"] for k in range(11)]
        codes = np.zeros((1, 2), dtype=np.int64)
        arcs = traced_arcs(lambda: cb.decide_all(cb.KINDS[item["kind"]], item["seat"], *state,
                                                 codes))
        if codes[0, item["seat"]] != item["code"]:
            mismatches.append([item, int(codes[0, item["seat"]])])
        per_state.append(sorted(arcs))
    Path(out_path).write_text(json.dumps({"arcs": per_state, "mismatches": mismatches}))


def record_states(picks):
    """Play scenes in this (compiled) process and keep the states at ``picks``: a list of
    (scene name, match, frame, seat). Each is one match's rows (memory and streams before the
    decision) and the compiled bot's code. Returns (meta, arrays) for :func:`replay_states`."""
    meta, blobs = [], {}
    by_scene = {}
    for scene, m, f, s in picks:
        by_scene.setdefault(scene, []).append((m, f, s))
    for name, items in by_scene.items():
        scene = SCENES[name] if isinstance(name, str) else name
        wanted = {}
        for m, f, s in items:
            wanted.setdefault(f, []).append((m, s))
        last = max(wanted)

        def grab(f, bots, memory, game, codes, before):
            for m, s in wanted.get(f, ()):
                rows = [a[m:m + 1].copy() for a in arrays(game, before[0], before[1])]
                rows[8] = game.rules_vector.copy()
                i = len(meta)
                meta.append({"scene": scene.name, "match": m, "frame": f, "seat": s,
                             "kind": scene.names[s], "code": int(codes[m, s])})
                for k, a in enumerate(rows):
                    blobs[f"s{i}_{k}"] = a
        _play_keeping_before(scene, grab, {m for m, _, _ in items}, last + 1)
    return meta, blobs


def _play_keeping_before(scene, grab, only, until):
    """``play`` with ``grab`` also given the memory and streams as they were before the
    frame's compiled decisions (a decision updates them)."""
    saved = {}

    def compiled(kind, seat, *args):
        memory, streams = args[9], args[10]
        if seat == min(scene.compare):
            saved["before"] = (memory.copy(), streams.copy())
        cb.decide_all(kind, seat, *args)

    def on_frame(f, bots, memory, game, codes, actions, live):
        grab(f, bots, memory, game, codes, saved["before"])
    # the compared seats decide in order: the second seat's memory row is untouched by the
    # first seat's decision, so a copy before the first serves both
    play(scene, on_frame=on_frame, only=only, compiled=compiled, until=until)


def replay_states(meta, blobs, timeout=1800):
    """Replay recorded states in a ``NUMBA_DISABLE_JIT=1`` subprocess under the tracer:
    (the set of arcs of each state, mismatches of plain-Python and compiled decisions)."""
    with tempfile.TemporaryDirectory() as tmp:
        states = Path(tmp) / "states.npz"
        out = Path(tmp) / "arcs.json"
        np.savez(states, meta=json.dumps(meta), **blobs)
        env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONWARNINGS="ignore")
        subprocess.run([sys.executable, "-c",
                        "import sys; from tests.spacewar.compiled_bot_scenes import _replay; "
                        "_replay(sys.argv[1], sys.argv[2])", str(states), str(out)],
                       cwd=ROOT, env=env, check=True, timeout=timeout)
        result = json.loads(out.read_text())
    return [{(a, b) for a, b in arcs} for arcs in result["arcs"]], result["mismatches"]


def coverage_report(picks):
    """(branches, per-state arcs, meta, mismatches) for the states at ``picks``."""
    meta, blobs = record_states(picks)
    per_state, mismatches = replay_states(meta, blobs)
    return branch_table(), per_state, meta, mismatches


def first_reaching(branches, per_state):
    """Branch id -> index of the first state reaching it."""
    where = {}
    for i, arcs in enumerate(per_state):
        for b in reached(branches, arcs):
            where.setdefault(b, i)
    return where


def all_picks(scene):
    return [(scene.name, m, f, s) for m in range(scene.matches) for f in range(scene.frames)
            for s in scene.compare]


def main(argv):
    names = [a for a in argv if not a.startswith("--")] or list(SCENES)
    limit = next((int(a.split("=")[1]) for a in argv if a.startswith("--matches=")), None)
    picks = []
    for n in names:
        sc = SCENES[n]
        picks += [p for p in all_picks(sc) if limit is None or p[1] < limit]
    branches, per_state, meta, mismatches = coverage_report(picks)
    where = first_reaching(branches, per_state)
    ids = set(where)
    every = [branch_id(b) for b in branches]
    print(f"{len(ids)} of {len(every)} branches reached by {len(meta)} decisions of {names}")
    for b in every:
        if b not in ids:
            print("  not reached:", b)
    if "--probes" in argv:
        probes = sorted({(meta[i]["scene"], meta[i]["match"], meta[i]["frame"], meta[i]["seat"])
                         for i in where.values()})
        print("PROBES =", probes)
        for b in every:
            if b in where:
                item = meta[where[b]]
                print(f"  {b}: {item['scene']} m{item['match']} f{item['frame']} s{item['seat']}")
    print("mismatches:", mismatches[:5], len(mismatches))


if __name__ == "__main__":
    main(sys.argv[1:])
