"""Hostile bots against the sandbox: each match and tournament finishes, the fault is named,
nothing is left running, the JSON is valid and no cheat changes a result.

The bots are in hostile_bots.py; those whose attack is in their module's import, or needs a
path or port chosen by the test, are written to a temporary file here.
"""
import json
import os
import signal
import socket
import subprocess
import sys
import textwrap
import time

import pytest

from spacewar import Rules
from spacewar.cli import main
from spacewar.arena.match import play_match
from spacewar.sandbox.limits import Limits
from spacewar.arena.tournament import run_tournament

HOSTILE = "tests.spacewar.hostile_bots"
SHORT = Rules(max_round_frames=400, post_round_delay=8)  # a drawn round ends soon
# budgets long enough that an honest answer is never late, however loaded the machine: the
# tests assert what the sandbox does, not how fast; FAST is for the bots that never answer
ROOMY = Limits(budget=2.0, overage=20.0, startup=60.0, stop_after=0.5)
FAST = Limits(budget=0.05, overage=0.2, startup=60.0, stop_after=0.5)
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="the bot sandbox's checks here are Linux's")


TAG = f"SPACEWAR_BOT=test-{os.getpid()}".encode()


def bot_processes():
    """Every process started by a bot of this test run, or by what it started: they carry
    the tag of this run in their environment (``SPACEWAR_BOT_TAG`` here becomes
    ``SPACEWAR_BOT`` in a bot's environment, and only there)."""
    found = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            with open(f"/proc/{pid}/environ", "rb") as f:
                tagged = TAG in f.read().split(b"\0")
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                cmd = f.read().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        if tagged:
            found.append(f"{pid}: {cmd}")
    return found


@pytest.fixture(autouse=True)
def nothing_left_running(monkeypatch):
    monkeypatch.setenv("SPACEWAR_BOT_TAG", TAG.decode().split("=", 1)[1])
    yield
    deadline = time.monotonic() + 10.0
    while bot_processes() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert bot_processes() == []


@pytest.fixture
def tmp_path():
    """A directory anyone may read (pytest's own is root's alone, and a bot started by root
    runs as nobody where it can), so that only the sandbox stands between bot and file."""
    import pathlib
    import shutil
    import tempfile

    path = pathlib.Path(tempfile.mkdtemp(prefix="spacewar-test-"))
    path.chmod(0o755)
    yield path
    shutil.rmtree(path, ignore_errors=True)


def write_bot(tmp_path, source, name="bot.py"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(source))
    path.chmod(0o644)
    return str(path)


def play(p1, p2="sniper", rules=SHORT, limits=ROOMY, **kw):
    result, _, _ = play_match(p1, p2, seed=3, rounds=1, rules=rules, limits=limits, **kw)
    json.dumps(result)  # plain data
    return result


@pytest.fixture(scope="module")
def baseline():
    """A do-nothing bot in its own process against sniper: what every cheat must still get."""
    result, replay, _ = play_match(f"{HOSTILE}:DoNothing", "sniper", seed=3, rounds=1, rules=SHORT, limits=ROOMY,
                                   record=True)
    assert result["winner"] == "sniper" and result["faults"][0]["total"] == 0
    return result, replay


# -- cheats -------------------------------------------------------------------------------------
@pytest.mark.parametrize("bot", ["PickleBomb", "GcKiller", "HugeCode"])
def test_cheats_do_not_change_the_result(bot, baseline):
    """The answer crosses as an action code and nothing else: the pickle payload, a Game
    found through gc (there is none in the bot's process) and a code() override change
    nothing. PickleBomb and GcKiller play the no-op, so the match is the baseline's to the bit."""
    expected, _ = baseline
    result = play(f"{HOSTILE}:{bot}")
    assert result["winner"] == "sniper" and result["score"] == expected["score"]
    if bot != "HugeCode":
        assert result["steps"] == expected["steps"] and result["faults"][0]["total"] == 0


