"""``check``: a replay re-simulated and its whole recorded result re-derived from it alone
(the referee judging the recorded faults again), the final state compared bit for bit."""
import math

from spacewar.game import core
from spacewar.faults import FAULT_KINDS
from spacewar.game.referee import Referee
from spacewar.rules import Rules
from spacewar.replay.schema import validate
from spacewar.replay.signing import SIGNATURE_FIELD, signature_status
from spacewar.replay.simulate import actions, fault_record, new_game

def _same(a, b):
    """Equal as JSON values, with bools and numbers kept apart (``True`` is not ``1``)."""
    if isinstance(a, bool) or isinstance(b, bool):
        return type(a) is type(b) and a == b
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, (dict, list, tuple)) or isinstance(b, (dict, list, tuple)):
        return False
    if a is None or b is None:
        return a is b
    if isinstance(a, str) or isinstance(b, str):
        return type(a) is type(b) and a == b
    return a == b


def _replay_match(replay):
    """Re-play the records; return ``(game, forfeits, logs, problems)``.

    ``logs[s]`` is ``(counts, examples, last)`` rebuilt from the fault record (None for version 1).
    """
    game = new_game(replay)
    codes = actions(replay)
    rows = fault_record(replay)
    problems = []
    if rows is None:  # version 1: no fault record; only the actions can be replayed
        for i, row in enumerate(codes):
            if game.over[0]:
                problems.append(f"actions recorded past the end of the match: {len(codes) - i} "
                                f"frame(s) after the game was over at frame {i}")
                break
            game.step(row[None, :])
        if not game.over[0]:
            # a forfeit would explain it, but a version 1 file has nothing to verify one by
            problems.append(f"the record stops at frame {int(game.frame[0])} before the match "
                            "is over, and a version 1 replay cannot show that anyone forfeited")
        return game, None, None, problems
    limit = math.inf if replay.get("max_faults") is None else replay["max_faults"]
    startup = replay.get("startup") or [0, 0]
    fatal = replay.get("fatal") or [None, None]
    # the match's own referee, judging the recorded faults again (their messages are not
    # recorded: the logs are compared without them)
    referee = Referee(limit)
    for s in range(2):
        if startup[s]:
            referee.could_not_start(s, (FAULT_KINDS[startup[s] - 1], ""))
    played = 0
    asked = 0
    if not referee.forfeited:
        for i in range(rows.shape[0]):
            if game.over[0]:
                break
            frame = int(game.match_state[0, core.FRAME])
            asked += 1
            for s in range(2):
                code = int(rows[i, s])
                if code and i < codes.shape[0] and int(codes[i, s]) != core.NOOP:
                    problems.append(f"seat {s} has a fault at frame {i} but its recorded action "
                                    f"is {int(codes[i, s])}, not the no-op a fault plays")
                if code:
                    referee.judge(s, frame, (FAULT_KINDS[code - 1], ""), dead=fatal[s] == i)
                elif fatal[s] == i:
                    problems.append(f"seat {s} is marked as ended by a fault at frame {i}, "
                                    "where it has none")
            if referee.questions_done():
                break
            if i >= codes.shape[0]:
                problems.append(f"frame {i} has a fault record but no actions")
                break
            game.step(codes[i][None, :])
            played += 1
    if played < codes.shape[0]:
        problems.append(f"actions recorded past the end of the match: {codes.shape[0] - played} "
                        f"frame(s) after it ended at frame {played}")
    if asked < rows.shape[0]:
        problems.append(f"fault record continues past the end of the match: "
                        f"{rows.shape[0] - asked} frame(s) after it ended")
    forfeits = referee.forfeits
    for s in range(2):
        if fatal[s] is not None and not forfeits[s]:
            problems.append(f"seat {s} is marked as ended by a fault at frame {fatal[s]}, "
                            "which the match never reached")
    if not any(forfeits) and not game.over[0]:
        problems.append(f"the record stops at frame {played} before the match is over and "
                        "nobody forfeited")
    logs = [(log.counts, [_without_message(e) for e in log.examples],
             _without_message(log.last)) for log in referee.faults]
    return game, forfeits, logs, problems


