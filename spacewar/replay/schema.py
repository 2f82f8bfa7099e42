"""What a replay must hold: ``validate`` and the checks of each field, naming the field and
the value that fail."""
import base64
import binascii

import numpy as np

from spacewar.game import core
from spacewar.faults import FAULT_KINDS
from spacewar.rules import Rules
from spacewar.replay.format import (DIGEST_FIELD, FORMAT, MAX_COUNT, MAX_FAULTS, MAX_ROUNDS, MAX_SEED,
                     READABLE_VERSIONS, RESULT_V1, RESULT_V2, ReplayError, TOP_V1, TOP_V2, digest)

def _fail(source, message):
    raise ReplayError(f"{source}: {message}")


def _is_int(value):
    return isinstance(value, int) and not isinstance(value, bool)


def _int(source, name, value, low, high):
    if not _is_int(value):
        _fail(source, f"{name} must be an int, got {_short(value)} ({type(value).__name__})")
    if not low <= value <= high:
        _fail(source, f"{name} must be in [{low}, {high}], got {_short(value)}")
    return value


def _short(value, limit=80):
    text = repr(value) if not _is_int(value) or value.bit_length() < 200 else \
        f"an int of {len(str(abs(value))) if value.bit_length() < 14000 else 'thousands of'} digits"
    return text if len(text) <= limit else text[:limit] + "..."


def _pair(source, name, value, check):
    if not isinstance(value, list) or len(value) != 2:
        _fail(source, f"{name} must be a list of two entries (one per seat), got {_short(value)}")
    for s, item in enumerate(value):
        check(f"{name}[{s}]", item)
    return value


def validate(data, source="replay", require_digest=False):
    """Check the structure and types of a replay dict; return it or raise ReplayError.

    ``require_digest`` (as ``load`` does for files): a version-2 replay must carry its
    ``content_sha256`` and match it. An in-memory replay (``make_replay``) has none yet.
    """
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        _fail(source, "not a spacewar replay (format field missing or wrong)")
    version = data.get("version")
    if not _is_int(version) or version not in READABLE_VERSIONS:
        _fail(source, f"has replay version {_short(version)}; this program reads versions "
                      f"{', '.join(map(str, READABLE_VERSIONS))}")
    for key in TOP_V2 if version >= 2 else TOP_V1:
        if key not in data:
            _fail(source, f"lacks the field {key!r}")
    if version >= 2 and require_digest:
        if DIGEST_FIELD not in data:
            _fail(source, f"lacks the field {DIGEST_FIELD!r}")
        want = data[DIGEST_FIELD]
        try:
            have = digest(data)
        except (TypeError, ValueError, RecursionError) as exc:
            raise ReplayError(f"{source}: not plain JSON data: {exc}") from None
        if not isinstance(want, str) or want != have:
            _fail(source, f"content does not match its {DIGEST_FIELD} (the file was edited or "
                          "damaged after it was written)")
    _int(source, "seed", data["seed"], 0, MAX_SEED)
    _int(source, "rounds", data["rounds"], 1, MAX_ROUNDS)
    _int(source, "frames", data["frames"], 0, MAX_COUNT)
    checked_rules(source, "rules", data["rules"])
    if not isinstance(data["actions"], str):
        _fail(source, f"actions must be a base64 string, got {type(data['actions']).__name__}")
    _hash(source, "final_state_sha256", data["final_state_sha256"])
    codes = decode_codes(source, "actions", data["actions"])
    if codes.shape[0] != data["frames"]:
        _fail(source, f"{codes.shape[0]} frames of actions but frames = {data['frames']}")
    if codes.size and codes.max() >= core.N_ACTIONS:
        _fail(source, f"action code {int(codes.max())} out of range [0, {core.N_ACTIONS})")
    if version >= 2:
        _validate_v2(source, data, codes.shape[0])
    elif "bots" in data:
        _pair(source, "bots", data["bots"], lambda n, v: _str(source, n, v))
    _result(source, data["result"], version)
    return data


def _validate_v2(source, data, frames):
    _pair(source, "bots", data["bots"], lambda n, v: _str(source, n, v))
    if data["max_faults"] is not None:
        _int(source, "max_faults", data["max_faults"], 1, MAX_FAULTS)
    if not isinstance(data["faults"], str):
        _fail(source, f"faults must be a base64 string, got {type(data['faults']).__name__}")
    rows = decode_codes(source, "faults", data["faults"])
    if rows.size and rows.max() > len(FAULT_KINDS):
        _fail(source, f"fault code {int(rows.max())} out of range [0, {len(FAULT_KINDS)}]")
    if rows.shape[0] not in (frames, frames + 1):
        _fail(source, f"{rows.shape[0]} frames of fault record for {frames} frames of actions "
                      "(there is one per frame played, and one more when a forfeit ended it)")
    _pair(source, "startup", data["startup"],
          lambda n, v: _int(source, n, v, 0, len(FAULT_KINDS)))
    _pair(source, "fatal", data["fatal"],
          lambda n, v: v is None or _int(source, n, v, 0, max(rows.shape[0] - 1, 0)))


