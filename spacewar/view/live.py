"""Spacewar! in a pygame window: people at the keyboard, bots, or two bots to watch.

    from spacewar.view.live import play, watch
    play("chaser", rounds=5)               # you fly the needle (seat 1) against the chaser
    play(p1="human", p2="human")           # two people at one keyboard
    watch("chaser", "sniper")              # two bots; pause, slow motion, fast forward

Who flies with which keys is in ``spacewar.view.keys``: one person (in either seat) gets both hands'
keys, A/D or Left/Right to turn, W or Up to thrust, Space or S to fire, H (or both turn keys)
for hyperspace, F to flip polarity; two people get WASD (player 1) and the arrows with the
right-hand keys or the numeric keypad (player 2). P pauses, Esc quits.

The game runs ``fps`` frames a second whatever the drawing rate (``spacewar.view.window.Pace``: the
engine's fixed-step clock turns wall time into whole frames, and the drawing blends the last
two frames by the clock's remainder); ``watch`` can run it from 1/8x to 8x, pause it and step
it frame by frame, since simulation time is not wall time. A bot plays exactly as in
``spacewar.arena.match``: in a fault-isolated seat (``spacewar.arena.seats.open_seat``; a bot that is not
built in runs in its own confined process), a fault costs it its turn, ``max_faults`` faults or
a dead bot forfeit the match. So ``watch`` with the same bots and seed plays the same match as
``spacewar match`` (while the bots keep within their budgets), and either can be recorded and
then scrubbed with ``spacewar replay FILE --view``.

pygame is part of the optional ``[viz]`` extra and is imported only when a window opens.
"""
import math

import numpy as np

from engine import space
from engine.atomic import check_output_path

from spacewar.game import core
from spacewar.view import keys as K
from spacewar.game.game import Game
from spacewar.faults import FAULT_KINDS, printable
from spacewar.arena.match import (DEFAULT_MAX_FAULTS, bot_seed, checked_limits, cpu_seconds,
                                  match_result)
from spacewar.protocol import Action, raw_length
from spacewar.game.referee import Referee
from spacewar.view.look import DIM_TEXT, TEXT
from spacewar.view.scene import Effects, frame_snapshot, scene
from spacewar.rules import Rules
from spacewar.arena.seats import bot_name, open_seat
from spacewar.view.window import (WATCH_SCREEN_HELP, Pace, Window, blend, check_display, check_speed,
                     check_window_arguments, help_lines, run_window)
from spacewar.view.window import require_pygame

BOT_BUDGET = 0.05  # seconds per bot action
HUMAN = "human"

# the keys of one person at the keyboard, as they have always been named here
TURN_LEFT = K.SOLO.left
TURN_RIGHT = K.SOLO.right
THRUST = K.SOLO.thrust
FIRE = K.SOLO.fire
HYPERSPACE = K.SOLO.hyperspace
FLIP = K.SOLO.flip
PAUSE = "p"
QUIT = "escape"
#: every key name ``play`` reads (pygame's names for them)
KEY_NAMES = K.PLAY_KEY_NAMES

#: (keys, what they do) of one person at the keyboard: shown on screen and in the help
KEYS_HELP = K.SOLO.help() + K.PLAY_CONTROLS_HELP


def held_keys_code(held, keyset=K.SOLO):
    """The action code for the set of held key names under ``keyset`` (default: one person's
    keys); pressing both turn keys is hyperspace."""
    turn, thrust, fire, hyperspace, flip = keyset.action(held)
    return Action(turn=turn, thrust=thrust, fire=fire, hyperspace=hyperspace, flip=flip).code()


def play_script_source(script):
    """``keys.script_source`` for the keys ``play`` reads: a function ``tick -> held keys``
    from a callable or a sequence of ``(tick, keys)``; ticks count the window's fixed-rate
    ticks from the start, paused or not."""
    return K.script_source(script, KEY_NAMES)


