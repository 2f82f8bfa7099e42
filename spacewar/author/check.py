"""``spacewar check``: does a bot load, play by the rules, answer in time, and repeat itself?

In the spirit of Gymnasium's ``check_env`` and PettingZoo's ``parallel_api_test``: before a
bot enters a tournament, ``check_bot`` loads it exactly as a match would (a bot named by a
file or module in its own confined process), plays it against every built-in bot from both
seats, and reports

* a load error (unknown name, missing file, import, construction or ``reset`` failing);
* its faults: the count of each kind (``raised``, ``invalid``, ``timeout``, ``crashed``,
  ``startup``, ``memory``, see ``spacewar.sandbox.process``) and the first messages, and its forfeits;
* the time of its actions (p50, p95, p99, max, as charged against the per-action budget;
  ``spacewar.sandbox.process``), pooled over every match;
* whether it is deterministic: the first match is played again with the same seed, and the
  two plays' results and replays (every frame's actions and faults, the final state's
  SHA-256) must be identical;
* for a batch bot named by a file, all of that as a tournament plays it: each opponent's
  matches in one game, its one confined process answering for all of them at once
  (``check_bot``), so that what it does in a tournament is what is checked;
* how each match went (wins, draws, losses: for information, never a reason to fail).

It passes when it loads, has no fault and no forfeit, its p99 action time is within the
budget, and it plays the same match the same way twice. Warnings (a slow tail paid from the
overage bank, little headroom, printed output that differs between the two plays) do not fail
it. Action times are wall-clock figures: they depend on the machine and its load, so they
are reported here and never written into a match's result.
"""
import base64
import dataclasses
import hashlib
import json

import numpy as np

from spacewar.bots import BotLoadError, available, locate
from spacewar.arena.match import (DEFAULT_MAX_FAULTS, check_bot_argument, act_time_summary,
                                  play_match)
from spacewar.rules import Rules, count_at_least
from spacewar.faults import FAULT_KINDS, printable
from spacewar.sandbox.limits import Limits
from spacewar.arena.seats import bot_name

#: a p99 action time above this fraction of the budget is a warning (little headroom)
HEADROOM = 0.5
#: fault messages kept in a report
MAX_EXAMPLES = 5
#: ``spacewar tournament``'s default seeds a pairing: a batch bot's default here, so that it
#: is asked for as many matches at once (2 x 10) as in a tournament of the defaults
TOURNAMENT_GAMES = 10


@dataclasses.dataclass
class CheckReport:
    """What ``check_bot`` found. ``passed`` is the verdict; ``reasons`` say why it failed
    (empty when it passed), ``warnings`` what deserves a look without failing it.

    ``matches``: one dict per match played (``opponent``, ``seat`` the checked bot's, 0 or 1,
    ``seed``, ``outcome`` "win" / "draw" / "loss" / "no result", ``score`` [its, the
    opponent's], ``rounds``, ``frames``, ``faults`` {kind: count}, ``forfeited``).
    ``faults``: {kind: count} over those matches (the determinism replay is compared, not
    counted); ``fault_examples``: the first few, each with its match's opponent, seat and
    seed; ``forfeits``: how many of those matches it forfeited. ``act``: the action-time
    summary in seconds (``spacewar.arena.match.act_time_summary``) over those matches,
    ``over_budget`` how many actions took longer than ``budget``, the per-action budget in
    seconds. ``deterministic``: True, False, or None when not checked (the bot could not
    start); ``determinism``: what was compared and what differed. ``output_bytes``: how many
    bytes it printed in all (a confined bot's stdout and stderr are captured). ``settings``:
    what the check played with (opponents, games, seed, rounds, rules, budgets, and
    ``together``: the size of each group of matches played at once, as a tournament plays a
    batch bot's matches, empty when every match was played alone)."""

    bot: str
    passed: bool = False
    reasons: list = dataclasses.field(default_factory=list)
    warnings: list = dataclasses.field(default_factory=list)
    load_error: str = None
    matches: list = dataclasses.field(default_factory=list)
    faults: dict = dataclasses.field(default_factory=lambda: {k: 0 for k in FAULT_KINDS})
    fault_examples: list = dataclasses.field(default_factory=list)
    forfeits: int = 0
    act: dict = dataclasses.field(default_factory=lambda: act_time_summary([]))
    over_budget: int = 0
    budget: float = None
    deterministic: bool = None
    determinism: str = ""
    output_bytes: int = 0
    settings: dict = dataclasses.field(default_factory=dict)

    def to_dict(self):
        """Plain data (JSON-ready)."""
        return dataclasses.asdict(self)

    def format(self):
        """The report as text for a terminal: the verdict first, then the details; every line
        escaped (``seats.printable``): the bot's name is a file name, its messages its own."""
        lines = [f"{'PASS' if self.passed else 'FAIL'}: {self.bot}"]
        lines += [f"  reason: {r}" for r in self.reasons]
        lines += [f"  warning: {w}" for w in self.warnings]
        if self.load_error is not None:  # the reason says it all: nothing was played
            return "\n".join(printable(line) for line in lines)
        lines.append(f"  matches: {_tally(self.matches)}")
        if self.settings.get("together"):
            sizes = "/".join(str(k) for k in sorted(set(self.settings["together"])))
            lines.append(f"  played as a tournament plays it: {sizes} matches at once "
                         "against each opponent, in one game")
        for opponent, text in _per_opponent(self.matches):
            lines.append(f"    vs {opponent:<10}{text}")
        total = sum(self.faults.values())
        kinds = ", ".join(f"{k} {n}" for k, n in self.faults.items() if n) or "none"
        lines.append(f"  faults: {total} ({kinds}); forfeits: {self.forfeits}")
        for e in self.fault_examples:
            lines.append(f"    {e['kind']} at frame {e['frame']} (vs {e['opponent']}, seat "
                         f"{e['seat'] + 1}, seed {e['seed']}): {e['message']}")
        lines.append(f"  act time: {_format_act(self.act, self.budget)}")
        lines.append(f"  deterministic: {_yes_no(self.deterministic)}: {self.determinism}")
        if self.output_bytes:
            lines.append(f"  printed output: {self.output_bytes} bytes (captured, not shown)")
        return "\n".join(printable(line) for line in lines)


