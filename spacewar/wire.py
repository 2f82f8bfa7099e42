"""The wire between a match and a bot's own process: fixed-layout binary messages, no pickle.

Every message starts with a 4-byte magic and has a fixed-size header (little-endian,
``struct`` formats below); the only variable parts are a length-prefixed payload whose
length the reader checks against a cap before reading it. The match never evaluates anything
the bot sends: it unpacks integers and bytes, checks each field, and treats anything else as
a fault of that bot.

match -> bot
  START   ``SWS1`` u32 length, then that many bytes of UTF-8 JSON (the bot's configuration)
  OBSERVE ``SWO1`` i64 frame, u32 count, then count float64 (``spacewar.protocol.raw_layout``)
  BATCH   ``SWB1`` i64 call, u32 rows, u32 width, then rows x width float32 (a batch bot's
          learning observations, ``spacewar.game.features.learning_layout``, one row per match)
  STOP    ``SWQ1`` i64 0, u32 0

bot -> match
  ANSWER  ``SWA1`` i64 frame, u8 status, u8 action code, u16 text length, then the text
          (UTF-8, at most ``MAX_TEXT`` bytes; an error message or nothing)
  CODES   ``SWC1`` i64 call, u8 status, u8 0, u16 text length, u32 rows, then one u8 action
          code per row, then the text (a batch bot's answer to BATCH)

A bot process is started for one kind of play: ANSWER to OBSERVE (one match), or CODES to
BATCH (``rows`` matches at once, the same count every call). Its start-up is answered with
ANSWER either way.

Statuses: READY (start-up done, frame -1), OK (the code is the action), RAISED (act raised;
the text is the message), INVALID (act returned something that is not an Action), STARTUP
(loading, constructing or resetting failed), MEMORY (the bot ran out of memory).
"""
import json
import struct

import numpy as np


START_MAGIC, OBSERVE_MAGIC, STOP_MAGIC, ANSWER_MAGIC = b"SWS1", b"SWO1", b"SWQ1", b"SWA1"
BATCH_MAGIC, CODES_MAGIC = b"SWB1", b"SWC1"
START_HEADER = struct.Struct("<4sI")
OBSERVE_HEADER = struct.Struct("<4sqI")
ANSWER_HEADER = struct.Struct("<4sqBBH")
BATCH_HEADER = struct.Struct("<4sqII")
CODES_HEADER = struct.Struct("<4sqBBHI")

READY, OK, RAISED, INVALID, STARTUP, MEMORY = range(6)
STATUS_NAMES = {READY: "ready", OK: "ok", RAISED: "raised", INVALID: "invalid",
                STARTUP: "startup", MEMORY: "memory"}
MAX_TEXT = 1024
MAX_START = 1 << 16
MAX_FLOATS = 1 << 12
MAX_ROWS = 1 << 12  # matches a confined batch bot answers for at once
MAX_BATCH_FLOATS = 1 << 22  # 16 MiB of float32 observations


class WireError(ValueError):
    """A message that breaks the protocol (the sender is at fault)."""


# -- match -> bot ---------------------------------------------------------------------------
def pack_start(config):
    data = json.dumps(config, sort_keys=True).encode()
    if len(data) > MAX_START:
        raise WireError(f"start message of {len(data)} bytes exceeds {MAX_START}")
    return START_HEADER.pack(START_MAGIC, len(data)) + data


def pack_observe(frame, raw):
    raw = np.ascontiguousarray(raw, dtype="<f8")
    return OBSERVE_HEADER.pack(OBSERVE_MAGIC, int(frame), raw.size) + raw.tobytes()


def pack_batch(call, obs):
    """The BATCH message of ``obs``, (rows, width) learning observations."""
    obs = np.ascontiguousarray(obs, dtype="<f4")
    rows, width = obs.shape
    if not 1 <= rows <= MAX_ROWS or rows * width > MAX_BATCH_FLOATS:
        raise WireError(f"a batch of {rows} x {width} observations exceeds the wire's caps "
                        f"({MAX_ROWS} rows, {MAX_BATCH_FLOATS} floats)")
    return BATCH_HEADER.pack(BATCH_MAGIC, int(call), rows, width) + obs.tobytes()


def pack_stop():
    return OBSERVE_HEADER.pack(STOP_MAGIC, 0, 0)


def read_start(read_exact):
    """The configuration dict; ``read_exact(n)`` returns exactly n bytes or raises EOFError."""
    magic, length = START_HEADER.unpack(read_exact(START_HEADER.size))
    if magic != START_MAGIC or length > MAX_START:
        raise WireError("bad start message")
    return json.loads(read_exact(length).decode())


def read_observe(read_exact):
    """``(frame, raw)`` for an observation, or ``None`` for STOP."""
    magic, frame, count = OBSERVE_HEADER.unpack(read_exact(OBSERVE_HEADER.size))
    if magic == STOP_MAGIC:
        return None
    if magic != OBSERVE_MAGIC or count > MAX_FLOATS:
        raise WireError("bad observe message")
    return frame, np.frombuffer(read_exact(8 * count), dtype="<f8").astype(np.float64)