# -- seats --------------------------------------------------------------------------------------
class KeyboardSeat:
    """A person's seat: the action is what their keys (``keyset``) hold at the frame.

    It has the shape of ``spacewar.sandbox.process`` seats (``act``, ``dead``, ``close``), so a match
    loop treats people and bots alike; a person never faults.
    """

    def __init__(self, name, keyset):
        self.spec = name
        self.keyset = keyset
        self.held = frozenset()
        self.dead = None

    def wait_ready(self):
        return None

    def act(self, raw):
        return held_keys_code(self.held, self.keyset), None

    def close(self):
        return {"text": "", "bytes": 0, "truncated": False}


def _is_human(spec):
    return isinstance(spec, str) and spec.strip().lower() == HUMAN


def _people_names(specs):
    """Each seat's name in the result: a bot's specification; ``human`` for one person,
    ``human 1`` and ``human 2`` for two."""
    people = [s for s, spec in enumerate(specs) if _is_human(spec)]
    names = []
    for s, spec in enumerate(specs):
        if not _is_human(spec):
            names.append(bot_name(spec))
        else:
            names.append(HUMAN if len(people) == 1 else f"{HUMAN} {s + 1}")
    return names


def _keysets(specs):
    """Each person's keys: both hands' for one person, WASD and the arrows for two."""
    people = [s for s, spec in enumerate(specs) if _is_human(spec)]
    if len(people) == 1:
        return {people[0]: K.SOLO}
    return {s: (K.PLAYER_1, K.PLAYER_2)[s] for s in people}


def _open_seats(specs, names, seed, limits, rules, rounds, isolation):
    """The two seats, bots started and ready; a bot that cannot start is a ValueError
    naming it (nothing is left running)."""
    keysets = _keysets(specs)
    cpu = cpu_seconds(rules, rounds, limits)  # a confined bot's CPU time, as in a match
    seats = []
    try:
        for s, spec in enumerate(specs):
            if s in keysets:
                seats.append(KeyboardSeat(names[s], keysets[s]))
                continue
            seat = open_seat(spec, bot_seed(seed, s), limits, rules, isolation, cpu, rounds=rounds)
            seats.append(seat)
            if getattr(seat, "wait_ready", None) is not None and seat.wait_ready() is not None:
                # the message comes from the bot's process: shown escaped, never as terminal codes
                raise ValueError(f"bot {names[s]!r} (seat {s + 1}) could not start: "
                                 f"{printable(str(seat.dead[1]))}")
    except BaseException:
        for seat in seats:
            seat.close()
        raise
    return seats


# -- a match played at the window's pace ------------------------------------------------------
class LiveMatch:
    """One match played a frame at a time when the window asks, with the rules of
    ``spacewar.arena.match.play_match``: both seats asked each frame (seat 1 first), a fault
    recorded and played as a no-op, a seat whose bot died or reached ``max_faults`` faults
    forfeits. Keeps the frame-by-frame records of a replay and a few statistics per seat.
    """

    def __init__(self, game, seats, names, seed, rounds, max_faults):
        self.game = game
        self.seats = seats
        self.names = names
        self.seed = seed
        self.rounds = rounds
        self.max_faults = max_faults
        self.referee = Referee(max_faults, record=True)
        self.faults = self.referee.faults
        self.forfeits = self.referee.forfeits
        self.fired = [0, 0]
        self.distance = [0.0, 0.0]
        self.jumps = [0, 0]
        self.previous_positions = None  # (pos, active) before the last frame played
        self.effects = Effects()  # the drawing's flashes and bursts, fed every frame played
        self.effects.update(frame_snapshot(game))
        self._actions = np.full((1, 2), 0, dtype=np.int64)
        self._raws = np.empty((2, raw_length(game.rules)))
        for s in range(2):
            game.write_raw(0, s, self._raws[s])

    @property
    def over(self):
        return bool(self.game.over[0]) or any(self.forfeits)

    @property
    def people(self):
        """The seats people fly."""
        return [s for s, seat in enumerate(self.seats) if isinstance(seat, KeyboardSeat)]

    def set_keys(self, held):
        """What the people's keys hold now (each person's seat reads its own keys of it)."""
        for seat in self.seats:
            if isinstance(seat, KeyboardSeat):
                seat.held = held

    def play_frame(self):
        """Ask both seats, then step the game one frame (unless a seat forfeited)."""
        game = self.game
        before = self._counters()
        positions = (game.pos[0].copy(), game.active[0].copy())
        if not self.referee.play_frame(game, self.seats, self._raws, self._actions):
            return
        self.previous_positions = positions
        self._count(before)
        self.effects.update(frame_snapshot(game))

    def _counters(self):
        game = self.game
        return (game.rounds_played(0), game.ship_counters[0, :, core.TORPS].copy(),
                game.ship_counters[0, :, core.IN_HYPER].copy())

    def _count(self, before):
        """Torpedoes fired, hyperspace jumps and distance flown in the frame just played."""
        game = self.game
        round_before, torpedoes_before, hyper_before = before
        if game.rounds_played(0) != round_before:
            return  # a new round reset the ships
        prev_pos, prev_active = self.previous_positions
        for s in range(2):
            self.fired[s] += int(max(0, torpedoes_before[s] - game.ship_counters[0, s, core.TORPS]))
            if game.ship_counters[0, s, core.IN_HYPER] and not hyper_before[s]:
                self.jumps[s] += 1
            if prev_active[s] and game.active[0, s]:
                step = space.wrap(game.pos[0, :, s] - prev_pos[:, s], 1.0)
                if abs(step).max() < 0.05:  # not a jump
                    self.distance[s] += float(math.hypot(*step))

    def finish(self, rules):
        """Close the seats; return ``(result, replay)`` in ``spacewar.arena.match``'s formats."""
        from spacewar.replay import make_replay

        outputs = [seat.close() for seat in self.seats]
        result = match_result(self.game, self.names, self.seed, self.rounds, rules, self.faults,
                              self.forfeits, outputs)
        replay = make_replay(result, bytes(self.referee.history), self.game.state_hash(0),
                             faults=bytes(self.referee.fault_codes), max_faults=self.max_faults)
        return result, replay


