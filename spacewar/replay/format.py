"""The replay format: its fields and limits, ``make_replay`` (a match's records as a replay
dict), and its canonical JSON and digest."""
import base64
import hashlib
import json
import math

import numpy as np

from spacewar.faults import FAULT_KINDS

FORMAT = "spacewar-replay"
VERSION = 2
READABLE_VERSIONS = (1, 2)
DIGEST_FIELD = "content_sha256"
# fault kinds in code order (spacewar.faults.FAULT_KINDS): code k (1..6) is FAULT_KINDS[k - 1];
# 0 means no fault
MAX_FILE_BYTES = 64 * 1024 * 1024
MAX_SEED = 2 ** 64 - 1
MAX_ROUNDS = 2 ** 31 - 1
MAX_FAULTS = 2 ** 31 - 1
MAX_COUNT = 2 ** 53  # frames, scores and fault counts: far beyond any real match

TOP_V1 = ("seed", "rounds", "rules", "frames", "actions", "result", "final_state_sha256")
TOP_V2 = TOP_V1 + ("bots", "faults", "max_faults", "startup", "fatal")
RESULT_V1 = ("bots", "winner", "winner_seat", "score", "rounds", "steps", "forfeit", "error",
              "faults", "seed", "rounds_asked", "rules")
RESULT_V2 = RESULT_V1 + ("forfeits",)
#: result fields ``check`` cannot re-derive (they depend on the bots' processes)
UNCHECKED_RESULT_FIELDS = ("output",)


class ReplayError(ValueError):
    """A replay file that cannot be read or does not describe a match."""


# -- making and saving --------------------------------------------------------------------------
def _bytes(name, value):
    if value is None:
        return None
    if not isinstance(value, (bytes, bytearray, memoryview)):
        raise TypeError(f"{name} must be bytes, got {type(value).__name__}")
    return bytes(value)


def make_replay(result, history, final_hash, *, faults=None, max_faults=None, startup=None,
                fatal=None):
    """The replay dict of a match (version 2).

    ``history``: two action-code bytes per frame played. ``faults``: two fault-kind bytes
    (code 1 + ``FAULT_KINDS.index(kind)``, 0 = none) per frame the bots were asked, which is
    one more than the frames played when the match stopped on a forfeit; ``None`` means no
    fault happened. ``max_faults``: the match's limit (a seat whose fault count reaches it
    forfeits; ``None``: unknown, never by count). ``startup``: per seat the kind code of a
    start-up failure (0 = none) and ``fatal``: per seat the frame whose fault ended that bot
    (it died, hung, broke the protocol), or None. When ``startup`` / ``fatal`` are not given
    they are inferred from ``result["forfeits"]``: a forfeit that the counts do not explain
    came from a fatal fault in the last frame asked (or at start-up when none was asked).
    """
    history = _bytes("history", history)
    faults = _bytes("faults", faults)
    frames = len(history) // 2
    if faults is None:
        faults = bytes(2 * frames)
    rows = np.frombuffer(faults[: len(faults) - len(faults) % 2], dtype=np.uint8).reshape(-1, 2)
    inferred_startup, inferred_fatal = _infer_fatal(result, rows, max_faults)
    return {
        "format": FORMAT,
        "version": VERSION,
        "bots": result["bots"],
        "seed": result["seed"],
        "rounds": result["rounds_asked"],
        "rules": result["rules"],
        "frames": frames,
        "actions": base64.b64encode(history).decode("ascii"),
        "faults": base64.b64encode(faults).decode("ascii"),
        "max_faults": max_faults,
        "startup": list(inferred_startup if startup is None else startup),
        "fatal": list(inferred_fatal if fatal is None else fatal),
        "result": result,
        "final_state_sha256": final_hash,
    }


def _infer_fatal(result, rows, max_faults):
    """``(startup, fatal)`` explaining the recorded forfeits that fault counts do not."""
    startup, fatal = [0, 0], [None, None]
    forfeits = result.get("forfeits") if isinstance(result, dict) else None
    if not (isinstance(forfeits, list) and len(forfeits) == 2):
        return startup, fatal
    limit = math.inf if max_faults is None else max_faults
    totals = [0, 0]
    for s in range(2):
        if not forfeits[s]:
            continue
        if rows.shape[0] == 0:
            kind = "startup"
            try:
                kind = result["faults"][s]["examples"][0]["kind"]
            except (KeyError, IndexError, TypeError):
                pass
            startup[s] = 1 + FAULT_KINDS.index(kind) if kind in FAULT_KINDS else 5
            continue
        totals[s] = int(np.count_nonzero(rows[:, s]))
        if totals[s] < limit and rows[-1, s] != 0:
            fatal[s] = int(rows.shape[0] - 1)
    return startup, fatal


def canonical_json(data):
    """The canonical JSON text of ``data``: sorted keys, compact separators, ASCII, no NaN."""
    return json.dumps(data, sort_keys=True, separators=(",", ":"), ensure_ascii=True,
                      allow_nan=False)


def digest(replay):
    """SHA-256 (hex) of the replay's canonical JSON without its ``content_sha256`` field."""
    body = {k: v for k, v in replay.items() if k != DIGEST_FIELD}
    return hashlib.sha256(canonical_json(body).encode("ascii")).hexdigest()
