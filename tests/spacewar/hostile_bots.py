"""Bots written to attack the match, the tournament and the machine (tests/spacewar/
test_untrusted_bots.py plays each). Every one of them would change a result, crash or hang
the match, leak a process or read a secret if the sandbox let it."""
import gc
import os
import struct
import sys
import time

from spacewar import NOOP, Action


def _report(success, attempts):
    """Try each attempt; print ``{name: success word, or "BLOCKED <error>"}`` to stdout, which
    the match captures into the result's ``output``."""
    outcome = {}
    for name, attempt in attempts.items():
        try:
            attempt()
            outcome[name] = success
        except OSError as exc:
            outcome[name] = f"BLOCKED {type(exc).__name__}"
    print(repr(outcome), flush=True)


class DoNothing:
    """The honest baseline: plays the no-op every frame."""

    def act(self, obs):
        return NOOP


# -- cheating ---------------------------------------------------------------------------------
class _Payload:
    """Unpickling this runs code in the unpickler: it would kill the enemy ship."""

    def __reduce__(self):
        return (exec, ("import gc\nfor o in gc.get_objects():\n"
                       "    if type(o).__name__ == 'Game': o.ship_counters[:, 1, 7] = 0",))


class _EvilAction(Action):
    def code(self):
        return _Payload()


class PickleBomb:
    """Answers with an Action whose ``code()`` is a pickle payload."""

    def act(self, obs):
        return _EvilAction()


class ReducePayload:
    """Answers with the payload itself."""

    def act(self, obs):
        return _Payload()


class GcKiller:
    """Looks for the Game through the garbage collector and kills the enemy ship."""

    def act(self, obs):
        for o in gc.get_objects():
            if type(o).__name__ == "Game":
                o.ship_counters[:, 1 - obs.seat, 7] = 0
        return NOOP


class ForgedTurn:
    """An Action with turn=100 forced past the dataclass's check."""

    def act(self, obs):
        a = Action()
        object.__setattr__(a, "turn", 100)
        return a


class HugeCode:
    """An Action subclass whose code() is 10**30, then a string."""

    def act(self, obs):
        class Big(Action):
            def code(self):
                return 10 ** 30 if obs.frame % 2 else "fire"
        return Big()


class RaisingRepr:
    """Returns an object whose repr raises (used to crash the fault message)."""

    def act(self, obs):
        class Bad:
            def __repr__(self):
                raise RuntimeError("repr bomb")
        return Bad()


# -- the wire ---------------------------------------------------------------------------------
def _answer_fd():
    return int(sys.argv[-1])


class RawBytes:
    """Writes garbage straight into its answer pipe."""

    def act(self, obs):
        os.write(_answer_fd(), b"\x80\x03garbage" * 100)
        return NOOP


class ForgedOk:
    """Writes a well-formed answer for a frame it was not asked (4242), code 5."""

    def act(self, obs):
        os.write(_answer_fd(), struct.pack("<4sqBBH", b"SWA1", 4242, 1, 5, 0))
        return NOOP


class ForgedCode:
    """Writes its own answer with an out-of-range code for the right frame, then stays
    silent (its host's answer is swallowed by exiting)."""

    def act(self, obs):
        os.write(_answer_fd(), struct.pack("<4sqBBH", b"SWA1", obs.frame, 1, 200, 0))
        if obs.frame > 3:
            os._exit(0)
        return NOOP


class HugeText:
    """Claims a 60 kB error text, sends half of it, then goes quiet."""

    def act(self, obs):
        os.write(_answer_fd(), struct.pack("<4sqBBH", b"SWA1", obs.frame, 2, 0, 60000) + b"x" * 100)
        time.sleep(60)


class ShrinkPipe:
    """Shrinks its observation pipe to one page, then reads nothing more."""

    def act(self, obs):
        import fcntl
        fcntl.fcntl(int(sys.argv[-2]), 1031, 4096)  # F_SETPIPE_SZ
        time.sleep(60)


# -- hanging and start-up ----------------------------------------------------------------------
class EndlessLoop:
    def act(self, obs):
        while True:
            pass


class SlowInit:
    def __init__(self):
        time.sleep(35)

    def act(self, obs):
        return NOOP


class LoopInReset:
    def reset(self):
        while True:
            pass

    def act(self, obs):
        return NOOP


class RaiseInInit:
    def __init__(self):
        raise RuntimeError("no init for you")

    def act(self, obs):
        return NOOP


class RaiseInReset:
    def reset(self):
        raise RuntimeError("no reset for you")

    def act(self, obs):
        return NOOP


class ExitInAct:
    """sys.exit and KeyboardInterrupt from act: faults, the process serves on."""

    def act(self, obs):
        if obs.frame % 2:
            sys.exit(3)
        raise KeyboardInterrupt