# -- the sessions -------------------------------------------------------------------------------
def _checked_rules(rules):
    if rules is None:
        return Rules()
    if isinstance(rules, dict):
        return Rules.from_dict(rules)
    if not isinstance(rules, Rules):
        raise TypeError(f"rules must be a spacewar.Rules or its dict, got {rules!r}")
    return rules


def play(p2="chaser", rules=None, seed=0, rounds=5, fps=60, scale=720, script=None,
         max_seconds=None, *, p1=HUMAN, limits=None, max_faults=DEFAULT_MAX_FAULTS,
         isolation="auto", record_to=None):
    """Play a match in a pygame window; ``p1`` (the needle) and ``p2`` (the wedge) are each
    ``"human"`` or a bot (a specification or a bot object). Default: you against the chaser.

    ``rules``: a ``Rules`` (or its dict), default the 1962 game. ``fps``: game frames a second.
    ``scale``: window side in pixels. ``script``: keys to play instead of the keyboard
    (``script_source``), for tests and demos. ``max_seconds``: stop after that much wall time.
    ``limits`` (``spacewar.sandbox.limits.Limits``; default a 50 ms budget per action), ``max_faults``
    and ``isolation``: the bots' budgets and seats, as in ``spacewar.arena.match.play_match``.
    ``record_to``: a replay file to write when the match is finished (its path is checked
    first); a match left before its end is not written, since a replay records a whole match
    (``spacewar replay --check`` refuses a record that stops early).
    With no person in the match this is ``watch``.

    Returns a summary dict: ``reason`` (``over``, ``quit``, ``closed``, ``time`` or
    ``interrupted``), ``players``, ``scores``, ``frames`` played, ``rounds``, ``over``,
    ``winner`` (with one person against one bot: ``human`` or ``bot``, as this function
    always said; otherwise the winner's name in ``players``; None for none), ``winner_seat``,
    ``forfeits``, per-seat
    ``faults`` and ``torpedoes_fired``, ``distance`` flown (arena units) and
    ``hyperspace_jumps``, ``bot`` (the bot's name when there is one bot), ``bot_faults`` and
    ``bot_fault_examples`` (all bots'), ``paused_frames`` (window ticks spent paused),
    ``dropped_steps`` (ticks the clock skipped because drawing fell behind), ``speed``,
    ``wall_seconds``, ``result`` (``spacewar.arena.match``'s result of the frames played),
    ``replay_path`` (None when none was written) and ``replay_skipped`` (one was asked for
    but the match was left before its end).
    """
    return _session((p1, p2), rules, seed, rounds, fps, scale, 1.0, script, max_seconds, limits,
                    max_faults, isolation, record_to)