def test_import_time_patch_of_the_match_does_not_rig_a_tournament(tmp_path):
    rigger = write_bot(tmp_path, """
        import spacewar.arena.match as m
        def rigged(game, bots, *args, **kw):
            return {"winner": bots[0], "score": [9, 0]}
        m.match_result = rigged
        from spacewar import NOOP
        class Rigger:
            def act(self, obs):
                return NOOP
    """)
    kw = dict(games=1, seed=2, rounds=1, rules=SHORT, progress=False, limits=ROOMY)
    for workers in (1, 2):
        report, _ = run_tournament([f"{rigger}:Rigger", "sniper"], workers=workers, **kw)
        rows = {r["bot"]: r for r in report["table"]}
        assert rows["sniper"]["wins"] == 2 and rows[f"{rigger}:Rigger"]["wins"] == 0
        assert rows[f"{rigger}:Rigger"]["faults"] == 0  # it did start, and patched its own copy


def test_exit_at_import_forfeits_and_the_tournament_prints_its_table(tmp_path, capsys):
    dead = write_bot(tmp_path, """
        import os
        os._exit(9)
        class Dead:
            def act(self, obs):
                return None
    """)
    args = ["tournament", "--bots", f"{dead}:Dead,idle,sniper", "--games", "1", "--rounds", "1",
            "--workers", "1", "--no-progress", "--json"]
    assert main(args) == 0
    report = json.loads(capsys.readouterr().out)
    rows = {r["bot"]: r for r in report["table"]}
    assert rows[f"{dead}:Dead"]["forfeits"] == 4 and rows[f"{dead}:Dead"]["wins"] == 0
    assert rows["sniper"]["played"] == 4
    result, _, _ = play_match(f"{dead}:Dead", "idle", seed=1, rounds=1)
    assert "died while starting: bot process exited (code 9)" in \
        result["faults"][0]["examples"][0]["message"]


# -- answers that used to crash the match --------------------------------------------------------
@pytest.mark.parametrize("bot, kind", [("ForgedTurn", "invalid"), ("ReducePayload", "invalid"),
                                       ("RaisingRepr", "invalid"), ("ExitInAct", "raised")])
def test_bad_answers_are_faults(bot, kind):
    result = play(f"{HOSTILE}:{bot}", max_faults=5)
    f = result["faults"][0]
    assert f[kind] == 5 and f["total"] == 5 and result["forfeit"] == f"{HOSTILE}:{bot}"
    assert result["winner"] == "sniper"


def check_protocol_breach(result, expected):
    """A breach of the wire protocol, and nothing else, ended seat 1's match at once: every
    fault of it is ``invalid`` (no timeout, no crash), the last one is the breach (its message
    starts with ``broke the protocol: `` and holds ``expected``, one of them when a tuple: the
    order of two writes decides which), made on frame 0 or 1, and the seat forfeited there."""
    f = result["faults"][0]
    assert result["forfeits"] == [True, False] and result["winner_seat"] == 1, result
    assert f["invalid"] == f["total"] >= 1 and f["timeout"] == f["crashed"] == 0, f
    message = f["last"]["message"]
    assert f["last"]["kind"] == "invalid" and message.startswith("broke the protocol: "), f
    expected = (expected,) if isinstance(expected, str) else expected
    assert any(text in message for text in expected), (message, expected)
    assert f["last"]["frame"] <= 1 and result["steps"] == f["last"]["frame"], (f, result["steps"])


@pytest.mark.parametrize("bot, expected", [
    ("RawBytes", "answer does not start with the protocol's magic"),
    ("ForgedOk", "answered frame 4242, asked 0"),
    # its own answer (code 200: an invalid action on frame 0), then its host's answer to
    # frame 0: read before frame 1 is asked, or as the answer to frame 1
    ("ForgedCode", ("answered before being asked", "answered frame 0, asked 1")),
    ("HugeText", "answer text of 60000 bytes exceeds 1024"),
])
def test_protocol_breaches_forfeit_at_once(bot, expected):
    """ROOMY's 2 s budget and 20 s bank: each breach comes on frame 0 or 1, long before a
    silent bot could time out, so it must be the fault that forfeits."""
    result = play(f"{HOSTILE}:{bot}", max_faults=1000)
    check_protocol_breach(result, expected)


# a round that would last 200000 frames, so the match outlasts any wait of the bot's
LONG = Rules(star="none", max_round_frames=200_000, max_extra_rounds=0)


