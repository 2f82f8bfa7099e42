"""Seats for strangers' bots: each in its own confined process, fed over the binary wire.

A seat turns a raw observation (``Game.raw_observation``) into an action code and reports any
fault as ``(kind, message)``:

- ``raised``: ``act`` raised (``SystemExit`` and ``KeyboardInterrupt`` included);
- ``invalid``: it returned something that is not a valid ``spacewar.Action``, or its process
  broke the wire protocol (the seat is then stopped);
- ``timeout``: no answer within the per-action budget and what is left of the overage bank,
  or over its CPU-time limit;
- ``crashed``: its process died;
- ``startup``: loading, constructing or resetting it failed, or took longer than the start-up
  budget;
- ``memory``: it ran out of its memory limit.

Every fault costs the bot its turn (a no-op is played). Each seat keeps ``act_seconds``, the
time of every action it was asked for: the wall-clock time from the question to the answer
(what the budget is charged), the whole allowance when no answer came; a frame on which a
confined bot was not asked, being still busy with an earlier one, is not listed. These are
wall-clock figures, for ``play_match``'s ``timing`` and ``spacewar check``, never for a
result. A seat whose bot can no longer play
(start-up failure, death, protocol breach, stopped after hanging) sets ``seat.dead`` and the
match forfeits it at once.

``InlineSeat`` calls a built-in bot in this process, on a read-only observation and a private
copy of the rules. ``ProcessSeat`` runs any other bot in its own confined process
(``spacewar.sandbox.bothost``, ``spacewar.sandbox.confinement``) and talks to it only in fixed-layout binary
messages (``spacewar.wire``); the match never blocks on it: every wait has a deadline.
"""
import array
import os
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np

from spacewar import codes, wire
from spacewar.sandbox import confinement
from spacewar.bots import absolute_spec, locate
from spacewar.faults import KIND_BY_STATUS, printable
from spacewar.sandbox.limits import DEFAULT_ROUNDS, MAX_CPU_SECONDS, TimeBank
from spacewar.sandbox.provision import (DIR_PREFIX, bot_environment, compiled_code_dirs,
                                        sweep_bot_directories)

SHOWN_OUTPUT = 4096  # bytes of a bot's stdout and stderr kept in the result