def watch(p1="chaser", p2="sniper", rules=None, seed=0, rounds=5, fps=60, scale=720, speed=1.0,
          script=None, max_seconds=None, *, limits=None, max_faults=DEFAULT_MAX_FAULTS,
          isolation="auto", record_to=None):
    """Watch bot ``p1`` (the needle) play bot ``p2`` (the wedge) in a pygame window.

    Space or P pauses, ``.`` steps one frame, ``]``/``[`` (or Up/Down) go faster or slower
    (``keys.SPEEDS``, 1/8x to 8x; ``speed`` is the one to start at), 1 is normal speed,
    Esc or Q quits. The other arguments and the summary are ``play``'s; the match is the one
    ``spacewar.arena.match.play_match`` plays with the same bots and seed.
    """
    for s, spec in enumerate((p1, p2)):
        if _is_human(spec):
            raise ValueError(f"p{s + 1} is {spec!r}: watch is for two bots (people play with "
                             "spacewar play)")
    return _session((p1, p2), rules, seed, rounds, fps, scale, speed, script, max_seconds,
                    limits, max_faults, isolation, record_to)


def _session(specs, rules, seed, rounds, fps, scale, speed, script, max_seconds, limits,
             max_faults, isolation, record_to):
    """Check everything, open the seats and the window, run, close; return the summary."""
    rules = _checked_rules(rules)
    check_window_arguments(fps, scale, max_seconds)
    speed = check_speed(speed)
    limits = checked_limits(max_faults, BOT_BUDGET, limits)
    watching = not any(_is_human(spec) for spec in specs)
    known = K.WATCH_KEY_NAMES if watching else KEY_NAMES
    source = None if script is None else K.script_source(script, known)
    if record_to is not None:
        record_to = check_output_path(record_to, "replay")  # before the match, not after it
    check_display()  # before any bot starts
    game = Game(rules, seeds=[seed], rounds=rounds)  # checks seed and rounds
    names = _people_names(specs)
    seats = _open_seats(specs, names, seed, limits, rules, rounds, isolation)
    match = LiveMatch(game, seats, names, seed, rounds, max_faults)
    try:
        window = Window(scale, _caption(specs, names), known)
    except BaseException:
        match.finish(rules)
        raise
    finished = False
    try:
        pace = Pace(fps, speed)
        session = LiveSession(match, pace, specs, watching, source is not None, window.size)
        _, seconds = run_window(window, pace, session, source, max_seconds)
        summary = {"reason": session.reason, "paused_frames": session.paused_ticks,
                   "dropped_steps": pace.dropped_ticks, "speed": pace.speed,
                   "wall_seconds": seconds}
        result, replay = match.finish(rules)
        finished = True
    finally:
        if not finished:
            match.finish(rules)
        window.close()
    written = record_to is not None and match.over
    if written:
        from spacewar.replay import save

        save(record_to, replay)
    return _summary(summary, match, result, specs, record_to if written else None,
                    record_to is not None and not written)


def _caption(specs, names):
    shown = _screen_names(specs, names)
    return f"Spacewar! - {shown[0]} (needle) vs {shown[1]} (wedge)"


def _screen_names(specs, names):
    """The names on screen: ``you`` for one person, ``player 1``/``player 2`` for two."""
    people = [s for s, spec in enumerate(specs) if _is_human(spec)]
    shown = list(names)
    for s in people:
        shown[s] = "you" if len(people) == 1 else f"player {s + 1}"
    return shown