@pytest.mark.parametrize("bot", ["EndlessLoop", "ShrinkPipe"])
def test_a_bot_that_never_answers_is_stopped_and_forfeits(bot):
    """Frames go on while it is busy (each one a timeout, the match never waits on it); once
    it has been silent ``stop_after`` past its allowance it is killed and forfeits, whatever
    the fault allowance."""
    result = play(f"{HOSTILE}:{bot}", "idle", rules=LONG, limits=FAST, max_faults=10 ** 6)
    f = result["faults"][0]
    assert result["forfeits"] == [True, False] and f["timeout"] == f["total"] >= 2
    assert f["last"]["message"].startswith("stopped: no answer to frame 0")
    # positive control for check_protocol_breach: this forfeit by timeout (the old check of
    # the breaches accepted a timeout too) is not a breach
    with pytest.raises(AssertionError):
        check_protocol_breach(result, "")


@pytest.mark.parametrize("bot", ["SlowInit", "LoopInReset"])
def test_slow_start_is_a_start_up_fault(bot):
    result = play(f"{HOSTILE}:{bot}", limits=Limits(startup=1.5))
    assert result["faults"][0]["startup"] == 1 and result["forfeits"] == [True, False]
    assert "start-up budget" in result["faults"][0]["examples"][0]["message"]


@pytest.mark.parametrize("bot", ["RaiseInInit", "RaiseInReset"])
def test_start_up_errors_forfeit_with_the_message(bot):
    result = play(f"{HOSTILE}:{bot}")
    f = result["faults"][0]
    assert f["startup"] == 1 and "RuntimeError: no" in f["examples"][0]["message"]
    assert result["winner"] == "sniper" and result["steps"] == 0


def test_both_bots_failing_to_start_is_nobody_s_win():
    result = play(f"{HOSTILE}:RaiseInInit", f"{HOSTILE}:RaiseInReset")
    assert result["forfeits"] == [True, True] and result["winner"] is None


def test_a_tournament_survives_start_up_faults():
    report, _ = run_tournament([f"{HOSTILE}:RaiseInInit", f"{HOSTILE}:SlowInit", "idle"],
                               games=1, seed=1, rounds=1, rules=SHORT, workers=2,
                               progress=False, limits=Limits(startup=1.5))
    rows = {r["bot"]: r for r in report["table"]}
    assert rows["idle"]["wins"] == 4
    assert rows[f"{HOSTILE}:RaiseInInit"]["forfeits"] == 4


# -- processes -------------------------------------------------------------------------------------
@pytest.mark.parametrize("bot", ["Forker", "Threads"])
def test_bots_cannot_start_processes_or_threads(bot):
    result = play(f"{HOSTILE}:{bot}", max_faults=5)
    if bot == "Forker":
        assert "forker: ['PermissionError', 'PermissionError']" in result["output"][0]["text"]
        assert result["faults"][0]["total"] == 0
    else:
        assert result["faults"][0]["raised"] == 5
    # the fixture then checks that no `sleep 1000` and no bot host is left


def test_a_bot_that_would_outlive_its_match_does_not():
    """Clearing the parent-death signal and leaving the process group are refused (seccomp);
    even where they are not, the match kills the bot's host by its own pid."""
    result = play(f"{HOSTILE}:Lingerer")
    assert result["winner"] == "sniper" and result["faults"][0]["total"] == 0
    assert "lingerer: -1 -1 PermissionError" in result["output"][0]["text"]
    # the fixture asserts nothing is left