def check_bot(bot, *, opponents=None, games=None, seed=0, rounds=1, rules=None, limits=None,
              max_faults=DEFAULT_MAX_FAULTS, isolation="auto", on_match=None):
    """Check the bot ``bot`` (a specification, as ``spacewar match`` takes it, or a bot
    object, which plays in this process) and return a ``CheckReport``.

    It plays ``games`` seeds (``seed``, ``seed + 1``, ...) against each of ``opponents``
    (default every built-in bot) from both seats, each match of ``rounds`` rounds under
    ``rules`` and ``limits`` (a ``spacewar.sandbox.limits.Limits``; default the match defaults), then
    the first match once more to compare. The matches are grouped as a tournament groups
    its own (``spacewar.arena.tournament``): a bot named by a file that plays as a batch bot (or a
    policy file) plays each opponent's ``2 * games`` matches together, answering for all of
    them at once, so it cannot tell a check from a tournament by its batch size; its
    ``games`` default to a tournament's (``TOURNAMENT_GAMES``), every other bot's to 1, and
    the determinism replay plays that first group again. ``on_match(record)`` is called
    after each match with its ``CheckReport.matches`` entry (``"repeat": True`` on the
    determinism replay). Bad arguments raise ValueError or TypeError naming them before any
    match is played."""
    opponents, rules, limits = _checked_arguments(bot, opponents, 1 if games is None else games,
                                                  seed, rounds, rules, limits, max_faults,
                                                  isolation)
    batch_files = _batch_files(bot, opponents)
    if games is None:
        games = TOURNAMENT_GAMES if _plays_together(bot, batch_files, isolation) else 1
    report = CheckReport(bot=bot_name(bot), budget=limits.budget, settings={
        "opponents": list(opponents), "games": int(games), "seed": int(seed),
        "rounds": int(rounds), "rules": rules.to_dict(), "max_faults": int(max_faults),
        "isolation": isolation,
        "budget": limits.budget, "overage": limits.overage, "startup": limits.startup})
    if isinstance(bot, str):
        try:
            locate(bot)  # a name that cannot be a bot fails here, before any process starts
        except BotLoadError as exc:
            return _failed_to_load(report, str(exc))
    jobs = _jobs(bot, opponents, games, seed, isolation, batch_files)
    report.settings["together"] = [len(entries) for entries, together in jobs if together]
    play = dict(rounds=rounds, rules=rules, limits=limits, max_faults=max_faults,
                isolation=isolation, batch_files=batch_files)
    times, first = [], None
    for entries, together in jobs:
        played = _play_job(bot, entries, together, play, record=first is None)
        for k, ((opponent, game_seed, seat), (result, _, timing)) in enumerate(zip(entries,
                                                                                 played)):
            startup = _startup_fault(result, seat)
            if startup is not None:
                return _failed_to_load(report, startup)
            times.append(timing["act_seconds"][seat])
            # matches played together share one process, whose output each of them shows
            _add_match(report, opponent, game_seed, seat, result, on_match, output=k == 0)
        if first is None:
            first = (entries, together, played)
    _judge_determinism(report, bot, first, play, on_match)
    pooled = np.concatenate(times)
    report.act = act_time_summary(pooled)
    report.over_budget = int(np.count_nonzero(pooled > limits.budget))
    _judge(report, limits)
    return report


