"""Replay files: ``save`` (checked, signed, written atomically) and ``load`` (bounded,
strict JSON, validated)."""
import json
import os

from engine.atomic import atomic_write, check_output_path

from spacewar.replay.format import (DIGEST_FIELD, MAX_FILE_BYTES, ReplayError, VERSION,
                                    canonical_json, digest)
from spacewar.replay.schema import validate
from spacewar.replay.signing import SIGNATURE_FIELD, sign
from spacewar.strangers_files import FileRefused, read_bounded

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