# -- the loop -----------------------------------------------------------------------------------
class LiveSession:
    """A live match in the window (``viewer.run_window``'s session): the keys fly the people's
    ships and control the session (pause and quit; while watching also single steps and the
    speed), each window tick plays the frames it is worth, and the end waits for a key."""

    def __init__(self, match, pace, specs, watching, scripted, size):
        self.match = match
        self.pace = pace
        self.watching = watching
        self.scripted = scripted
        self.reason = None
        self.paused_ticks = 0
        self.held = frozenset()
        self.names = _screen_names(specs, match.names)
        self.footer_help = _footer_help(specs, watching, size)

    def hold(self, held):
        self.held = held

    def click(self, x, y):
        pass  # nothing to click on

    def press(self, names):
        quit_keys, pause_keys = (K.QUIT, K.PAUSE) if self.watching else (K.PLAY_QUIT, K.PLAY_PAUSE)
        for name in sorted(names):
            if name in quit_keys:
                self.reason = "quit"
            elif name in pause_keys:
                self.pace.paused = not self.pace.paused
            elif self.watching:
                self._watch_key(name)
        if self.match.over and names and self.reason is None:
            self.reason = "over"  # any key closes the window at the end

    def _watch_key(self, name):
        pace = self.pace
        if name in K.STEP_FORWARD:
            pace.paused = True
            if not self.match.over:
                self.match.play_frame()
        else:
            pace.speed_key(name)

    def tick(self):
        """One window tick: nothing while paused, else the frames it is worth at the speed."""
        match = self.match
        if match.over:
            if self.scripted:
                self.reason = "over"  # no one to press a key
            return
        if self.pace.paused:
            self.paused_ticks += 1
            return
        match.set_keys(self.held)
        for _ in range(self.pace.frames()):
            match.play_frame()
            if match.over:
                break

    def draw(self, window):
        _draw(window, self)


def _footer_help(specs, watching, size):
    """The keys, in short, along the bottom of the window."""
    if watching:
        return help_lines(WATCH_SCREEN_HELP, size)
    keysets = _keysets(specs)
    controls = (("P", "pause"), ("Esc", "quit"))
    if len(keysets) == 1:
        keyset = next(iter(keysets.values()))
        return help_lines(keyset.help(short=True) + controls, size)
    lines = []
    for s, keyset in sorted(keysets.items()):
        lines += help_lines(keyset.help(short=True), size, prefix=f"player {s + 1}:  ")
    return lines + help_lines(controls, size)


def _outcome(match, names):
    """The end of the match in words: who won or forfeited."""
    s0, s1 = (int(x) for x in match.game.scores[0])
    if all(match.forfeits):
        return "both forfeited"
    if any(match.forfeits):
        return f"{names[match.forfeits.index(True)]} forfeited"
    people = match.people
    if s0 == s1:
        return f"a draw {s0}-{s1}"
    winner = 0 if s0 > s1 else 1
    if len(people) == 1:
        return ("you win " if winner in people else "you lose ") + f"{max(s0, s1)}-{min(s0, s1)}"
    return f"{names[winner]} wins {max(s0, s1)}-{min(s0, s1)}"


def _draw(window, session):
    """One picture of a live session: the game (blended towards the latest frame by the
    clock's remainder), the keys and, while watching, the frame and the speed."""
    match, pace = session.match, session.pace
    game = match.game
    snapshot = frame_snapshot(game)
    if not pace.paused and not match.over and match.previous_positions is not None:
        snapshot = blend(snapshot, game, *match.previous_positions, pace.alpha)
    footer = []
    if session.watching:
        state = f"   speed {K.speed_label(pace.speed)}" + ("   paused" if pace.paused else "")
        footer.append((f"frame {int(game.frame[0])}{state}", TEXT))
    footer += [(line, DIM_TEXT) for line in session.footer_help]
    banner = None
    if match.over:
        banner = "game over: " + _outcome(match, session.names)
        if not session.scripted:
            banner += " - press a key"
    elif pace.paused and not session.watching:
        banner = "paused (P to resume)"
    window.show(scene(snapshot, window.size, effects=match.effects, names=session.names,
                      rounds=match.rounds, footer=footer, banner=banner))