def _checked_arguments(bot, opponents, games, seed, rounds, rules, limits, max_faults,
                       isolation):
    """The opponents, rules and limits to play with, after checking every argument."""
    check_bot_argument("bot", bot)
    count_at_least("games", games, 1)
    count_at_least("seed", seed, 0)
    count_at_least("rounds", rounds, 1)
    count_at_least("max_faults", max_faults, 1)
    if isolation not in ("auto", "process"):
        raise ValueError(f"isolation must be auto or process, got {isolation!r}")
    opponents = available() if opponents is None else opponents
    if isinstance(opponents, str):
        opponents = [o.strip() for o in opponents.split(",") if o.strip()]
    opponents = list(opponents)
    if not opponents:
        raise ValueError("opponents must name at least one bot, got none")
    for opponent in opponents:
        if not isinstance(opponent, str):
            raise TypeError(f"opponents must be bot specifications (str), got {opponent!r}")
        locate(opponent)  # BotLoadError (a ValueError) naming it
    rules = Rules() if rules is None else rules
    if not isinstance(rules, Rules):
        raise TypeError(f"rules must be a spacewar.Rules, got {rules!r}")
    limits = Limits() if limits is None else limits
    if not isinstance(limits, Limits):
        raise TypeError(f"limits must be a spacewar.sandbox.limits.Limits, got {limits!r}")
    return opponents, rules, limits


def _schedule(opponents, games, seed):
    """``(opponent, seed, seat)`` of every match, opponent by opponent, both seats a seed."""
    return [(opponent, seed + g, seat) for opponent in opponents for g in range(games)
            for seat in (0, 1)]


def _batch_files(bot, opponents):
    """The bots from files among ``bot`` and ``opponents`` that a tournament plays as batch
    bots (``jobs.batch_files_of``); none are run to find out."""
    from spacewar.arena.jobs import batch_files_of

    return batch_files_of([x for x in [bot, *opponents] if isinstance(x, str)])


def _plays_together(bot, batch_files, isolation):
    """Whether a tournament plays ``bot``'s matches against a built-in bot together: a
    specification of a batch bot or a policy file (``batch_match.is_batch_spec``), unless
    every match is confined alone (``isolation="process"``). A bot object is the caller's own
    code, which no tournament plays: it plays its matches one at a time."""
    from spacewar.arena.batch_match import is_batch_spec

    return isinstance(bot, str) and isolation != "process" and is_batch_spec(bot, batch_files)


def _jobs(bot, opponents, games, seed, isolation, batch_files):
    """The schedule cut as a tournament cuts its own (``jobs.group_jobs``): a list of
    ``(entries, together)``, ``entries`` the ``(opponent, seed, seat)`` of each match of a
    job, ``together`` whether they are played in one game (``batch_match.play_matches``)."""
    from spacewar.arena.jobs import group_jobs

    schedule = _schedule(opponents, games, seed)
    if not isinstance(bot, str):
        return [([entry], False) for entry in schedule]
    matches = [(*_seated(bot, opponent, seat), s) for opponent, s, seat in schedule]
    jobs, start = [], 0
    for job, together in group_jobs(matches, isolation, batch_files):
        jobs.append((schedule[start:start + len(job)], together))
        start += len(job)
    return jobs


def _play_job(bot, entries, together, play, record):
    """``[(result, replay, timing)]`` of a job's matches (``replay`` None unless ``record``),
    ``timing`` with every action's time (``act_seconds``)."""
    options = dict(play)
    batch_files = options.pop("batch_files")
    if not together:
        (opponent, game_seed, seat), = entries
        return [play_match(*_seated(bot, opponent, seat), seed=game_seed, record=record,
                           act_seconds=True, **options)]
    from spacewar.arena.batch_match import play_matches

    options.pop("isolation")  # together only when it is not "process"
    matches = [(*_seated(bot, opponent, seat), s) for opponent, s, seat in entries]
    played = play_matches(matches, batch_files=batch_files, record=record, act_seconds=True,
                          **options)
    return played if record else [(result, None, timing) for result, timing in played]


