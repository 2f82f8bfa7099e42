"""The bot's own process: confine itself, load the bot, answer observations over the wire.

Started by ``spacewar.sandbox.process.ProcessSeat`` as ``python -I -m spacewar.sandbox.bothost IN OUT`` (the
file descriptors of its two pipes), possibly under ``unshare``. Nothing of the bot runs
before ``confinement.confine`` has applied every layer; from then on the bot's module is
imported, its class checked, constructed and reset here, and the match only ever learns
"ready" or a start-up fault with a message.

Started with ``batch`` in its configuration (a count of matches), it hosts a batch bot
(``spacewar.bots.batch``): one instance answers BATCH messages, all those matches' learning
observations at once, with CODES. Its answers are checked here for helpful messages,
and again by the match, which trusts nothing that arrives.
"""
import io
import json
import os
import sys

from spacewar import wire
from spacewar.bots.ask import ask
from spacewar.protocol import observation_of_copy, raw_length


def _read_exact(fd, n):
    chunks = []
    while n:
        chunk = os.read(fd, n)
        if not chunk:
            raise EOFError
        chunks.append(chunk)
        n -= len(chunk)
    return b"".join(chunks)


class _Inbox:
    """The match's messages as they arrive: each read takes whatever the pipe holds (a whole
    observation: the match writes one in a single piece before it lets this process run),
    and the parts a message is parsed from are served from that. One system call a message
    where reading header and body apart took two."""

    def __init__(self, fd):
        self.fd = fd
        self.data = b""  # what was read and not yet served: data[position:]
        self.position = 0

    def read_exact(self, n):
        end = self.position + n
        if end > len(self.data):
            parts = [self.data[self.position:]]
            missing = end - len(self.data)
            while missing > 0:
                chunk = os.read(self.fd, max(missing, 1 << 16))
                if not chunk:
                    raise EOFError
                parts.append(chunk)
                missing -= len(chunk)
            self.data, self.position, end = b"".join(parts), 0, n
        part = self.data[self.position:end]
        self.position = end
        return part


def _write_all(fd, data):
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


class _CappedOutput(io.RawIOBase):
    """The bot's stdout and stderr: the first ``cap`` bytes reach the file, the rest is
    counted and dropped (so a flood neither fills a disk nor raises in the bot)."""

    def __init__(self, fd, cap):
        self.fd, self.cap, self.seen = fd, cap, 0

    def writable(self):
        return True

    def write(self, data):
        room = self.cap - self.seen
        self.seen += len(data)
        if room > 0:
            try:
                _write_all(self.fd, bytes(data[:room]))
            except OSError:
                pass
        return len(data)


def _capture_output(cap):
    raw = _CappedOutput(1, cap)
    stream = io.TextIOWrapper(io.BufferedWriter(raw), encoding="utf-8", errors="replace",
                              line_buffering=True)
    sys.stdout = sys.stderr = stream


def _load(config):
    from spacewar.bots import import_top_level, make_bot
    from spacewar.rules import Rules

    if config.get("path"):  # a module:Class bot: its module from where the match found it
        import_top_level(config["spec"], config["path"])
    from spacewar.bots.batch import is_batch_bot, one_match_bot

    rules = Rules.from_dict(config["rules"])
    bot = make_bot(config["spec"], seed=config["seed"])
    if config.get("batch"):
        if not is_batch_bot(bot):
            raise TypeError(f"{config['spec']!r} defines act_batch in its source, but the bot "
                            "it makes has no callable act_batch")
    else:
        bot = one_match_bot(bot, rules, config["rounds"])
    reset = getattr(bot, "reset", None)
    if callable(reset):
        reset()
    return bot, rules


def _answer(bot, rules, frame, raw):
    """The answer message of ``bot`` to the observation ``raw`` of ``frame`` (a fresh array
    of this process's own, which the observation keeps)."""
    if raw.shape != (raw_length(rules),):
        raise wire.WireError(f"observation of {raw.size} numbers, {raw_length(rules)} expected")
    status, code, text = ask(bot, observation_of_copy(raw, rules))
    return wire.pack_answer(frame, status, code, text)


def _answer_batch(bot, call, obs):
    """The CODES message of batch ``bot`` to the observations ``obs`` of ``call``."""
    from spacewar.bots.batch import ask_batch

    status, codes, text = ask_batch(bot, obs)
    return wire.pack_codes(call, status, codes if status == wire.OK else b"", text)


def main(argv):
    fd_in, fd_out = int(argv[1]), int(argv[2])
    try:
        config = wire.read_start(lambda n: _read_exact(fd_in, n))
    except (EOFError, OSError, ValueError):
        os._exit(2)
    from spacewar.sandbox import confinement

    try:
        layers = confinement.confine(config["confinement"])
    except BaseException as exc:
        _write_all(fd_out, wire.pack_answer(-1, wire.STARTUP, 0,
                                            "confinement failed: " + wire.exception_text(exc)))
        os._exit(3)
    _capture_output(int(config["output_bytes"]))
    import warnings

    # numba's cache cannot take its lock without /dev/shm: say nothing of it in the bot's output
    warnings.filterwarnings("ignore", message="Could not obtain multiprocessing lock")
    try:
        bot, rules = _load(config)
    except MemoryError:
        _write_all(fd_out, wire.pack_answer(-1, wire.MEMORY, 0, "MemoryError while starting"))
        os._exit(4)
    except BaseException as exc:
        _write_all(fd_out, wire.pack_answer(-1, wire.STARTUP, 0, wire.exception_text(exc)))
        os._exit(4)
    _write_all(fd_out, wire.pack_answer(-1, wire.READY, 0, "; ".join(layers)))
    batch = bool(config.get("batch"))
    read = wire.read_batch if batch else wire.read_observe
    read_exact = _Inbox(fd_in).read_exact
    while True:
        try:
            message = read(read_exact)
        except (EOFError, OSError, ValueError):
            break
        if message is None:
            break
        frame, observation = message
        try:
            if batch:
                answer = _answer_batch(bot, frame, observation)
            else:
                answer = _answer(bot, rules, frame, observation)
        except wire.WireError:
            break
        except MemoryError:
            answer = (wire.pack_codes(frame, wire.MEMORY, b"", "MemoryError") if batch
                      else wire.pack_answer(frame, wire.MEMORY, 0, "MemoryError"))
        try:
            _write_all(fd_out, answer)
        except OSError:
            break
    try:
        sys.stdout.flush()
    except BaseException:
        pass
    os._exit(0)


if __name__ == "__main__":
    main(sys.argv)
