"""Seats: a bot at the table, isolated so that it can fail without taking the match down.

A seat turns an observation into an action code and reports any fault:

- ``raised``: ``act`` raised an exception;
- ``invalid``: it returned something that is not a ``spacewar.Action``;
- ``timeout``: it took longer than the per-action time budget (its answer is discarded);
- ``crashed``: its process died.

Every fault costs the bot its turn (a no-op is played). ``InlineSeat`` calls the bot in this
process (fast; a slow answer is discarded after the fact, but a bot that never returns would
hang it, so it is for trusted, built-in bots). ``ProcessSeat`` runs the bot in a child process
and stops waiting when the budget is spent, so even a bot stuck in an endless loop only loses
turns; the child is killed when the match ends.
"""
import multiprocessing
import time
import traceback

from . import core
from .bots import make_bot
from .protocol import Action

FAULT_KINDS = ("raised", "invalid", "timeout", "crashed")


def _check_action(result):
    """The action code of a valid answer, or None."""
    if isinstance(result, Action):
        return result.code()
    return None


def _describe(result):
    text = repr(result)
    return text if len(text) <= 80 else text[:77] + "..."


class InlineSeat:
    """A bot called directly in this process."""

    def __init__(self, spec, seed, budget):
        self.spec = spec
        self.bot = make_bot(spec, seed=seed)
        self.budget = budget
        reset = getattr(self.bot, "reset", None)
        if callable(reset):
            reset()

    def act(self, obs):
        """``(code, fault)``: fault is None or ``(kind, message)``."""
        start = time.perf_counter()
        try:
            result = self.bot.act(obs)
        except Exception as exc:  # a bot's bug must not end the match
            return core.NOOP, ("raised", f"{type(exc).__name__}: {exc}")
        elapsed = time.perf_counter() - start
        if elapsed > self.budget:
            return core.NOOP, ("timeout", f"answered after {elapsed * 1e3:.1f} ms "
                                          f"(budget {self.budget * 1e3:.1f} ms)")
        code = _check_action(result)
        if code is None:
            return core.NOOP, ("invalid", f"returned {_describe(result)}, not an Action")
        return code, None

    def close(self):
        pass


def _child(conn, spec, seed):
    """The child process of a ProcessSeat: answer each (frame, obs) with (frame, kind, payload)."""
    try:
        bot = make_bot(spec, seed=seed)
        reset = getattr(bot, "reset", None)
        if callable(reset):
            reset()
        conn.send((-1, "ready", None))
    except Exception as exc:
        conn.send((-1, "raised", f"{type(exc).__name__}: {exc}"))
        return
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message is None:
            return
        frame, obs = message
        try:
            result = bot.act(obs)
            code = _check_action(result)
            if code is None:
                conn.send((frame, "invalid", f"returned {_describe(result)}, not an Action"))
            else:
                conn.send((frame, "ok", code))
        except Exception as exc:
            conn.send((frame, "raised", f"{type(exc).__name__}: {exc}"))
        except BaseException:  # SystemExit, KeyboardInterrupt inside a bot: report and stop
            conn.send((frame, "raised", traceback.format_exc(limit=1).strip().splitlines()[-1]))
            return


def _context():
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("fork" if "fork" in methods else "spawn")


class ProcessSeat:
    """A bot in its own process, with a hard per-action time budget."""

    def __init__(self, spec, seed, budget, start_timeout=30.0):
        self.spec = spec
        self.budget = budget
        ctx = _context()
        self._conn, child_conn = ctx.Pipe()
        self._proc = ctx.Process(target=_child, args=(child_conn, spec, seed), daemon=True)
        self._proc.start()
        child_conn.close()
        self._frame = 0
        self._dead = None
        if not self._conn.poll(start_timeout):
            self.close()
            raise RuntimeError(f"bot {spec!r} did not start within {start_timeout} s")
        _, kind, payload = self._conn.recv()
        if kind != "ready":
            self.close()
            from .bots import BotLoadError
            raise BotLoadError(f"bot {spec!r} failed to start: {payload}")

    def act(self, obs):
        if self._dead is not None:
            return core.NOOP, ("crashed", self._dead)
        self._frame += 1
        try:
            self._conn.send((self._frame, obs))
        except (BrokenPipeError, OSError) as exc:
            self._dead = f"bot process is gone ({type(exc).__name__})"
            return core.NOOP, ("crashed", self._dead)
        deadline = time.perf_counter() + self.budget
        while True:
            remaining = deadline - time.perf_counter()
            try:
                ready = self._conn.poll(max(0.0, remaining))
            except (EOFError, OSError):
                ready = False
            if not ready:
                if not self._proc.is_alive():
                    self._dead = f"bot process died (exit code {self._proc.exitcode})"
                    return core.NOOP, ("crashed", self._dead)
                return core.NOOP, ("timeout", f"no answer within {self.budget * 1e3:.1f} ms")
            try:
                frame, kind, payload = self._conn.recv()
            except (EOFError, OSError):
                self._dead = f"bot process died (exit code {self._proc.exitcode})"
                return core.NOOP, ("crashed", self._dead)
            if frame != self._frame:
                continue  # a late answer to an earlier frame: already played as a no-op
            if kind == "ok":
                return payload, None
            return core.NOOP, (kind, payload)

    def close(self):
        try:
            self._conn.send(None)
        except (BrokenPipeError, OSError):
            pass
        self._proc.join(timeout=0.2)
        if self._proc.is_alive():
            self._proc.kill()
            self._proc.join(timeout=1.0)
        self._conn.close()


def open_seat(spec, seed, budget, isolation="auto"):
    """A seat for bot ``spec``: ``inline``, ``process``, or ``auto`` (built-ins inline)."""
    from .bots import BotLoadError, available, is_builtin

    if isolation not in ("auto", "inline", "process"):
        raise ValueError(f"isolation must be auto, inline or process, got {isolation!r}")
    if not isinstance(spec, str) or (":" not in spec and not is_builtin(spec)):
        raise BotLoadError(f"unknown bot {spec!r}; available: {', '.join(available())} "
                           "(or give package.module:Class or path/to/file.py:Class)")
    if isolation == "inline" or (isolation == "auto" and is_builtin(spec)):
        return InlineSeat(spec, seed, budget)
    return ProcessSeat(spec, seed, budget)