def _seated(bot, opponent, seat):
    """``(p1, p2)`` with the checked bot in ``seat``."""
    return (bot, opponent) if seat == 0 else (opponent, bot)


def _startup_fault(result, seat):
    """The message of the checked bot's start-up fault in this match, or None."""
    faults = result["faults"][seat]
    if not faults["startup"]:
        return None
    found = [e for e in faults["examples"] if e["kind"] == "startup"]
    return found[0]["message"] if found else "start-up failed"


def _failed_to_load(report, message):
    report.load_error = message
    report.reasons.append(f"it does not load: {message}")
    report.passed = False
    return report


def _outcome(result, seat):
    if result["winner_seat"] is None:
        return "draw" if not any(result["forfeits"]) else "no result"
    return "win" if result["winner_seat"] == seat else "loss"


def _add_match(report, opponent, game_seed, seat, result, on_match, output=True):
    """Count one match's outcome, faults, forfeit and (``output``) output into ``report``."""
    faults = result["faults"][seat]
    record = {"opponent": opponent, "seat": seat, "seed": game_seed,
              "outcome": _outcome(result, seat),
              "score": [result["score"][seat], result["score"][1 - seat]],
              "rounds": result["rounds"], "frames": result["steps"],
              "faults": {k: faults[k] for k in FAULT_KINDS if faults[k]},
              "forfeited": bool(result["forfeits"][seat])}
    report.matches.append(record)
    for kind in FAULT_KINDS:
        report.faults[kind] += faults[kind]
    for example in faults["examples"]:
        if len(report.fault_examples) < MAX_EXAMPLES:
            report.fault_examples.append({**example, "opponent": opponent, "seat": seat,
                                          "seed": game_seed})
    report.forfeits += record["forfeited"]
    if output:
        report.output_bytes += result["output"][seat]["bytes"]
    if on_match is not None:
        on_match(record)


