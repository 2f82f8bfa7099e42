"""Replays: seed, rules and every action of a match, as versioned JSON (never pickle).

A replay holds what is needed to re-simulate the match exactly without the bots: the rules,
the seed, the number of rounds and the action codes of both ships for every frame played
(``actions``: base64 of two bytes a frame), the per-frame fault record (``faults``: base64 of
one byte per seat for every frame the bots were asked, the fault kind code, 0 = none), the
``max_faults`` of the match, the recorded result and a SHA-256 of the final state.

Version 2 (written now) adds ``faults``, ``max_faults``, ``startup`` (the kind code of a
seat's start-up failure, 0 = none), ``fatal`` (per seat, the frame whose fault ended the bot
regardless of its count: it died, hung or broke the protocol; ``null`` = never) and
``content_sha256``: a SHA-256 of the file's canonical JSON (sorted keys, compact separators,
that field left out), written by ``save`` and verified by ``load``, so any edit of a saved
file is detected. Version 1 files are still read and checked, without the checks that need
the new fields (faults, forfeits).

``check`` re-simulates and re-derives the whole recorded result from the replay alone:
winner, winner_seat, score, rounds, steps, forfeit, forfeits, error, the fault counts of each
kind per seat and the frame and kind of each fault example, bots, seed, rounds_asked and
rules, plus the final state bit for bit; frames recorded after the match was over are
refused. The fault *messages* (and the bots' captured ``output``) cannot be re-derived without
the bots and are not compared.
"""
import base64
import binascii
import hashlib
import hmac
import json
import math
import os
import secrets

import numpy as np

from engine.atomic import atomic_write, check_output_path

from . import core
from .game import Game
from .rules import Rules
from .faults import FAULT_KINDS
from .referee import Referee
from .strangers_files import FileRefused, read_bounded

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

_TOP_V1 = ("seed", "rounds", "rules", "frames", "actions", "result", "final_state_sha256")
_TOP_V2 = _TOP_V1 + ("bots", "faults", "max_faults", "startup", "fatal")
_RESULT_V1 = ("bots", "winner", "winner_seat", "score", "rounds", "steps", "forfeit", "error",
              "faults", "seed", "rounds_asked", "rules")
_RESULT_V2 = _RESULT_V1 + ("forfeits",)
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


# -- signing ----------------------------------------------------------------------------------
SIGNATURE_FIELD = "signature"


def key_path():
    """The file of this user's replay-signing key: ``$SPACEWAR_REPLAY_KEY_FILE``, else
    ``$XDG_CONFIG_HOME/spacewar/replay-key`` (``~/.config``)."""
    explicit = os.environ.get("SPACEWAR_REPLAY_KEY_FILE")
    if explicit:
        return explicit
    base = os.environ.get("XDG_CONFIG_HOME") or os.path.join(os.path.expanduser("~"), ".config")
    return os.path.join(base, "spacewar", "replay-key")


def _key(create):
    """This user's 32-byte signing key (made on first use, mode 0600), or None."""
    path = key_path()
    try:
        with open(path) as f:
            return bytes.fromhex(f.read().strip())
    except FileNotFoundError:
        if not create:
            return None
    except (OSError, ValueError) as exc:
        raise ReplayError(f"the replay-signing key {path!r} is unreadable: {exc}") from None
    os.makedirs(os.path.dirname(path) or ".", mode=0o700, exist_ok=True)
    key = secrets.token_bytes(32)
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except FileExistsError:  # made meanwhile by another process: use that one
        return _key(create=False)
    with os.fdopen(fd, "w") as f:
        f.write(key.hex() + "\n")
    return key


def _key_id(key):
    return hashlib.sha256(b"spacewar replay key " + key).hexdigest()[:16]


def _mac(key, replay):
    body = {k: v for k, v in replay.items() if k not in (DIGEST_FIELD, SIGNATURE_FIELD)}
    return hmac.new(key, canonical_json(body).encode("ascii"), hashlib.sha256).hexdigest()


def sign(document):
    """The ``signature`` field for ``document`` (a dict of plain JSON data: a replay, or a
    league's results file; its own ``signature`` and ``content_sha256`` fields are left out):
    an HMAC-SHA256 of its canonical JSON with this user's key (``key_path()``, made on first
    use). ``signature_status`` checks it. TypeError or ValueError if it is not plain data."""
    key = _key(create=True)
    return {"key": _key_id(key), "hmac_sha256": _mac(key, document)}