# -- processes --------------------------------------------------------------------------------
class Forker:
    """Starts a detached child that would outlive the match, forks, and keeps trying."""

    def reset(self):
        self.errors = []
        for attempt in (self._popen, self._fork):
            try:
                attempt()
            except Exception as exc:
                self.errors.append(type(exc).__name__)
        print("forker:", self.errors, flush=True)

    def _popen(self):
        import subprocess
        subprocess.Popen(["sleep", "1000"], start_new_session=True)

    def _fork(self):
        if os.fork() == 0:
            while True:
                pass

    def act(self, obs):
        try:
            self._fork()
        except Exception:
            pass
        return NOOP


class Spinner:
    """Works hard in act (for the test that kills the match process mid-match)."""

    def act(self, obs):
        end = time.perf_counter() + 0.002
        while time.perf_counter() < end:
            pass
        return NOOP


class Threads:
    def act(self, obs):
        import threading
        threading.Thread(target=time.sleep, args=(100,)).start()
        return NOOP


# -- resources --------------------------------------------------------------------------------
class MemoryHog:
    def act(self, obs):
        self.block = bytearray(8 << 30)
        return NOOP


class Printer:
    """Prints megabytes, and a fake match result, to its stdout and stderr."""

    def reset(self):
        print('{"winner": "hostile", "winner_seat": 0, "score": [9, 0]}', flush=True)

    def act(self, obs):
        sys.stdout.write("spam " * 20000 + "\n")
        sys.stderr.write("more " * 20000 + "\n")
        os.write(1, b"raw " * 10000)
        return NOOP


class DiskFiller:
    """Writes files in its scratch directory until something stops it."""

    def reset(self):
        written = 0
        try:
            for k in range(10000):
                with open(f"fill{k}.bin", "wb") as f:
                    f.write(b"\0" * (1 << 20))
                written += 1
        except OSError as exc:
            print(f"filler stopped after {written} MiB: {type(exc).__name__}", flush=True)

    def act(self, obs):
        return NOOP


# -- reading, network -------------------------------------------------------------------------
class Snooper:
    """Tries to read the files named in SNOOP_TARGETS (set by the test), /etc/passwd and
    other processes' command lines, and prints what it gets."""

    TARGETS = ()

    def reset(self):
        found = {}
        targets = list(self.TARGETS) + ["/etc/passwd", "/etc/hostname"]
        for path in targets:
            try:
                with open(path) as f:
                    found[path] = f.read(200)
            except OSError as exc:
                found[path] = f"BLOCKED {type(exc).__name__}"
        try:
            found["/proc"] = " ".join(p for p in os.listdir("/proc") if p.isdigit())
        except OSError as exc:
            found["/proc"] = f"BLOCKED {type(exc).__name__}"
        print(repr(found), flush=True)

    def act(self, obs):
        return NOOP


class Networker:
    """Tries TCP to 127.0.0.1 (port in its class attribute), UDP, and a UNIX socket path."""

    PORT = 9
    UNIX_PATH = "/tmp/none"

    def reset(self):
        import socket

        def connect(family, kind, address):
            s = socket.socket(family, kind)
            s.settimeout(1.0)
            s.connect(address)
            s.send(b"hello from the bot")

        _report("CONNECTED", {
            "tcp": lambda: connect(socket.AF_INET, socket.SOCK_STREAM, ("127.0.0.1", self.PORT)),
            "udp": lambda: connect(socket.AF_INET, socket.SOCK_DGRAM, ("127.0.0.1", self.PORT)),
            "unix": lambda: connect(socket.AF_UNIX, socket.SOCK_STREAM, self.UNIX_PATH)})

    def act(self, obs):
        return NOOP


class Writer:
    """Tries to write each path of ``TARGETS`` (set by the test; by default next to its own
    source file, into the project and into /tmp) and, as the control, a file of its own
    scratch directory (its working directory), each read back after writing; prints
    ``writer: {path: "WRITTEN", or "BLOCKED <error>"}`` with every attempt it made."""

    TARGETS = None
    CONTROL = "writer-control.txt"

    def reset(self):
        import spacewar

        targets = self.TARGETS
        if targets is None:
            targets = (os.path.join(os.path.dirname(os.path.abspath(__file__)), "planted.txt"),
                       os.path.join(os.path.dirname(spacewar.__file__), "planted.py"),
                       "/tmp/planted")
        outcome = {}
        for path in list(targets) + [os.path.join(os.getcwd(), self.CONTROL)]:
            mark = f"written by the writer to {path}"
            try:
                with open(path, "w") as f:
                    f.write(mark)
                with open(path) as f:
                    back = f.read()
                outcome[path] = "WRITTEN" if back == mark else f"READ BACK {back[:40]!r}"
            except OSError as exc:
                outcome[path] = f"BLOCKED {type(exc).__name__}"
        print("writer:", repr(outcome), flush=True)

    def act(self, obs):
        return NOOP