@pytest.mark.parametrize("bot", ["Spinner", "Lingerer"])
def test_killing_the_match_process_kills_the_bot(bot):
    """The match process reports every 25th frame it has played; once it has reported frame
    50 (so the bot has answered 50 frames of a match 200000 frames long: it is playing), the
    match is killed, and never finishes; the fixture then asserts the bot's processes are
    gone."""
    import select

    code = ("from spacewar.arena.match import play_match\n"
            "from spacewar import Rules\n"
            "def on_frame(game):\n"
            "    if int(game.frame[0]) % 25 == 0:\n"
            "        print('frame', int(game.frame[0]), flush=True)\n"
            "rules = Rules(star='none', max_round_frames=200_000, max_extra_rounds=0)\n"
            f"play_match('{HOSTILE}:{bot}', 'idle', seed=1, rounds=1, rules=rules, "
            "on_frame=on_frame)\n"
            "print('finished', flush=True)\n")
    match = subprocess.Popen([sys.executable, "-c", code], cwd=ROOT, stdout=subprocess.PIPE,
                             text=True)
    try:
        seen = []
        deadline = time.monotonic() + 120
        while "frame 50" not in seen and match.poll() is None and time.monotonic() < deadline:
            if select.select([match.stdout], [], [], 1.0)[0]:
                seen.append(match.stdout.readline().strip())
        assert seen[-1:] == ["frame 50"], seen  # the match reached frame 50, and is going on
        assert bot_processes(), "the bot is not running at frame 50"
    finally:
        match.send_signal(signal.SIGKILL)
        match.wait()
    rest = match.stdout.read().split("\n")
    match.stdout.close()
    assert match.returncode == -signal.SIGKILL
    assert "finished" not in rest, rest  # killed in the middle of the match


# -- resources and output -------------------------------------------------------------------------
def test_memory_hog_is_a_memory_fault():
    import dataclasses

    # ROOMY's budgets: its answer (a MemoryError at once) is never late, so each fault is
    # a memory fault whatever the machine's load
    result = play(f"{HOSTILE}:MemoryHog", max_faults=3,
                  limits=dataclasses.replace(ROOMY, memory_mb=512))
    f = result["faults"][0]
    assert f["memory"] == f["total"] == 3 and result["forfeits"] == [True, False], f


def test_output_is_captured_capped_and_never_the_match_s_stdout(capsys):
    args = ["match", "--p1", f"{HOSTILE}:Printer", "--p2", "sniper", "--seed", "3",
            "--rounds", "1", "--json"]
    assert main(args) == 0
    out = capsys.readouterr().out
    result = json.loads(out)  # the whole stdout is the one JSON result
    assert result["winner"] == "sniper"
    shown = result["output"][0]
    assert shown["text"].startswith('{"winner": "hostile"') and shown["truncated"]
    assert len(shown["text"]) <= 4096 and shown["bytes"] <= (1 << 16) + (1 << 20)


def test_disk_filler_is_stopped_by_its_scratch_limit():
    result = play(f"{HOSTILE}:DiskFiller")
    text = result["output"][0]["text"]
    assert "filler stopped after" in text
    assert int(text.split("after ")[1].split(" MiB")[0]) <= 64


def test_bot_cannot_read_other_files(tmp_path):
    secret_dir = tmp_path / "elsewhere"
    secret_dir.mkdir(mode=0o755)
    secret = secret_dir / "secret.txt"
    secret.write_text("TOP-SECRET-42")
    secret.chmod(0o644)  # readable by anyone: only the sandbox keeps the bot from it
    bot_dir = tmp_path / "bot"
    bot_dir.mkdir(mode=0o755)
    source = open(os.path.join(ROOT, "tests", "spacewar", "hostile_bots.py")).read()
    sibling = bot_dir / "other_bot.py"  # another author's bot in the same directory
    sibling.write_text("SIBLING-SOURCE-7")
    sibling.chmod(0o644)
    snooper = write_bot(bot_dir, source + f"\nSnooper.TARGETS = ({str(secret)!r}, {str(sibling)!r}, "
                                          f"{os.path.join(ROOT, 'tests', 'spacewar', 'test_match.py')!r})\n")
    result = play(f"{snooper}:Snooper")
    text = result["output"][0]["text"]
    assert "TOP-SECRET-42" not in text and "SIBLING-SOURCE-7" not in text and "root:" not in text
    assert text.count("BLOCKED") >= 5 and result["winner"] == "sniper"


def writer_attempts(text):
    """The ``{path: outcome}`` a Writer printed (hostile_bots.Writer); {} if it printed none."""
    import ast

    lines = [line for line in text.splitlines() if line.startswith("writer: ")]
    assert len(lines) <= 1, text
    return ast.literal_eval(lines[0][len("writer: "):]) if lines else {}