def play_fingerprint(result, replay):
    """A SHA-256 of what a match's play is: its result without the bots' printed output,
    every frame's action codes and fault codes, and the final state's hash (from the replay).
    Two plays of a seed by a deterministic bot have the same fingerprint."""
    played = {k: v for k, v in result.items() if k != "output"}
    data = {"result": played, "actions": replay["actions"], "faults": replay["faults"],
            "final_state_sha256": replay["final_state_sha256"]}
    text = json.dumps(data, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


@dataclasses.dataclass
class _TwoPlays:
    """One match of the determinism replay: the checked bot's seat, the seed, and the two
    plays' results and replays."""

    seat: int
    seed: int
    result: dict
    replay: dict
    again: dict
    replay_again: dict

    def differ(self):
        return (play_fingerprint(self.result, self.replay)
                != play_fingerprint(self.again, self.replay_again))

    def output_differs(self):
        return self.result["output"][self.seat] != self.again["output"][self.seat]

    def was_late(self):
        return bool(self.result["faults"][self.seat]["timeout"]
                    or self.again["faults"][self.seat]["timeout"])


def _judge_determinism(report, bot, first, play, on_match):
    """Play the first job again (one match, or a batch bot's first group of matches) and
    compare the two plays of each match (``play_fingerprint``)."""
    entries, together, played = first
    replayed = _play_job(bot, entries, together, play, record=True)
    pairs = []
    for (opponent, game_seed, seat), (result, replay, _), (again, replay_again, _) in zip(
            entries, played, replayed):
        if on_match is not None:
            on_match({"opponent": opponent, "seat": seat, "seed": game_seed, "repeat": True,
                      "outcome": _outcome(again, seat),
                      "score": [again["score"][seat], again["score"][1 - seat]]})
        pairs.append(_TwoPlays(seat, game_seed, result, replay, again, replay_again))
    where = _replayed_where(entries)
    differing = [pair for pair in pairs if pair.differ()]
    if not differing:
        report.deterministic = True
        fingerprint = play_fingerprint(pairs[0].result, pairs[0].replay)
        report.determinism = f"{where}: identical (play fingerprint {fingerprint[:16]})"
        if any(pair.output_differs() for pair in pairs):
            report.warnings.append("what it prints differs between two plays of the same "
                                   "match, so their result JSON differs (the play is the same)")
        return
    pair = differing[0]
    report.deterministic = False
    difference = _first_difference(pair.replay, pair.replay_again, pair.seat)
    if len(entries) > 1:
        difference = f"seed {pair.seed} from seat {pair.seat + 1}: {difference}"
    report.determinism = f"{where}: {difference}"
    if any(p.was_late() for p in pairs):
        advice = ("it was late in one of them, and whether an answer is late depends on the "
                  "machine: a bot within its budget plays the same way every time")
    else:
        advice = ("draw any randomness from random.Random(seed) with the seed its "
                  "constructor gets, and never from the clock")
    report.reasons.append(f"it is not deterministic: {report.determinism}; {advice}")


def _replayed_where(entries):
    """What the determinism replay played, in words."""
    opponent, game_seed, seat = entries[0]
    if len(entries) == 1:
        return f"seed {game_seed} against {opponent} from seat {seat + 1}, played twice"
    seeds = sorted({s for _, s, _ in entries})
    return (f"the {len(entries)} matches against {opponent} (seeds {seeds[0]} to {seeds[-1]}, "
            "both seats), played together twice")


def _first_difference(one, two, seat):
    """Where two replays of the same match first differ, in words."""
    a = base64.b64decode(one["actions"])
    b = base64.b64decode(two["actions"])
    for frame in range(min(len(a), len(b)) // 2):
        x, y = a[2 * frame + seat], b[2 * frame + seat]
        if x != y:
            return f"its action at frame {frame} was code {x} the first time, {y} the second"
        if a[2 * frame:2 * frame + 2] != b[2 * frame:2 * frame + 2]:
            return f"the opponent's action at frame {frame} differs"
    fa, fb = base64.b64decode(one["faults"]), base64.b64decode(two["faults"])
    if fa != fb:
        return "the same actions, but different faults"
    if len(a) != len(b):
        return f"one play lasted {len(a) // 2} frames, the other {len(b) // 2}"
    return "the same actions and faults, but a different result or final state"


def _judge(report, limits):
    """The verdict: reasons to fail and warnings, from everything gathered."""
    total = sum(report.faults.values())
    if total:
        kinds = ", ".join(f"{n} {k}" for k, n in report.faults.items() if n)
        first = report.fault_examples[0]
        report.reasons.insert(0, f"{total} fault(s) in {len(report.matches)} matches ({kinds}); "
                                 f"the first: {first['kind']}: {first['message']}")
    if report.forfeits:
        report.reasons.append(f"it forfeited {report.forfeits} of {len(report.matches)} "
                              "matches")
    budget_ms = limits.budget * 1e3
    act = report.act
    if act["count"]:
        if act["p99"] > limits.budget:
            report.reasons.append(
                f"p99 action time {act['p99'] * 1e3:.1f} ms is over the budget of "
                f"{budget_ms:g} ms: more than 1 action in 100 is paid from the overage bank "
                f"({limits.overage * 1e3:g} ms a match), which a long match spends")
        elif act["max"] > limits.budget:
            report.warnings.append(
                f"{report.over_budget} action(s), up to "
                f"{act['max'] * 1e3:.1f} ms, went over the budget of {budget_ms:g} ms "
                "(paid from the overage bank)")
        elif act["p99"] > HEADROOM * limits.budget:
            report.warnings.append(
                f"p99 action time {act['p99'] * 1e3:.1f} ms is over {HEADROOM:.0%} of the "
                f"budget ({budget_ms:g} ms): a slower or busier machine may make it late")
    report.passed = not report.reasons


def _tally(matches):
    wins = sum(m["outcome"] == "win" for m in matches)
    draws = sum(m["outcome"] == "draw" for m in matches)
    losses = sum(m["outcome"] == "loss" for m in matches)
    other = len(matches) - wins - draws - losses
    text = f"{len(matches)} played: {wins} won, {draws} drawn, {losses} lost"
    return text + (f", {other} without a result" if other else "")


def _per_opponent(matches):
    """``(opponent, summary)`` in the order played."""
    order = list(dict.fromkeys(m["opponent"] for m in matches))
    for opponent in order:
        mine = [m for m in matches if m["opponent"] == opponent]
        scores = ", ".join(f"{m['score'][0]}-{m['score'][1]} (seat {m['seat'] + 1})"
                           for m in mine)
        yield opponent, f"{_tally(mine)}; scores {scores}"


def _format_act(act, budget):
    if not act["count"]:
        return "no action answered"
    ms = {k: act[k] * 1e3 for k in ("p50", "p95", "p99", "max")}
    return (f"p50 {ms['p50']:.2f} ms, p95 {ms['p95']:.2f} ms, p99 {ms['p99']:.2f} ms, "
            f"max {ms['max']:.2f} ms over {act['count']} actions; budget {budget * 1e3:g} ms")


def _yes_no(value):
    return {True: "yes", False: "NO", None: "not checked"}[value]