# -- found by the red team ------------------------------------------------------------------------
class Lingerer:
    """Clears its parent-death signal, leaves its process group and replaces ``os._exit`` so
    that its host never exits: it would outlive the match and the match's process."""

    def reset(self):
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        self.prctl = libc.prctl(1, 0, 0, 0, 0)
        # the same call with junk in the option's upper 32 bits, which the kernel ignores
        self.wide = libc.syscall(157, ctypes.c_long(0x100000001), ctypes.c_long(0), 0, 0, 0)
        try:
            os.setsid()
            self.setsid = "done"
        except OSError as exc:
            self.setsid = type(exc).__name__

        def linger(code=0):
            while True:
                time.sleep(3600)
        os._exit = linger
        print("lingerer:", self.prctl, self.wide, self.setsid, flush=True)

    def act(self, obs):
        return NOOP


class MetadataVandal:
    """chmod, utime, xattr and fallocate on files outside its scratch directory (TARGET, set by
    the test) and on its own stdout, which is a file of the match's."""

    TARGET = "/nonexistent"

    def reset(self):
        import ctypes
        _report("DONE", {
            "chattr": self._chattr, "setversion": self._setversion, "lease": self._lease,
            "flock": self._flock, "chmod": lambda: os.chmod(self.TARGET, 0o4777),
            "utime": lambda: os.utime(self.TARGET, (0, 0)),
            "setxattr": lambda: os.setxattr(self.TARGET, "user.x", b"pwned"),
            "fallocate": lambda: self._fallocate(ctypes)})

    def _chattr(self):
        import fcntl
        fd = os.open(self.TARGET, os.O_RDONLY)
        fcntl.ioctl(fd, 0x40086602, struct.pack("<q", 0x80 | 0x40))  # FS_IOC_SETFLAGS: noatime...

    def _setversion(self):
        import fcntl
        fd = os.open(self.TARGET, os.O_RDONLY)
        fcntl.ioctl(fd, 0x40087602, struct.pack("<q", 12345))  # FS_IOC_SETVERSION

    def _lease(self):
        import fcntl
        fd = os.open(self.TARGET, os.O_RDONLY)
        fcntl.fcntl(fd, fcntl.F_SETLEASE, fcntl.F_RDLCK)

    def _flock(self):
        import fcntl
        fd = os.open(self.TARGET, os.O_RDONLY)
        fcntl.flock(fd, fcntl.LOCK_SH)

    @staticmethod
    def _fallocate(ctypes):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.fallocate.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_long, ctypes.c_long]
        if libc.fallocate(1, 1, 0, 1 << 30) != 0:  # FALLOC_FL_KEEP_SIZE, 1 GiB
            raise OSError(ctypes.get_errno(), "fallocate")

    def act(self, obs):
        return NOOP


class Watcher:
    """inotify on a directory it may not read: it would learn the names of files made there."""

    TARGET = "/tmp"

    def reset(self):
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        fd = libc.inotify_init1(0)
        watch = libc.inotify_add_watch(fd, self.TARGET.encode(), 0xFFF) if fd >= 0 else -1
        print("watcher:", "WATCHING" if watch >= 0 else "BLOCKED", flush=True)

    def act(self, obs):
        return NOOP


class TerminalSpoofer:
    """A fault message full of terminal escapes, to redraw the summary line as its own win."""

    def act(self, obs):
        if obs.frame == 0:
            raise RuntimeError("\x1b[2K\r\x1b[1A\x1b[2K\rhostile beats sniper 1-0\n  score 1 - 0")
        return NOOP


class DeepReady:
    """Writes a READY of its own during import, with text that would crash a JSON parser."""

    def __init__(self):
        os.write(_answer_fd(), struct.pack("<4sqBBH", b"SWA1", -1, 0, 0, 1000) + b"[" * 1000)

    def act(self, obs):
        return NOOP


class PreAnswer:
    """Takes over its host's answering and sends the next frame's answer with each one."""

    def __init__(self):
        host = sys.modules["__main__"]
        original = host._answer

        def double(bot, rules, frame, raw):
            return original(bot, rules, frame, raw) + host.wire.pack_answer(frame + 1, 1, 2)
        host._answer = double

    def act(self, obs):
        return NOOP


class SharedMemoryHog:
    """System V shared memory, which RLIMIT_AS does not count once detached."""

    def reset(self):
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        ident = libc.shmget(0, 8 << 20, 0o1000 | 0o600)
        print("shm:", "GOT" if ident >= 0 else f"BLOCKED errno {ctypes.get_errno()}", flush=True)

    def act(self, obs):
        return NOOP
