"""Replays: seed, rules and every action of a match, as versioned JSON (never pickle).

A replay holds what is needed to re-simulate the match exactly without the bots: the rules,
the seed, the number of rounds and the action codes of both ships for every frame (base64 of
two bytes a frame), plus the recorded result and a SHA-256 of the final state. ``check``
re-simulates and confirms the identical outcome, bit for bit.
"""
import base64
import json
import os
import tempfile

import numpy as np

from . import core
from .game import Game
from .rules import Rules

FORMAT = "spacewar-replay"
VERSION = 1


class ReplayError(ValueError):
    """A replay file that cannot be read or does not describe a match."""


def make_replay(result, history, final_hash):
    return {
        "format": FORMAT,
        "version": VERSION,
        "bots": result["bots"],
        "seed": result["seed"],
        "rounds": result["rounds_asked"],
        "rules": result["rules"],
        "frames": len(history) // 2,
        "actions": base64.b64encode(history).decode("ascii"),
        "result": result,
        "final_state_sha256": final_hash,
    }


def save(path, replay):
    """Write atomically: a crash mid-write never leaves a truncated file at ``path``."""
    directory = os.path.dirname(os.path.abspath(path)) or "."
    fd, tmp = tempfile.mkstemp(prefix=".replay-", suffix=".json", dir=directory)
    try:
        with os.fdopen(fd, "w") as f:
            json.dump(replay, f, separators=(",", ":"), sort_keys=True)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def load(path):
    """Read and validate a replay file (JSON only: nothing in it is executed)."""
    try:
        with open(path) as f:
            data = json.load(f)
    except OSError as exc:
        raise ReplayError(f"cannot read replay {path!r}: {exc}") from exc
    except json.JSONDecodeError as exc:
        raise ReplayError(f"{path!r} is not a JSON replay: {exc}") from exc
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise ReplayError(f"{path!r} is not a spacewar replay (format field missing or wrong)")
    if data.get("version") != VERSION:
        raise ReplayError(f"{path!r} has replay version {data.get('version')!r}; "
                          f"this program reads version {VERSION}")
    for key in ("seed", "rounds", "rules", "frames", "actions", "result"):
        if key not in data:
            raise ReplayError(f"{path!r} lacks the field {key!r}")
    codes = actions(data)
    if codes.shape[0] != data["frames"]:
        raise ReplayError(f"{path!r}: {codes.shape[0]} frames of actions but frames = {data['frames']}")
    if codes.size and codes.max() >= core.N_ACTIONS:
        raise ReplayError(f"{path!r}: action code {int(codes.max())} out of range")
    return data


def actions(replay):
    """The (frames, 2) array of action codes of a replay."""
    try:
        raw = base64.b64decode(replay["actions"], validate=True)
    except (ValueError, TypeError) as exc:
        raise ReplayError(f"replay actions are not valid base64: {exc}") from exc
    if len(raw) % 2:
        raise ReplayError("replay actions have an odd number of bytes")
    return np.frombuffer(raw, dtype=np.uint8).reshape(-1, 2).astype(np.int64)


def simulate(replay, on_frame=None):
    """Re-run a replay's frames; return the Game at the end."""
    try:
        rules = Rules.from_dict(replay["rules"])
    except (TypeError, ValueError) as exc:
        raise ReplayError(f"replay rules are invalid: {exc}") from exc
    game = Game(rules, seeds=[replay["seed"]], rounds=replay["rounds"])
    if on_frame is not None:
        on_frame(game)
    for row in actions(replay):
        game.step(row[None, :])
        if on_frame is not None:
            on_frame(game)
    return game


def check(replay):
    """Re-simulate; return ``(ok, details)`` comparing score, rounds, frames and final state."""
    game = simulate(replay)
    recorded = replay["result"]
    got = {"score": [int(x) for x in game.scores[0]], "rounds": game.rounds_played(0),
           "steps": int(game.frame[0]), "final_state_sha256": game.state_hash(0)}
    want = {"score": recorded["score"], "rounds": recorded["rounds"], "steps": recorded["steps"],
            "final_state_sha256": replay.get("final_state_sha256")}
    mismatches = {k: {"recorded": want[k], "replayed": got[k]} for k in got if got[k] != want[k]}
    return not mismatches, {"replayed": got, "mismatches": mismatches}
