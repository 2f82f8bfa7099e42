"""``spacewar sandbox``: a probe bot tries each attack from inside the bot sandbox.

The probe is started exactly as an untrusted bot is (``spacewar.sandbox.process.ProcessSeat``), tries
each thing a hostile bot would in its ``reset`` and prints what happened to its stdout, which
the match side captures. ``probe()`` returns the findings; each check is ``blocked`` or
``allowed``, and ``ok`` says whether every one came out as the sandbox intends on this
machine.
"""
import json
import os

from spacewar.protocol import NOOP

#: check -> the outcome the sandbox intends
EXPECTED = {
    "write outside the scratch directory": "blocked",
    "write in the scratch directory": "allowed",
    "read /etc/passwd": "blocked",
    "list /": "blocked",
    "open a socket": "blocked",
    "fork": "blocked",
    "start a program": "blocked",
    "start a thread": "blocked",
    "allocate 4 GiB": "blocked",
    "raise its own limits": "blocked",
    "write a 4 MiB file": "blocked",
    "see other processes": "blocked",
}


def _try(action):
    try:
        result = action()
    except BaseException as exc:  # every failure is a finding, whatever its kind
        return {"outcome": "blocked", "detail": f"{type(exc).__name__}: {exc}"[:160]}
    if result is False:
        return {"outcome": "blocked", "detail": "refused"}
    return {"outcome": "allowed", "detail": "" if result in (None, True) else str(result)[:160]}


def _write(path):
    with open(path, "w") as f:
        f.write("x")
    os.unlink(path)


def _thread():
    import threading

    t = threading.Thread(target=lambda: None)
    t.start()
    t.join()


def _raise_limits():
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (resource.RLIM_INFINITY, resource.RLIM_INFINITY))


def _other_processes():
    pids = [p for p in os.listdir("/proc") if p.isdigit()]
    return len(pids) > 2 or False  # itself and perhaps its namespace's first process


def _big_file():
    with open("big.bin", "wb") as f:
        for _ in range(4):
            f.write(b"\0" * (1 << 20))
            f.flush()


def _socket():
    import socket

    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.settimeout(0.5)
    s.connect(("127.0.0.1", 9))


def _start_program():
    import subprocess

    subprocess.run(["/bin/true"], check=True, timeout=2)


class Probe:
    """A bot whose ``reset`` tries every attack of ``EXPECTED`` and prints the findings."""

    def reset(self):
        import spacewar

        package = os.path.dirname(spacewar.__file__)
        checks = {
            "write outside the scratch directory": lambda: _write(os.path.join(package, ".probe")),
            "write in the scratch directory": lambda: _write("probe.txt"),
            "read /etc/passwd": lambda: open("/etc/passwd").read(1) and None,
            "list /": lambda: os.listdir("/") and None,
            "open a socket": _socket,
            "fork": lambda: os._exit(0) if os.fork() == 0 else None,
            "start a program": _start_program,
            "start a thread": _thread,
            "allocate 4 GiB": lambda: bytearray(4 << 30) and None,
            "raise its own limits": _raise_limits,
            "write a 4 MiB file": _big_file,
            "see other processes": _other_processes,
        }
        findings = {name: _try(check) for name, check in checks.items()}
        os.write(1, (json.dumps(findings) + "\n").encode())

    def act(self, obs):
        return NOOP


def probe():
    """Run the probe in a bot sandbox; return ``{"layers", "checks", "ok"}``."""
    from spacewar.sandbox.process import SHOWN_OUTPUT, ProcessSeat
    from spacewar.sandbox.limits import Limits
    from spacewar.rules import Rules

    seat = ProcessSeat("spacewar.sandbox.probe:Probe", 0, Limits(startup=30.0), Rules())
    fault = seat.wait_ready()
    output = seat.close()
    if fault is not None:
        return {"layers": [], "checks": {}, "ok": False, "error": f"{fault[0]}: {fault[1]}"}
    try:
        checks = json.loads(output["text"].splitlines()[0])
    except (ValueError, IndexError):
        return {"layers": seat.layers, "checks": {}, "ok": False,
                "error": f"unreadable probe output ({SHOWN_OUTPUT} bytes shown): "
                         f"{output['text'][:200]!r}"}
    for name, finding in checks.items():
        finding["expected"] = EXPECTED.get(name, "?")
    ok = all(checks.get(name, {}).get("outcome") == want for name, want in EXPECTED.items())
    return {"layers": seat.layers, "checks": checks, "ok": ok}


def format_findings(findings):
    lines = ["Bot sandbox on this machine: " + (", ".join(findings["layers"]) or "none")]
    if "error" in findings:
        lines.append("probe failed: " + findings["error"])
    for name, f in findings["checks"].items():
        mark = "ok  " if f["outcome"] == f["expected"] else "GAP "
        lines.append(f"  {mark}{name:<38}{f['outcome']:<9}{f['detail'][:70]}")
    lines.append("every check as intended" if findings["ok"] else
                 "some checks are not as intended: see docs/game.md, 'Running untrusted bots'")
    return "\n".join(lines)