def signature_status(replay):
    """``"verified"`` (signed with this user's key and unchanged since), ``"unsigned"``,
    ``"other key"`` (signed elsewhere: cannot be verified here) or ``"forged"``, for a replay
    or any document signed by ``sign``.

    The content digest catches accidents, but anyone can recompute it; the signature is an
    HMAC-SHA256 with a key only its owner has, so records the simulation cannot re-derive
    (which bot sat where, the fault record) are trustworthy only when it verifies.
    """
    sig = replay.get(SIGNATURE_FIELD)
    if sig is None:
        return "unsigned"
    if not isinstance(sig, dict) or not isinstance(sig.get("key"), str) \
            or not isinstance(sig.get("hmac_sha256"), str):
        return "forged"
    key = _key(create=False)
    if key is None or sig["key"] != _key_id(key):
        return "other key"
    return "verified" if hmac.compare_digest(sig["hmac_sha256"], _mac(key, replay)) else "forged"


def save(path, replay):
    """Check ``replay``, sign it, add its content digest and write it atomically to ``path``.

    The signature is an HMAC-SHA256 of the canonical content with this user's key
    (``key_path()``, made on first use); see ``signature_status``.

    The path is checked first (``engine.atomic.check_output_path(path, "replay")``: an
    existing file there must be a replay or empty) and the file is written with
    ``engine.atomic.atomic_write``: a crash mid-write never leaves a truncated file at
    ``path``, and the file gets the usual mode ``0o666 & ~umask``.
    """
    if not isinstance(replay, dict):
        raise ReplayError(f"a replay must be a dict, got {type(replay).__name__}")
    data = {k: v for k, v in replay.items() if k not in (DIGEST_FIELD, SIGNATURE_FIELD)}
    data["version"] = data.get("version", VERSION)
    if data["version"] == VERSION:
        path = check_output_path(path, "replay")  # before a key is made for it
        try:
            data[SIGNATURE_FIELD] = sign(data)
        except ReplayError:  # an unreadable key: its own message
            raise
        except (TypeError, ValueError) as exc:
            raise ReplayError(f"replay to save is not plain JSON data: {exc}") from None
        data[DIGEST_FIELD] = digest(data)
    validate(data, "replay to save", require_digest=data["version"] >= 2)
    try:
        text = canonical_json(data)
    except (TypeError, ValueError) as exc:
        raise ReplayError(f"replay to save is not plain JSON data: {exc}") from None
    path = check_output_path(path, "replay")
    atomic_write(path, text)
    return path


# -- loading and validating -------------------------------------------------------------------
def _reject_constant(name):
    raise ValueError(f"non-standard JSON constant {name}")


def load(path):
    """Read and validate a replay file (JSON only: nothing in it is executed).

    Any malformed content (not JSON, nested too deep, numbers too long or out of range, fields
    of the wrong type, a version-2 file whose content digest does not match) raises
    ReplayError with a message naming the problem; never another exception.
    """
    shown = os.fspath(path) if isinstance(path, (str, bytes, os.PathLike)) else path
    raw = _read_replay_bytes(path, shown)
    _check_structure(raw, shown)
    try:
        data = json.loads(raw, parse_constant=_reject_constant)
    except RecursionError:
        raise ReplayError(f"{shown!r} is not a JSON replay: nested too deeply") from None
    except (ValueError, TypeError) as exc:  # JSONDecodeError, int digit limit, bad UTF-8
        raise ReplayError(f"{shown!r} is not a JSON replay: {exc}") from None
    return validate(data, repr(shown), require_digest=True)


def _read_replay_bytes(path, shown):
    """The bytes of the replay file at ``path``: a regular file (a FIFO would block ``open``
    for ever, a device never end), opened without blocking and checked by ``fstat`` on the
    descriptor it is then read from, of at most ``MAX_FILE_BYTES`` (a replay holds about 6
    bytes a frame: 64 MiB is over 10 million frames, far beyond any match)."""
    try:
        return read_bounded(path, MAX_FILE_BYTES)
    except FileRefused as exc:
        raise ReplayError({
            "not regular": f"cannot read replay {shown!r}: not a regular file (a replay is a "
                           "JSON file; pipes and devices are refused)",
            "too large": f"{shown!r} has {exc.size} bytes, over the {MAX_FILE_BYTES} a replay "
                         "may have: not a replay",
            "grew": f"{shown!r} is larger than {MAX_FILE_BYTES} bytes: not a replay",
        }[exc.reason]) from None
    except (OSError, TypeError, ValueError) as exc:
        raise ReplayError(f"cannot read replay {shown!r}: {exc}") from None