def _str(source, name, value, allow_none=False):
    if value is None and allow_none:
        return value
    if not isinstance(value, str):
        _fail(source, f"{name} must be a string{' or null' if allow_none else ''}, got "
                      f"{_short(value)}")
    return value


def _hash(source, name, value):
    if not (isinstance(value, str) and len(value) == 64
            and all(c in "0123456789abcdef" for c in value)):
        _fail(source, f"{name} must be 64 lowercase hex digits, got {_short(value)}")


def checked_rules(source, name, value):
    if not isinstance(value, dict):
        _fail(source, f"{name} must be a dict of rules fields, got {_short(value)} "
                      f"({type(value).__name__})")
    if not all(isinstance(k, str) for k in value):
        _fail(source, f"{name} has a non-string key")
    try:
        return Rules.from_dict(value)
    except Exception as exc:  # any bad field, whatever Rules raises for it, is a bad replay
        raise ReplayError(f"{source}: {name} are invalid: {exc}") from None


def decode_codes(source, name, text):
    try:
        raw = base64.b64decode(text.encode("ascii"), validate=True)
    except (ValueError, binascii.Error, UnicodeEncodeError) as exc:
        raise ReplayError(f"{source}: replay {name} are not valid base64: {exc}") from None
    if len(raw) % 2:
        _fail(source, f"replay {name} have an odd number of bytes")
    return np.frombuffer(raw, dtype=np.uint8).reshape(-1, 2).astype(np.int64)


def _result(source, result, version):
    if not isinstance(result, dict):
        _fail(source, f"result must be a dict, got {_short(result)} ({type(result).__name__})")
    for key in RESULT_V2 if version >= 2 else RESULT_V1:
        if key not in result:
            _fail(source, f"result lacks the field {key!r}")
    where = source + ": result"
    _pair(where, "bots", result["bots"], lambda n, v: _str(where, n, v))
    _str(where, "winner", result["winner"], allow_none=True)
    if result["winner_seat"] is not None:
        _int(where, "winner_seat", result["winner_seat"], 0, 1)
    _pair(where, "score", result["score"], lambda n, v: _int(where, n, v, 0, MAX_COUNT))
    _int(where, "rounds", result["rounds"], 0, MAX_COUNT)
    _int(where, "steps", result["steps"], 0, MAX_COUNT)
    _str(where, "forfeit", result["forfeit"], allow_none=True)
    if not isinstance(result["error"], bool):
        _fail(where, f"error must be true or false, got {_short(result['error'])}")
    if "forfeits" in result:
        def boolean(n, v):
            if not isinstance(v, bool):
                _fail(where, f"{n} must be true or false, got {_short(v)}")
        _pair(where, "forfeits", result["forfeits"], boolean)
    _pair(where, "faults", result["faults"], lambda n, v: _fault_log(where, n, v, version))
    _int(where, "seed", result["seed"], 0, MAX_SEED)
    _int(where, "rounds_asked", result["rounds_asked"], 1, MAX_ROUNDS)
    checked_rules(where, "rules", result["rules"])
    if "output" in result and not isinstance(result["output"], list):
        _fail(where, f"output must be a list, got {_short(result['output'])}")


def _fault_log(source, name, log, version):
    if not isinstance(log, dict):
        _fail(source, f"{name} must be a dict of fault counts, got {_short(log)}")
    required = ("total", "examples") + (FAULT_KINDS if version >= 2 else ())
    for key in required:
        if key not in log:
            _fail(source, f"{name} lacks the field {key!r}")
    _int(source, f"{name}.total", log["total"], 0, MAX_COUNT)
    for kind in FAULT_KINDS:
        if kind in log:
            _int(source, f"{name}.{kind}", log[kind], 0, MAX_COUNT)
    examples = log["examples"]
    if not isinstance(examples, list):
        _fail(source, f"{name}.examples must be a list, got {_short(examples)}")
    for k, ex in enumerate(examples):
        _fault(source, f"{name}.examples[{k}]", ex)
    if log.get("last") is not None:
        _fault(source, f"{name}.last", log["last"])


def _fault(source, name, ex):
    if not isinstance(ex, dict):
        _fail(source, f"{name} must be a dict, got {_short(ex)}")
    for key in ("frame", "kind", "message"):
        if key not in ex:
            _fail(source, f"{name} lacks the field {key!r}")
    _int(source, f"{name}.frame", ex["frame"], 0, MAX_COUNT)
    if ex["kind"] not in FAULT_KINDS:
        _fail(source, f"{name}.kind must be one of {', '.join(FAULT_KINDS)}, "
                      f"got {_short(ex['kind'])}")
    _str(source, f"{name}.message", ex["message"])