class ProcessSeat:
    """A bot in its own confined process. Construction starts it; ``wait_ready`` waits."""

    _batch_rows = 0  # a BatchProcessSeat's count of matches; 0: one match, asked with OBSERVE
    _asked = "frame"  # what each question is called in fault messages

    def __init__(self, spec, seed, limits, rules, cpu_seconds=None, rounds=None):
        self.spec = spec
        self.act_seconds = array.array("d")  # each action's time (see the module's text)
        self.limits = limits
        self.bank = TimeBank(limits)
        self.dead = None
        self.layers = []
        self._pending = None  # (frame, time sent) of the observation awaiting an answer
        self._reader = wire.AnswerReader()
        self._proc = None
        self._init = self._host = None  # pidfds: the namespace's first process, the bot host
        self._stopped = False
        self._busy_for = 0.0  # seconds the bot has run on the pending frame
        self._to_bot = self._from_bot = self._log_fd = -1
        self._dir = None
        self._started = time.monotonic()
        self._rounds = DEFAULT_ROUNDS if rounds is None else int(rounds)
        _, self._user, self._namespaces = confinement.launch_plan()
        read_dirs, list_dirs, search_path = locate(spec)  # a bad spec raises here, first
        try:
            self._start(spec, seed, rules, cpu_seconds, read_dirs, list_dirs, search_path)
        except OSError as exc:  # no process, no pipe, no room: this bot cannot start
            self._stop("startup", f"could not start its process: {wire.exception_text(exc)}")

    def _start(self, spec, seed, rules, cpu_seconds, read_dirs, list_dirs, search_path):
        limits = self.limits
        sweep_bot_directories()
        self._dir = tempfile.mkdtemp(prefix=f"{DIR_PREFIX}{os.getpid()}-")
        scratch = os.path.join(self._dir, "scratch")
        os.mkdir(scratch, 0o700)
        log = os.path.join(self._dir, "output.log")
        # the match reads the bot's output through its own descriptor: whatever the bot does
        # to the path, the match reads the file it made
        log_fd = os.open(log, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o600)
        self._log_fd = os.open(log, os.O_RDONLY | os.O_CLOEXEC | os.O_NOFOLLOW)
        if confinement.bot_uid() is not None:  # the bot runs as nobody: only scratch is its
            os.chmod(self._dir, 0o711)
            os.chown(scratch, confinement.bot_uid(), confinement.bot_uid())
        dirs, files = confinement.read_paths(extra_dirs=read_dirs)
        config = {
            "spec": absolute_spec(spec), "seed": int(seed), "rules": rules.to_dict(),
            "rounds": self._rounds, "batch": self._batch_rows,
            "path": search_path, "output_bytes": limits.output_bytes,
            "confinement": {"numba_cache": compiled_code_dirs(), "scratch": scratch,
                            "scratch_mb": limits.scratch_mb, "memory_mb": limits.memory_mb,
                            "file_mb": limits.file_mb, "max_files": limits.max_files,
                            "namespaces": self._namespaces, "user": self._user,
                            "cpu_seconds": min(cpu_seconds or limits.cpu_seconds or 3600,
                                               MAX_CPU_SECONDS),
                            "read_dirs": dirs, "read_files": files, "list_dirs": list_dirs},
        }
        to_bot_r, self._to_bot = os.pipe()
        self._from_bot, from_bot_w = os.pipe()
        command = [*confinement.launch_prefix(), *confinement.namespace_init(), sys.executable,
                   "-s", "-B", "-m", "spacewar.sandbox.bothost", str(to_bot_r), str(from_bot_w)]
        try:
            self._proc = subprocess.Popen(
                command, stdin=subprocess.DEVNULL, stdout=log_fd, stderr=log_fd,
                pass_fds=(to_bot_r, from_bot_w), close_fds=True, start_new_session=True,
                cwd=scratch, env=bot_environment(scratch),
                preexec_fn=confinement.die_with_parent)
        finally:
            for fd in (to_bot_r, from_bot_w, log_fd):
                os.close(fd)
        os.set_blocking(self._to_bot, False)
        os.set_blocking(self._from_bot, False)
        self._started = time.monotonic()
        if not self._send(wire.pack_start(config), self._started + limits.startup):
            self._stop("startup", "did not read its start message")

    # -- start-up ---------------------------------------------------------------------------
    def wait_ready(self):
        """None once the bot is ready, else the start-up fault ``(kind, message)``."""
        if self.dead is not None:
            return self.dead
        deadline = self._started + self.limits.startup
        while True:
            answer = self._receive(deadline)
            if answer is None:
                if self.dead is not None:
                    kind, message = self.dead
                    self.dead = ("startup", f"died while starting: {message}")
                    return self.dead
                return self._stop("startup", f"not ready within the start-up budget of "
                                             f"{self.limits.startup:g} s")
            frame, status, code, text = answer
            if status == wire.READY and frame == -1:
                if self._batch_rows:
                    self._reader.rows = self._batch_rows  # CODES from now on
                self._find_processes()
                self.layers = [printable(x) for x in text.split("; ")][:16] if text else []
                self._pause()  # it runs only on its turns from now on
                return None
            if status in (wire.STARTUP, wire.MEMORY) and frame == -1:
                kind = "memory" if status == wire.MEMORY else "startup"
                return self._stop(kind, text or "start-up failed")
            return self._stop("invalid", "broke the protocol while starting")

    # -- play -------------------------------------------------------------------------------
    def act(self, raw):
        """``(code, fault)`` for one observation; never waits past the bot's allowance.

        The bot's process is stopped (SIGSTOP) between its turns, so it can neither think
        ahead nor take CPU from the other bot while that one plays; time it spends past a
        deadline is taken from its following turns, a budget each.
        """
        if self.dead is not None:
            return codes.NOOP, None
        try:
            return self._act(int(raw[0]), raw)
        finally:
            if self.dead is None:
                self._pause()

    def _act(self, frame, raw):
        answer, fault, elapsed = self._exchange(frame, wire.pack_observe(frame, raw),
                                                self.limits.budget, self.bank.allowance())
        if elapsed is not None:  # None: not asked (dead, or still busy with an earlier frame)
            self.act_seconds.append(elapsed)
        if answer is None:
            if elapsed is not None:  # silent for its whole allowance: the bank is spent
                self.bank.left = 0.0
            return codes.NOOP, fault
        if not self.bank.charge(elapsed):
            return codes.NOOP, ("timeout", self.bank.late(elapsed))
        return self._judge(answer)

    def _exchange(self, frame, message, budget, allowance):
        """Send ``message`` (asking for ``frame``) and wait for the answer, at most
        ``allowance`` s; a late answer to an earlier frame is waited for ``budget`` s first.

        ``(answer, None, seconds)`` when it answered in time, else ``(None, fault,
        seconds)``: ``seconds`` is the allowance when it said nothing for all of it, None
        when it was not asked (still busy, dead, stopped)."""
        if self._pending is None and (self._reader.buffer or self._unsolicited()):
            return None, self.dead or self._stop(
                "invalid", "broke the protocol: answered before being asked"), None
        if self._pending is not None:
            self._resume()  # it finishes the frame it is late with, on this turn's time
            late_frame, _ = self._pending
            window = time.monotonic()
            answer = self._receive(window + budget)
            self._busy_for += time.monotonic() - window
            if self.dead is not None:
                return None, self.dead, None
            if answer is None:
                if self._busy_for > allowance + self.limits.stop_after:
                    return None, self._stop(
                        "timeout", f"stopped: no answer to {self._asked} {late_frame} after "
                                   f"{self._busy_for:.1f} s of its turns"), None
                return None, ("timeout", f"still busy with {self._asked} {late_frame}"), None
            self._pending = None  # the late answer to an earlier frame: that one was a no-op
        sent = time.monotonic()
        # Written while the bot is still stopped, then continued: it wakes once, with its
        # question already in the pipe (continued first, it would wake to an empty pipe, sleep
        # and be woken again by the write: one more wake-up of another processor a turn).
        if not self._send(message, sent + allowance):
            return None, self.dead or self._stop("timeout", "did not read its observation"), None
        self._resume()
        self._pending, self._busy_for = (frame, sent), 0.0
        answer = self._receive(sent + allowance)
        if answer is None:
            if self.dead is not None:
                return None, self.dead, None
            self._busy_for = time.monotonic() - sent
            return None, ("timeout", f"no answer within {allowance * 1e3:.1f} ms "
                                     "(budget and overage bank)"), allowance
        self._pending = None
        return answer, None, time.monotonic() - sent

    def _unsolicited(self):
        """Whether the bot wrote anything while it was not asked (it is stopped now), or died.
        One read of the non-blocking pipe answers both (an empty pipe raises at once)."""
        try:
            data = os.read(self._from_bot, 1 << 16)
        except BlockingIOError:
            return False
        except OSError:
            data = b""
        if not data:
            self._died()
        return True

    def _judge(self, answer):
        _, status, code, text = answer
        if status == wire.OK:
            if 0 <= code < codes.N_ACTIONS:
                return code, None
            return codes.NOOP, ("invalid", f"action code {code} out of range [0, {codes.N_ACTIONS})")
        if status in KIND_BY_STATUS:
            return codes.NOOP, (KIND_BY_STATUS[status], text or wire.STATUS_NAMES[status])
        return codes.NOOP, self._stop("invalid", f"broke the protocol: status "
                                                 f"{wire.STATUS_NAMES[status]!r} during play")

    # -- the pipes --------------------------------------------------------------------------
    def _send(self, data, deadline):
        view = memoryview(data)
        while view:
            try:
                view = view[os.write(self._to_bot, view):]
                continue
            except BlockingIOError:
                self._resume()  # the pipe is full (a large batch): the bot must read on
            except OSError:
                self._died()
                return False
            remaining = deadline - time.monotonic()
            if remaining <= 0 or not select.select([], [self._to_bot], [], remaining)[1]:
                return False
        return True

    def _receive(self, deadline):
        """The next answer, or None at the deadline or when the bot dies or misbehaves."""
        while True:
            try:  # an empty buffer (the common case: nothing read yet) holds no answer
                answer = self._reader.next() if self._reader.buffer else None
            except wire.WireError as exc:
                self._stop("invalid", f"broke the protocol: {exc}")
                return None
            if answer is not None:
                frame = answer[0]
                expected = -1 if self._pending is None else self._pending[0]
                if frame != expected:
                    self._stop("invalid", f"broke the protocol: answered {self._asked} "
                                          f"{frame}, asked {expected}")
                    return None
                return answer
            remaining = deadline - time.monotonic()
            if remaining > 0:
                if not select.select([self._from_bot], [], [], remaining)[0]:
                    return None
            try:
                data = os.read(self._from_bot, 1 << 16)
            except BlockingIOError:
                if remaining <= 0:
                    return None
                continue
            except OSError:
                data = b""
            if not data:
                self._died()
                return None
            try:
                self._reader.feed(data)
            except wire.WireError as exc:
                self._stop("invalid", f"broke the protocol: {exc}")
                return None

    # -- ending -----------------------------------------------------------------------------
    def _died(self):
        try:
            code = self._proc.wait(timeout=1.0)
        except subprocess.TimeoutExpired:
            code = None
        if code is not None and code > 128 and confinement.namespace_init() and self._namespaces:
            code = 128 - code  # the namespace's sh reports a signal death as 128 + signal
        if code is not None and code < 0 and -code == signal.SIGXCPU:
            self.dead = ("timeout", "over its CPU-time limit")
        elif code is not None and code < 0:
            try:
                name = signal.Signals(-code).name
            except ValueError:
                name = f"signal {-code}"
            self.dead = ("crashed", f"bot process killed by {name}")
        else:
            self.dead = ("crashed", f"bot process exited (code {code})")
        self._kill()

    def _stop(self, kind, message):
        self.dead = (kind, message)
        self._kill()
        return self.dead

    def _find_processes(self):
        """Hold the namespace's first process and the bot host by pidfds (found once).

        Under ``unshare`` the first process is a trusted ``sh`` that runs nothing of the bot:
        killing it makes the kernel kill everything in the bot's PID namespace, whatever the
        bot did to its own process. Without namespaces the host is our own child."""
        if self._host is not None or self._proc is None or self._proc.poll() is not None:
            return  # found already, or never started, or gone (its pid may be another's now)
        self._init = self._host = -1
        try:
            if self._namespaces:
                first = _children(self._proc.pid)
                if first:
                    self._init = os.pidfd_open(first[0])
                    host = _children(first[0])
                    if host:
                        self._host = os.pidfd_open(host[0])
            else:
                self._host = os.pidfd_open(self._proc.pid)
        except (OSError, AttributeError):
            pass

    def _signal_host(self, sig):
        if self._host is not None and self._host >= 0:
            try:
                signal.pidfd_send_signal(self._host, sig)
            except OSError:
                pass

    def _pause(self):
        if not self._stopped:
            self._signal_host(signal.SIGSTOP)
            self._stopped = True

    def _resume(self):
        if self._stopped:
            self._signal_host(signal.SIGCONT)
            self._stopped = False

    def _kill(self):
        if self._proc is None:
            return
        self._find_processes()
        for pidfd in (self._init, self._host):
            if pidfd is not None and pidfd >= 0:
                try:
                    signal.pidfd_send_signal(pidfd, signal.SIGKILL)
                except OSError:
                    pass
                os.close(pidfd)
        self._init = self._host = -1  # found once, killed once
        if self._proc.returncode is not None:
            return
        try:
            os.killpg(self._proc.pid, signal.SIGKILL)  # its session: it and all it started
        except (ProcessLookupError, PermissionError):
            pass
        self._proc.kill()
        self._proc.wait()

    def close(self):
        """Stop the bot (and everything it started); return its captured output."""
        if self._proc is not None and self._proc.returncode is None:
            self._resume()
            if self._send(wire.pack_stop(), time.monotonic() + 0.05):
                try:
                    self._proc.wait(timeout=0.2)
                except subprocess.TimeoutExpired:
                    pass
            self._kill()
        output = _read_output(self._log_fd)
        for fd in (self._to_bot, self._from_bot, self._log_fd):
            if fd >= 0:
                try:
                    os.close(fd)
                except OSError:
                    pass
        self._to_bot = self._from_bot = self._log_fd = -1
        if self._dir is not None:
            shutil.rmtree(self._dir, ignore_errors=True)
        return output

    def __del__(self):
        if getattr(self, "_proc", None) is not None and self._proc.returncode is None:
            self._kill()
        for fd in (getattr(self, "_to_bot", -1), getattr(self, "_from_bot", -1),
                   getattr(self, "_log_fd", -1)):
            if fd >= 0:
                try:
                    os.close(fd)
                except OSError:
                    pass