#: the JSON values a replay may hold, bounded by counting the characters that open or
#: separate them. A replay holds a few hundred (a 3-round match: 10 '[', 9 '{', 125 ','); its
#: texts (fault messages, bots' output), where these characters may also stand, are capped at
#: about 13,000 characters in all. A file of the same size made of tiny values parses into
#: far more memory than its bytes: 60 MiB of '[],' is 21 million lists (+1.5 GiB measured).
MAX_JSON_VALUES = 1 << 16


def _check_structure(raw, shown):
    """Refuse, before parsing, a file that could hold more than ``MAX_JSON_VALUES`` JSON
    values: every value but the first follows a ',' or opens with '[' or '{', and counting
    those bytes reads the file once, allocating nothing. The memory json.loads then takes
    is about the file's bytes plus a few MiB."""
    openers = raw.count(b"[") + raw.count(b"{") + raw.count(b",")
    if openers > MAX_JSON_VALUES:
        raise ReplayError(f"{shown!r} could hold {openers} JSON values, over the "
                          f"{MAX_JSON_VALUES} a replay may have: not a replay")


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
    for key in _TOP_V2 if version >= 2 else _TOP_V1:
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
    _rules(source, "rules", data["rules"])
    if not isinstance(data["actions"], str):
        _fail(source, f"actions must be a base64 string, got {type(data['actions']).__name__}")
    _hash(source, "final_state_sha256", data["final_state_sha256"])
    codes = _codes(source, "actions", data["actions"])
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
    rows = _codes(source, "faults", data["faults"])
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


def _rules(source, name, value):
    if not isinstance(value, dict):
        _fail(source, f"{name} must be a dict of rules fields, got {_short(value)} "
                      f"({type(value).__name__})")
    if not all(isinstance(k, str) for k in value):
        _fail(source, f"{name} has a non-string key")
    try:
        return Rules.from_dict(value)
    except Exception as exc:  # any bad field, whatever Rules raises for it, is a bad replay
        raise ReplayError(f"{source}: {name} are invalid: {exc}") from None


def _codes(source, name, text):
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
    for key in _RESULT_V2 if version >= 2 else _RESULT_V1:
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
    _rules(where, "rules", result["rules"])
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


# -- reading the records ----------------------------------------------------------------------
def actions(replay):
    """The (frames, 2) array of action codes of a replay."""
    text = replay["actions"]
    if not isinstance(text, str):
        raise ReplayError(f"replay actions must be a base64 string, got {type(text).__name__}")
    return _codes("replay", "actions", text)


def fault_record(replay):
    """The (frames asked, 2) array of fault kind codes (0 = none), or None (version 1)."""
    text = replay.get("faults")
    if text is None:
        return None
    if not isinstance(text, str):
        raise ReplayError(f"replay faults must be a base64 string, got {type(text).__name__}")
    return _codes("replay", "faults", text)


def _game(replay):
    rules = _rules("replay", "rules", replay["rules"])
    try:
        return Game(rules, seeds=[replay["seed"]], rounds=replay["rounds"])
    except (TypeError, ValueError, OverflowError) as exc:
        raise ReplayError(f"replay seed or rounds are invalid: {exc}") from None


def simulate(replay, on_frame=None):
    """Re-run a replay's frames; return the Game at the end.

    Raises ReplayError if actions are recorded after the match was over.
    """
    game = _game(replay)
    if on_frame is not None:
        on_frame(game)
    for i, row in enumerate(actions(replay)):
        if game.over[0]:
            raise ReplayError(f"replay has actions recorded past the end of the match: frame "
                              f"{i} of {replay['frames']} comes after the game was over")
        game.step(row[None, :])
        if on_frame is not None:
            on_frame(game)
    return game


# -- checking ---------------------------------------------------------------------------------
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
    game = _game(replay)
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


__all__ = ["FORMAT", "VERSION", "FAULT_KINDS", "ReplayError", "make_replay", "save", "load",
           "validate", "check", "simulate", "actions", "fault_record", "digest",
           "canonical_json", "signature_status", "key_path", "SIGNATURE_FIELD"]