# -- the summary --------------------------------------------------------------------------------
def _summary(run, match, result, specs, replay_path, replay_skipped):
    people = [s for s, spec in enumerate(specs) if _is_human(spec)]
    bots = [s for s in range(2) if s not in people]
    winner_seat = result["winner_seat"]
    if not match.over:
        winner_seat = None  # left before its end: the score so far names no winner
    if winner_seat is None:
        winner = None
    elif len(people) == 1 and len(bots) == 1:
        winner = HUMAN if winner_seat in people else "bot"
    else:
        winner = match.names[winner_seat]
    bot_examples = [ex for s in bots for ex in result["faults"][s]["examples"]][:3]
    return {
        "reason": run["reason"], "players": list(match.names), "scores": list(result["score"]),
        "frames": result["steps"], "rounds": result["rounds"], "rounds_asked": match.rounds,
        "over": bool(match.game.over[0]) or any(match.forfeits), "winner": winner,
        "winner_seat": winner_seat, "forfeits": list(result["forfeits"]),
        "faults": [result["faults"][s]["total"] for s in range(2)],
        "torpedoes_fired": list(match.fired), "distance": list(match.distance),
        "hyperspace_jumps": list(match.jumps), "seed": match.seed,
        "mode": match.game.rules.mode,
        "bot": match.names[bots[0]] if len(bots) == 1 else None,
        "bot_faults": sum(result["faults"][s]["total"] for s in bots),
        "bot_fault_examples": bot_examples,
        "paused_frames": run["paused_frames"], "dropped_steps": run["dropped_steps"],
        "speed": run["speed"], "wall_seconds": run["wall_seconds"], "result": result,
        "replay_path": None if replay_path is None else str(replay_path),
        "replay_skipped": replay_skipped,
    }


_ENDINGS = {"over": "the match is over", "quit": "quit before the end",
            "closed": "window closed before the end", "time": "stopped at the time limit",
            "interrupted": "interrupted (Ctrl-C) before the end"}


def format_summary(summary):
    """The summary of ``play``/``watch`` as a small table for people to read."""
    result = summary["result"]
    names = [printable(name) for name in summary["players"]]  # file names: shown escaped
    rows = [("", "seat 1 (needle)", "seat 2 (wedge)"),
            ("player", *names),
            ("score", *map(str, summary["scores"])),
            ("faults", *(_fault_cell(result["faults"][s]) for s in range(2))),
            ("forfeited", *("yes" if f else "no" for f in summary["forfeits"])),
            ("torpedoes fired", *map(str, summary["torpedoes_fired"])),
            ("hyperspace jumps", *map(str, summary["hyperspace_jumps"])),
            ("distance flown", *(f"{d:.2f}" for d in summary["distance"]))]
    widths = [max(len(row[k]) for row in rows) for k in range(3)]
    lines = ["  ".join(cell.ljust(widths[k]) for k, cell in enumerate(row)).rstrip()
             for row in rows]
    winner = summary["winner_seat"]
    won = "none (a draw)" if winner is None else f"{names[winner]} (seat {winner + 1})"
    if winner is None and all(summary["forfeits"]):
        won = "none (both forfeited)"
    elif winner is None and not summary["over"]:
        won = "none (left before the end)"
    lines.append("")
    lines.append(f"winner: {won}   rounds: {summary['rounds']} of {summary['rounds_asked']}   "
                 f"frames: {summary['frames']}   mode: {summary['mode']}   seed: {summary['seed']}")
    lines.append(f"ended: {_ENDINGS.get(summary['reason'], summary['reason'])}   "
                 f"paused {summary['paused_frames']} ticks, {summary['dropped_steps']} ticks "
                 f"dropped, {summary['wall_seconds']:.1f} s")
    if summary.get("replay_path"):
        lines.append(f"replay written to {summary['replay_path']}")
    elif summary.get("replay_skipped"):
        lines.append("no replay written: the match was left before its end (a replay records "
                     "a whole match)")
    return "\n".join(lines)


def _fault_cell(faults):
    if not faults["total"]:
        return "0"
    kinds = ", ".join(f"{k} {faults[k]}" for k in FAULT_KINDS if faults.get(k))
    return f"{faults['total']} ({kinds})"


__all__ = ["play", "watch", "format_summary", "held_keys_code", "play_script_source", "KeyboardSeat",
           "LiveMatch", "LiveSession", "KEYS_HELP", "KEY_NAMES", "require_pygame"]