def check_writes_confined(text, refused):
    """The Writer's output shows it tried every path of ``refused`` and was refused each time
    (an OSError), and that it tried the control, a file in its scratch directory, and wrote
    and read it back: the write check was made, and made where a write succeeds; and no file
    of ``refused`` is there."""
    attempts = writer_attempts(text)
    control = [path for path in attempts if os.path.basename(path) == "writer-control.txt"]
    assert len(control) == 1 and attempts[control[0]] == "WRITTEN", attempts
    assert set(attempts) - set(control) == set(refused), (attempts, refused)
    for path in refused:
        assert attempts[path].startswith("BLOCKED "), (path, attempts[path])
        assert not os.path.lexists(path), path


def writer_targets(tmp_path):
    """Where the Writer tries to write: a directory anyone may write to (so that only the
    sandbox can refuse it), next to its own source file, into the project's package and into
    /tmp."""
    open_dir = tmp_path / "open"
    open_dir.mkdir()
    open_dir.chmod(0o777)
    return (str(open_dir / "planted.txt"), str(tmp_path / "planted.txt"),
            os.path.join(ROOT, "spacewar", "planted.py"), f"/tmp/spacewar-planted-{os.getpid()}")


def test_bot_cannot_write_outside_its_scratch_directory(tmp_path):
    source = open(os.path.join(ROOT, "tests", "spacewar", "hostile_bots.py")).read()
    targets = writer_targets(tmp_path)
    writer = write_bot(tmp_path, source + f"\nWriter.TARGETS = {targets!r}\n")
    result = play(f"{writer}:Writer")
    check_writes_confined(result["output"][0]["text"], targets)
    assert result["faults"][0]["total"] == 0 and result["winner"] == "sniper"


def test_the_write_check_fails_when_nothing_confines_the_writer(tmp_path, monkeypatch, capsys):
    """Positive controls for check_writes_confined: the same Writer run here, outside the
    sandbox, writes its target and the check fails; so it does on a bot that never tried."""
    from tests.spacewar.hostile_bots import Writer

    target = writer_targets(tmp_path)[0]
    monkeypatch.chdir(tmp_path)  # its control file goes here, not into the checkout
    monkeypatch.setattr(Writer, "TARGETS", (target,))
    Writer().reset()
    text = capsys.readouterr().out
    assert writer_attempts(text)[target] == "WRITTEN" and os.path.exists(target)
    with pytest.raises(AssertionError, match="WRITTEN"):  # (target, 'WRITTEN')
        check_writes_confined(text, (target,))
    os.remove(target)
    with pytest.raises(AssertionError):  # no attempt made: nothing shows the check was made
        check_writes_confined("", (target,))


def test_bot_cannot_change_metadata_or_grow_its_output_file(tmp_path):
    target = tmp_path / "victim.py"
    target.write_text("print('victim')\n")
    target.chmod(0o644)
    before = os.stat(target)
    source = open(os.path.join(ROOT, "tests", "spacewar", "hostile_bots.py")).read()
    bot = write_bot(tmp_path, source + f"\nMetadataVandal.TARGET = {str(target)!r}\n")
    result = play(f"{bot}:MetadataVandal")
    text = result["output"][0]["text"]
    assert "DONE" not in text and text.count("BLOCKED") == 8
    after = os.stat(target)
    assert (after.st_mode, after.st_mtime_ns) == (before.st_mode, before.st_mtime_ns)
    assert result["output"][0]["bytes"] < 4096


def test_a_forged_ready_message_is_text_not_code():
    result = play(f"{HOSTILE}:DeepReady", max_faults=3)
    assert result["winner"] == "sniper" and result["forfeits"] == [True, False]


def test_the_bot_is_stopped_between_its_turns():
    """Out of its turn a bot's process is stopped (SIGSTOP), so it cannot think ahead or take
    the CPU from the other bot; it runs again only when it is asked."""
    from spacewar.game.game import Game
    from spacewar.sandbox.process import ProcessSeat

    game = Game(SHORT, seeds=[1])
    seat = ProcessSeat(f"{HOSTILE}:DoNothing", 1, ROOMY, SHORT)
    try:
        assert seat.wait_ready() is None
        for _ in range(3):
            code, fault = seat.act(game.raw_observation(0, 0))
            assert fault is None
            assert _state_when_settled(seat) == "T"
    finally:
        seat.close()