def _derive(replay, game, forfeits, logs):
    """The result the match must have had, from the re-simulated game and records."""
    bots = list(replay.get("bots") or replay["result"]["bots"])
    score = [int(x) for x in game.scores[0]]
    error = game.errored(0)
    derived = {"bots": bots, "seed": replay["seed"], "rounds_asked": replay["rounds"],
               "rules": Rules.from_dict(replay["rules"]).to_dict(), "score": score,
               "rounds": game.rounds_played(0), "steps": int(game.frame[0]), "error": error}
    if forfeits is None:  # version 1: only a match played to its end can be verified
        forfeit_seat = None
    else:
        forfeit_seat = forfeits.index(True) if forfeits.count(True) == 1 else None
    if forfeit_seat is not None or (forfeits is not None and any(forfeits)):
        winner = None if forfeit_seat is None else 1 - forfeit_seat
    elif error or score[0] == score[1]:
        winner = None
    else:
        winner = 0 if score[0] > score[1] else 1
    derived.update({"winner": None if winner is None else bots[winner], "winner_seat": winner,
                    "forfeit": None if forfeit_seat is None else bots[forfeit_seat]})
    if forfeits is not None:
        derived["forfeits"] = list(forfeits)
        derived["faults"] = [{"total": sum(c.values()), **c, "examples": ex, "last": last}
                             for c, ex, last in logs]
    return derived


#: the keys of a seat's fault log that are re-derived (its other keys are listed as unchecked)
_FAULT_LOG_KEYS = ("total",) + FAULT_KINDS + ("examples", "last")


def _without_message(fault):
    if not isinstance(fault, dict):
        return fault
    return {"frame": fault.get("frame"), "kind": fault.get("kind")}


def _comparable_faults(recorded, derived):
    """The re-derivable part of recorded and derived fault logs: no messages, the same keys."""
    want, have, unchecked = [], [], []
    for s, (rec, der) in enumerate(zip(recorded, derived)):
        keys = [k for k in _FAULT_LOG_KEYS if k in rec or k != "last"]
        w = {k: rec.get(k) for k in keys}
        w["examples"] = [_without_message(ex) for ex in rec.get("examples", [])]
        if "last" in w:
            w["last"] = _without_message(w["last"])
        want.append(w)
        have.append({k: der[k] for k in keys})
        unchecked += [f"faults[{s}].{k}" for k in sorted(set(rec) - set(_FAULT_LOG_KEYS))]
    return want, have, unchecked


def check(replay):
    """Re-simulate; return ``(ok, details)`` comparing the whole result with the records.

    Every result field is re-derived from the replay alone and compared: winner, winner_seat,
    score, rounds, steps, forfeit, forfeits, error, faults, bots, seed, rounds_asked and rules,
    and the final state's SHA-256. For faults, the count of each kind, the total and the frame
    and kind of each example and of the ``last`` fault are compared; the messages (and
    ``output``) cannot be re-derived without the bots and are not (``details["unchecked"]``
    lists the result fields left uncompared). Frames recorded after the match was over (or
    after a forfeit), and a record that stops before the match ended, are mismatches too.
    Version 1 replays (no fault record) are checked without the fault comparisons, and only
    when they run to the match's end (nothing in them could verify a forfeit).
    The bots' names and the fault record cannot be re-derived without the bots: they are
    trusted when ``details["signature"]`` is ``"verified"`` (see ``signature_status``), and a
    signature that does not match is a mismatch.
    ``details["mismatches"]`` maps each differing field to ``{"recorded", "replayed"}``
    (``"record"`` lists inconsistencies of the frames themselves). A structurally invalid
    replay raises ReplayError.
    """
    validate(replay, "replay")
    game, forfeits, logs, problems = _replay_match(replay)
    recorded = replay["result"]
    derived = _derive(replay, game, forfeits, logs)
    got = {"score": derived["score"], "rounds": derived["rounds"], "steps": derived["steps"],
           "final_state_sha256": game.state_hash(0)}
    mismatches = {}
    unchecked = sorted(set(recorded) - set(derived))
    if replay["final_state_sha256"] != got["final_state_sha256"]:
        mismatches["final_state_sha256"] = {"recorded": replay["final_state_sha256"],
                                            "replayed": got["final_state_sha256"]}
    for key, value in derived.items():
        want = recorded.get(key)
        if key == "faults":
            want, value, more = _comparable_faults(want, value)
            unchecked += more
        if not _same(want, value):
            mismatches[key] = {"recorded": want, "replayed": value}
    # the top-level fields are what was simulated: they must be the result's own
    for top, key in (("seed", "seed"), ("rounds", "rounds_asked"), ("rules", "rules"),
                     ("bots", "bots")):
        if top in replay and not _same(replay[top], recorded.get(key)):
            mismatches.setdefault(key, {"recorded": recorded.get(key), "replayed": replay[top]})
    if problems:
        mismatches["record"] = {"recorded": replay["frames"], "replayed": got["steps"],
                                "problems": problems}
    signature = signature_status(replay)
    if signature == "forged":
        mismatches["signature"] = {"recorded": replay.get(SIGNATURE_FIELD),
                                   "replayed": "does not match the content with this user's key"}
    return not mismatches, {"replayed": {**got, **derived}, "mismatches": mismatches,
                            "unchecked": unchecked, "signature": signature}