def read_batch(read_exact):
    """``(call, obs)`` for a BATCH message, ``obs`` a (rows, width) float32 array, or ``None``
    for STOP."""
    head = read_exact(OBSERVE_HEADER.size)
    if head[:4] == STOP_MAGIC:
        return None
    magic, call, rows, width = BATCH_HEADER.unpack(head + read_exact(BATCH_HEADER.size
                                                                     - OBSERVE_HEADER.size))
    if magic != BATCH_MAGIC or not 1 <= rows <= MAX_ROWS or rows * width > MAX_BATCH_FLOATS:
        raise WireError("bad batch message")
    data = read_exact(4 * rows * width)
    return call, np.frombuffer(data, dtype="<f4").astype(np.float32).reshape(rows, width)


# -- bot -> match ---------------------------------------------------------------------------
def exception_text(exc):
    """``Kind: message`` of an exception, capped at ``MAX_TEXT``, even when its ``__str__``
    misbehaves (a bot's exception is the bot's code)."""
    try:
        text = f"{type(exc).__name__}: {exc}"
    except BaseException:
        text = f"{type(exc).__name__} (its message could not be shown)"
    return text[:MAX_TEXT]


def pack_answer(frame, status, code=0, text=""):
    data = text.encode("utf-8", "replace")[:MAX_TEXT]
    return ANSWER_HEADER.pack(ANSWER_MAGIC, int(frame), int(status), int(code), len(data)) + data


def pack_codes(call, status, codes=b"", text=""):
    """The CODES message: ``codes`` one action code (0..255) per row."""
    data = text.encode("utf-8", "replace")[:MAX_TEXT]
    codes = codes if isinstance(codes, bytes) else np.asarray(codes, dtype=np.uint8).tobytes()
    return (CODES_HEADER.pack(CODES_MAGIC, int(call), int(status), 0, len(data), len(codes))
            + codes + data)


class AnswerReader:
    """Parses answers out of the bytes a bot sends, however they arrive in pieces.

    ``feed(data)`` adds bytes; ``next()`` returns ``(frame, status, code, text)`` for each
    complete answer, ``None`` when more bytes are needed, and raises ``WireError`` as soon as
    the stream cannot be an answer (wrong magic, unknown status, text over the cap).

    With ``rows`` set (a batch bot in play) it reads CODES instead: ``next()`` returns
    ``(call, status, codes, text)``, ``codes`` the bytes of exactly ``rows`` action codes
    when the status is OK, and none otherwise (any other count: ``_check_code_count``).
    """

    def __init__(self, rows=None):
        self.buffer = bytearray()
        self.rows = rows

    def feed(self, data):
        self.buffer += data
        if self.rows is None:
            most = ANSWER_HEADER.size + MAX_TEXT + 64
        else:
            most = CODES_HEADER.size + self.rows + MAX_TEXT + 64
        if len(self.buffer) > most:
            # more than one outstanding answer is never legitimate: the match asks one at a time
            raise WireError(f"bot sent {len(self.buffer)} bytes without being asked")

    def next(self):
        magic_expected = ANSWER_MAGIC if self.rows is None else CODES_MAGIC
        header = ANSWER_HEADER if self.rows is None else CODES_HEADER
        if len(self.buffer) < header.size:
            if self.buffer and not magic_expected.startswith(bytes(self.buffer[:4])):
                raise WireError("answer does not start with the protocol's magic")
            return None
        if self.rows is None:
            magic, frame, status, code, length = header.unpack_from(self.buffer)
            count = 0
        else:
            magic, frame, status, _, length, count = header.unpack_from(self.buffer)
        if magic != magic_expected:
            raise WireError("answer does not start with the protocol's magic")
        if status not in STATUS_NAMES:
            raise WireError(f"unknown answer status {status}")
        if length > MAX_TEXT:
            raise WireError(f"answer text of {length} bytes exceeds {MAX_TEXT}")
        if self.rows is not None:
            _check_code_count(status, count, self.rows)
        end = header.size + count + length
        if len(self.buffer) < end:
            return None
        text = bytes(self.buffer[header.size + count:end]).decode("utf-8", "replace")
        if self.rows is not None:
            code = bytes(self.buffer[header.size:header.size + count])
        del self.buffer[:end]
        return frame, status, code, text


def _check_code_count(status, count, rows):
    """A CODES answer holds one code per row when its status is OK and none otherwise: any
    other count (none with OK included) is a WireError, a breach of the protocol."""
    expected = rows if status == OK else 0
    if count != expected:
        raise WireError(f"answered {count} codes for a batch of {rows} with status "
                        f"{STATUS_NAMES[status]!r} (expected {expected})")