def _children(pid):
    with open(f"/proc/{pid}/task/{pid}/children") as f:
        return [int(x) for x in f.read().split()]


def _state_when_settled(seat):
    """The bot host's process state: unshare -> the namespace's sh -> the host, or our child."""
    host = seat._proc.pid
    if seat._namespaces:
        host = _children(_children(host)[0])[0]
    for _ in range(2000):  # a stop signal is delivered asynchronously: wait until it is
        with open(f"/proc/{host}/stat") as f:
            state = f.read().rsplit(")", 1)[1].split()[0]
        if state == "T":
            return state
        time.sleep(0.005)
    return state


def test_bot_cannot_watch_directories(tmp_path):
    source = open(os.path.join(ROOT, "tests", "spacewar", "hostile_bots.py")).read()
    bot = write_bot(tmp_path, source + f"\nWatcher.TARGET = {str(tmp_path)!r}\n")
    result = play(f"{bot}:Watcher")
    assert "watcher: BLOCKED" in result["output"][0]["text"]


def test_fault_messages_cannot_redraw_the_terminal(capsys):
    assert main(["match", "--p1", f"{HOSTILE}:TerminalSpoofer", "--p2", "sniper", "--seed", "3",
                 "--rounds", "1"]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\\x1b[2K" in out
    assert out.splitlines()[0].startswith("sniper beats")


def test_bot_has_no_network(tmp_path):
    listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    listener.bind(("127.0.0.1", 0))
    listener.listen(1)
    listener.settimeout(0.2)
    unix_path = str(tmp_path / "sock")
    unix = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    unix.bind(unix_path)
    unix.listen(1)
    unix.settimeout(0.2)
    source = open(os.path.join(ROOT, "tests", "spacewar", "hostile_bots.py")).read()
    bot = write_bot(tmp_path, source + f"\nNetworker.PORT = {listener.getsockname()[1]}\n"
                                       f"Networker.UNIX_PATH = {unix_path!r}\n")
    try:
        result = play(f"{bot}:Networker")
        for server in (listener, unix):
            with pytest.raises(socket.timeout):
                server.accept()
    finally:
        listener.close()
        unix.close()
    assert "CONNECTED" not in result["output"][0]["text"]
    assert result["output"][0]["text"].count("BLOCKED") == 3


def test_sandbox_probe_reports_every_layer_here():
    from spacewar.sandbox.probe import probe

    findings = probe()
    assert findings["ok"], findings
    assert any(layer.startswith("landlock") for layer in findings["layers"])


# -- trusted bots in this process ------------------------------------------------------------------
class _ExitInline:
    def act(self, obs):
        if obs.frame % 3 == 0:
            raise SystemExit(1)
        if obs.frame % 3 == 1:
            raise KeyboardInterrupt
        class Bad:
            def __repr__(self):
                raise RuntimeError("repr bomb")
        return Bad()


class _CodeRaises:
    def act(self, obs):
        from spacewar import Action

        class A(Action):
            def code(self):
                raise SystemExit("from code()")
        return A(turn=1)


class _Mutator:
    """Writes into its observation and its rules: neither may reach the game."""

    def __init__(self):
        self.errors = 0

    def act(self, obs):
        object.__setattr__(obs.rules, "torpedoes", 1)
        object.__setattr__(obs.rules, "star_mu", 0.0)
        try:
            obs.me.pos[0] = 0.25
        except ValueError:
            self.errors += 1
        return NOOP_ACTION


NOOP_ACTION = __import__("spacewar").NOOP


def test_inline_bot_exits_and_bad_reprs_are_faults():
    result = play(_ExitInline(), max_faults=9)
    f = result["faults"][0]
    assert f["raised"] == 6 and f["invalid"] == 3
    assert result["forfeits"] == [True, False]


def test_inline_code_override_is_ignored():
    result = play(_CodeRaises(), "idle", max_faults=3)
    assert result["faults"][0]["total"] == 0  # the fields are valid; the override never runs


def test_inline_bot_mutating_its_observation_changes_nothing(tmp_path):
    from spacewar import replay as replay_io

    bot = _Mutator()
    result, rep, _ = play_match(bot, "sniper", seed=3, rounds=1, rules=SHORT, record=True)
    assert bot.errors > 0  # the arrays are read-only
    assert result["rules"] == SHORT.to_dict()
    ok, details = replay_io.check(rep)
    assert ok, details


# serial (docs/testing.md): a worker process per core of its own and seven confined bots, some
# burning a core or memory, while the honest bot is held to a wall-clock budget
@pytest.mark.serial
def test_a_tournament_of_hostile_bots_finishes_with_an_honest_table(capsys):
    hostile = ["PickleBomb", "RawBytes", "EndlessLoop", "Forker", "Printer", "MemoryHog"]
    bots = [f"{HOSTILE}:{b}" for b in hostile] + ["sniper"]
    # 500 ms: over 100x sniper's p99 act time (2.4-4.2 ms, measured on this 2-core machine
    # while it ran other suites: 1197 actions), so the honest bot is never late however loaded
    # the machine; the never-answering EndlessLoop is stopped all the same
    args = ["tournament", "--bots", ",".join(bots), "--games", "1", "--rounds", "1",
            "--workers", "2", "--json", "--budget-ms", "500", "--overage-ms", "200",
            "--bot-memory-mb", "512"]
    assert main(args) == 0
    report = json.loads(capsys.readouterr().out)  # stdout holds the report and nothing else
    rows = {r["bot"]: r for r in report["table"]}
    assert rows["sniper"]["wins"] == rows["sniper"]["played"] == 12
    assert report["table"][0]["bot"] == "sniper"
    for name in ("RawBytes", "EndlessLoop", "MemoryHog"):
        assert rows[f"{HOSTILE}:{name}"]["forfeits"] >= 1
    assert rows["sniper"]["faults"] == 0  # the honest bot lost no turn


class _ResetExits:
    def reset(self):
        raise SystemExit("bye")

    def act(self, obs):
        return NOOP_ACTION


class _RulesHunter:
    """Looks for any Rules object reachable from its observation and breaks it."""

    def act(self, obs):
        for value in vars(obs).values():
            if isinstance(value, Rules):
                object.__setattr__(value, "torpedoes", 1)
        return NOOP_ACTION


def test_inline_bot_object_failing_to_reset_forfeits():
    result = play(_ResetExits(), "idle")
    assert result["faults"][0]["startup"] == 1 and result["forfeits"] == [True, False]
    assert "SystemExit: bye" in result["faults"][0]["examples"][0]["message"]


def test_inline_bot_reaches_no_rules_but_its_own_copy():
    result = play(_RulesHunter(), "sniper")
    assert result["winner"] == "sniper" and result["rules"] == SHORT.to_dict()


def test_a_process_that_cannot_start_is_a_start_up_fault(monkeypatch):
    import spacewar.sandbox.process

    def refuse(*args, **kwargs):
        raise BlockingIOError(11, "Resource temporarily unavailable")

    monkeypatch.setattr(spacewar.sandbox.process.subprocess, "Popen", refuse)
    open_fds = len(os.listdir("/proc/self/fd"))
    for _ in range(3):
        result = play(f"{HOSTILE}:DoNothing", "idle")
        assert result["forfeits"] == [True, False]
        assert "could not start its process" in result["faults"][0]["examples"][0]["message"]
    assert len(os.listdir("/proc/self/fd")) == open_fds  # no pipe or file left open


@pytest.mark.parametrize("option, value", [("--startup-s", "1e12"), ("--overage-ms", "1e308"),
                                           ("--budget-ms", "1e300")])
def test_absurd_budgets_are_refused_before_any_bot_starts(capsys, option, value):
    assert main(["match", "--p1", "idle", "--p2", "idle", "--isolation", "process",
                 option, value]) == 2
    assert "must be a number of seconds" in capsys.readouterr().err


def test_an_answer_sent_ahead_of_its_question_is_a_breach():
    result = play(f"{HOSTILE}:PreAnswer", max_faults=1000)
    assert result["forfeits"] == [True, False]
    assert "answered before being asked" in result["faults"][0]["last"]["message"]


def test_no_system_v_shared_memory():
    result = play(f"{HOSTILE}:SharedMemoryHog")
    assert "shm: BLOCKED errno 1" in result["output"][0]["text"]


def test_a_bot_copies_only_this_checkout_s_compiled_code(tmp_path, monkeypatch):
    """The compiled-code directories of the same sources hold a subdirectory for every checkout
    that compiled them (numba names it after the source directory's path); a bot's scratch gets
    this checkout's only, else a few other checkouts fill its tmpfs (the bot then finds its
    copies cut short)."""
    import hashlib

    from engine.cache import cache_dir
    from spacewar.sandbox import provision

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    here = os.path.join(provision.PROJECT_ROOT, "spacewar")
    elsewhere = "/elsewhere/checkout/spacewar"
    mine, other = (os.path.join(cache_dir("spacewar"), "spacewar_" + hashlib.sha1(
        path.encode()).hexdigest()) for path in (here, elsewhere))
    for directory in (mine, other):
        os.makedirs(directory)
        with open(os.path.join(directory, "learning.f-1.py311.nbi"), "wb") as f:
            f.write(b"index")
    pairs = provision.compiled_code_dirs.__wrapped__()
    assert [source for source, _, _ in pairs] == [mine]
    assert pairs[0][1] == os.path.relpath(mine, str(tmp_path))
    assert "learning" in pairs[0][2] and "rules" in pairs[0][2]  # the modules spacewar/ has


def test_a_bot_copies_no_compiled_code_of_a_module_since_moved(tmp_path):
    """numba names each cache file after its module: the files of a module that moved to a
    subpackage (or was removed) stay in the old directory's cache, and are not copied."""
    from spacewar.sandbox.confinement import _copy_compiled_code

    source = tmp_path / "cache" / "spacewar_abc"
    source.mkdir(parents=True)
    for name in ("rules.f-1.py311.nbi", "rules.f-1.py311.1.nbc", "core.step-9.py311.nbi",
                 "core.step-9.py311.1.nbc"):
        (source / name).write_bytes(b"x")
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    _copy_compiled_code([(str(source), "pkg/spacewar_abc", ["rules", "protocol"])], str(scratch),
                        budget_bytes=1 << 20, budget_files=100)
    copied = sorted(p.name for p in scratch.rglob("*") if p.is_file())
    assert copied == ["rules.f-1.py311.1.nbc", "rules.f-1.py311.nbi"]


def test_compiled_code_is_copied_whole_within_its_budget_or_not_at_all(tmp_path, monkeypatch):
    import shutil

    from spacewar.sandbox.confinement import _copy_compiled_code

    pairs = []
    # a tmpfs charges whole 4 KiB pages: a takes 3, b 7 (1, 2 and 3 for its data files, 1 for
    # its index), c 3
    for name, sizes in (("a", [300, 200]), ("b", [600, 5000, 9000]), ("c", [100, 100])):
        source = tmp_path / "cache" / name
        source.mkdir(parents=True)
        for i, size in enumerate(sizes):
            (source / f"f{i}.nbc").write_bytes(b"x" * size)
        (source / "f.nbi").write_bytes(b"i" * 10)
        pairs.append((str(source), f"pkg/{name}"))
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    _copy_compiled_code(pairs, str(scratch), budget_bytes=7 * 4096, budget_files=100)
    copied = sorted(p.relative_to(scratch).as_posix() for p in scratch.rglob("*") if p.is_file())
    assert copied == ["numba/pkg/a/f.nbi", "numba/pkg/a/f0.nbc", "numba/pkg/a/f1.nbc",
                      "numba/pkg/c/f.nbi", "numba/pkg/c/f0.nbc", "numba/pkg/c/f1.nbc"]

    # a disk that fills during a copy leaves no truncated file (numba would fail to read a
    # truncated index; a missing one only means a compile), and the bot still starts
    real = shutil.copyfile

    def filling(source, target):
        if os.path.basename(source) == "f1.nbc":
            with open(target, "wb") as f:
                f.write(b"x" * 10)
            raise OSError(28, "No space left on device")
        return real(source, target)

    monkeypatch.setattr(shutil, "copyfile", filling)
    full = tmp_path / "full"
    full.mkdir()
    _copy_compiled_code(pairs, str(full), budget_bytes=1 << 20, budget_files=100)
    left = sorted(p.relative_to(full).as_posix() for p in full.rglob("*") if p.is_file())
    assert left == ["numba/pkg/a/f0.nbc"]