class BatchProcessSeat(ProcessSeat):
    """A batch bot from a file (``spacewar.bots.batch``) in its own confined process, one
    instance answering for ``rows`` matches at once: every call sends all their learning
    observations (BATCH) and takes one code per row back (CODES), with every protection and
    deadline of ``ProcessSeat``. What the caller charges to each match is its business
    (``spacewar.arena.batch_match``); this seat judges only the answer."""

    _asked = "call"

    def __init__(self, spec, seed, limits, rules, rows, cpu_seconds=None, rounds=None):
        if isinstance(rows, bool) or not isinstance(rows, int) or not 1 <= rows <= wire.MAX_ROWS:
            raise ValueError(f"rows must be an int in [1, {wire.MAX_ROWS}], got {rows!r}")
        self._batch_rows = rows
        super().__init__(spec, seed, limits, rules, cpu_seconds=cpu_seconds, rounds=rounds)

    def act_batch(self, call, obs, budget, allowance):
        """Ask for call number ``call`` on ``obs`` ((rows, D) float32); never waits past
        ``allowance`` s (a late answer to the previous call: ``budget`` s).

        Returns ``(status, codes, text, seconds, fault)``: with an answer, ``status`` is the
        wire's (``codes`` the (rows,) int64 codes when OK, else None; INVALID when one of the
        ``rows`` codes is out of range), ``seconds`` how long it took and ``fault`` None;
        without one, ``status`` is None and ``fault`` says why (``self.dead`` set when the bot
        can play no more: a count of codes other than ``rows`` on an OK answer, or any on
        another, breaks the protocol), ``seconds`` the allowance when it was silent for all
        of it."""
        if self.dead is not None:
            return None, None, "", None, self.dead
        try:
            answer, fault, seconds = self._exchange(call, wire.pack_batch(call, obs), budget,
                                                    allowance)
        finally:
            if self.dead is None:
                self._pause()
        if answer is None:
            return None, None, "", seconds, fault
        _, status, data, text = answer
        if status == wire.OK:  # exactly one code a row (the reader's check: else a breach)
            found = np.frombuffer(data, dtype=np.uint8).astype(np.int64)
            bad = found >= codes.N_ACTIONS
            if bad.any():
                return (wire.INVALID, None, f"action code {found[bad][0]} out of range "
                        f"[0, {codes.N_ACTIONS})", seconds, None)
            return wire.OK, found, "", seconds, None
        if status in KIND_BY_STATUS:
            return status, None, text or wire.STATUS_NAMES[status], seconds, None
        return None, None, "", None, self._stop(
            "invalid", f"broke the protocol: status {wire.STATUS_NAMES[status]!r} during play")


def _children(pid):
    with open(f"/proc/{pid}/task/{pid}/children") as f:
        return [int(x) for x in f.read().split()]


def _read_output(fd):
    """The first ``SHOWN_OUTPUT`` bytes of the bot's output file, its size, whether cut."""
    if fd < 0:
        return {"text": "", "bytes": 0, "truncated": False}
    try:
        head = os.pread(fd, SHOWN_OUTPUT + 1, 0)
        size = os.fstat(fd).st_size
    except OSError:
        return {"text": "", "bytes": 0, "truncated": False}
    return {"text": head[:SHOWN_OUTPUT].decode("utf-8", "replace"), "bytes": int(size),
            "truncated": len(head) > SHOWN_OUTPUT}
