"""A bot author's first hour: the conventions a bot relies on, ``spacewar new-bot``,
``spacewar check``, how ``module:Class`` is found, and ``play_match`` from Python.

Bots named by a file run confined (as nobody when the tests run as root), so their files are
written to a directory anyone may read.
"""
import json
import math
import pathlib
import shutil
import subprocess
import sys
import tempfile
import textwrap

import numpy as np
import pytest

import spacewar
from spacewar import NOOP, Action, Game, Rules
from spacewar.bots import BotLoadError, locate, make_bot
from spacewar.bots import geometry
from spacewar.bots.geometry import angle_diff, heading_after, launch_state, torus_delta, wrap
from spacewar.author.check import check_bot, play_fingerprint
from spacewar.cli import main
from spacewar.arena.match import act_time_summary, play_match
from spacewar.sandbox.limits import Limits
from spacewar.sandbox.process import ProcessSeat
from spacewar.arena.seats import open_seat
from spacewar.author.new_bot import class_name_for, starter_source, write_starter

# budgets long enough that an honest answer is never late on a loaded machine: these tests
# assert what a bot does, not how fast the machine is
ROOMY = Limits(budget=2.0, overage=20.0, startup=60.0, stop_after=0.5)
SHORT = Rules(max_round_frames=400, post_round_delay=8)  # a drawn round ends soon
TINY = Rules(max_round_frames=100, post_round_delay=8, max_extra_rounds=0)  # about 108 frames
NO_STAR = Rules(star="none")

on_linux = pytest.mark.skipif(not sys.platform.startswith("linux"),
                              reason="confined bots are checked on Linux")


@pytest.fixture
def shared_dir():
    """A directory anyone may read: a confined bot may run as nobody."""
    path = pathlib.Path(tempfile.mkdtemp(prefix="spacewar-author-"))
    path.chmod(0o755)
    yield path
    shutil.rmtree(path, ignore_errors=True)


def write_bot(directory, source, name="bot.py"):
    path = directory / name
    path.write_text(textwrap.dedent(source))
    path.chmod(0o644)
    return str(path)


def one_frame(game, *actions):
    game.step([list(actions) + [NOOP] * (2 - len(actions))])
    return game.observe(0, 0)


# -- conventions ------------------------------------------------------------------------------
def test_heading_zero_thrusting_moves_plus_x():
    """Turn the seat-0 ship (it starts facing -y, heading -pi/2) to heading 0, then thrust:
    the velocity gains exactly rules.thrust along +x and the position moves by that velocity."""
    game = Game(NO_STAR, seeds=[0], rounds=1)
    start = game.observe(0, 0).me
    assert start.heading == -math.pi / 2 and start.vel.tolist() == [0.0, 0.0]
    for _ in range(25):  # a quarter turn at 2 pi / 100 a frame
        obs = one_frame(game, Action(turn=1))
    assert abs(obs.me.heading) < 1e-12
    before = obs.me
    after = one_frame(game, Action(thrust=True)).me
    dv = after.vel - before.vel
    assert dv[0] == NO_STAR.thrust * math.cos(before.heading)
    assert dv[1] == NO_STAR.thrust * math.sin(before.heading)
    assert dv[0] > 0 and abs(dv[1]) < 1e-18
    assert after.pos[0] - before.pos[0] == pytest.approx(dv[0], rel=1e-9)
    assert 0.5 <= NO_STAR.fuel - after.fuel <= 1.5  # one thrusting frame's burn


def test_turn_plus_one_is_anticlockwise_and_headings_stay_in_range():
    game = Game(NO_STAR, seeds=[0], rounds=1)
    heading = game.observe(0, 0).me.heading
    obs = one_frame(game, Action(turn=1))
    assert obs.me.heading == heading + NO_STAR.turn_rate  # anticlockwise: the angle grows
    obs = one_frame(game, Action(turn=-1))
    assert obs.me.heading == pytest.approx(heading, abs=1e-15)
    seen = []
    for _ in range(120):  # more than a full turn: the heading wraps at pi
        seen.append(one_frame(game, Action(turn=1)).me.heading)
    assert all(-math.pi < h <= math.pi for h in seen)
    jumps = [b - a for a, b in zip(seen, seen[1:])]
    assert sum(j < 0 for j in jumps) == 1  # one wrap from near +pi to near -pi
    assert all(j == pytest.approx(NO_STAR.turn_rate) for j in jumps if j > 0)


def test_turn_plus_one_under_angular_momentum_speeds_the_turn_up_anticlockwise():
    rules = Rules(star="none", angular_momentum=True)
    game = Game(rules, seeds=[0], rounds=1)
    h0 = game.observe(0, 0).me.heading
    obs = one_frame(game, Action(turn=1))
    assert obs.me.angular_velocity == rules.angular_accel
    assert obs.me.heading == pytest.approx(h0 + rules.angular_accel, abs=1e-15)


def test_torus_delta_takes_the_nearest_image_across_the_edge():
    # binary fractions: every difference below is exact
    assert torus_delta((0.375, 0.0), (-0.375, 0.125)).tolist() == [0.25, 0.125]
    assert torus_delta((-0.375, 0.0), (0.375, 0.0)).tolist() == [-0.25, 0.0]
    assert torus_delta((0.0, -0.4375), (0.0, 0.4375)).tolist() == [0.0, -0.125]
    assert torus_delta((0.125, 0.125), (0.25, 0.0)).tolist() == [0.125, -0.125]  # no edge
    pairs = torus_delta(np.array([[0.375, 0.0], [0.0, 0.0]]), np.array([[-0.375, 0.0],
                                                                        [0.25, 0.25]]))
    assert pairs.tolist() == [[0.25, 0.0], [0.25, 0.25]]
    assert wrap(0.75) == -0.25 and wrap(-0.5) == -0.5 and wrap(0.5) == -0.5
    assert geometry.torus_distance((0.375, 0.375), (-0.375, -0.375)) == math.hypot(0.25, 0.25)
    assert geometry.bearing((0.375, 0.0), (-0.375, 0.0)) == 0.0  # to the right, across the edge


def test_angle_diff_is_the_signed_short_way_round():
    assert angle_diff(0.25, -0.25) == 0.5
    assert angle_diff(-0.25, 0.25) == -0.5
    assert angle_diff(-3.0, 3.0) == pytest.approx(2 * math.pi - 6.0)  # across the seam: > 0
    assert angle_diff(math.pi, 0.0) == math.pi and angle_diff(-math.pi, 0.0) == math.pi
    assert geometry.turn_towards(3.0, -3.0, Rules()) == 1  # anticlockwise across the seam
    assert geometry.turn_towards(-3.0, 3.0, Rules()) == -1


def test_positions_wrap_and_torus_delta_recovers_each_frames_velocity():
    """A ship thrusting down leaves the bottom edge and comes back at the top; from frame to
    frame the nearest-image displacement is the velocity (``pos = wrap(pos + vel)``)."""
    game = Game(NO_STAR, seeds=[0], rounds=1)
    obs = game.observe(0, 0)
    assert obs.me.heading == -math.pi / 2
    wrapped = False
    for _ in range(400):
        before = obs.me.pos.copy()
        obs = one_frame(game, Action(thrust=True))
        assert -0.5 <= obs.me.pos[1] < 0.5
        assert torus_delta(before, obs.me.pos) == pytest.approx(obs.me.vel, abs=1e-15)
        wrapped |= obs.me.pos[1] - before[1] > 0.5
    assert wrapped


def test_a_torpedo_leaves_along_the_heading_after_this_frame_s_turn():
    game = Game(NO_STAR, seeds=[0], rounds=1)
    ship = game.observe(0, 0).me
    heading = heading_after(ship, 1, NO_STAR)
    obs = one_frame(game, Action(turn=1, fire=True))
    (torpedo,) = obs.torpedoes
    p0, v0 = launch_state(ship, heading, NO_STAR)
    assert torpedo.mine and torpedo.vel.tolist() == v0.tolist()
    assert torpedo.ttl == NO_STAR.torpedo_life - 1  # frames left before it bursts
    assert torpedo.pos == pytest.approx(p0 + v0, abs=1e-15)  # launched, then one frame's drift
    assert obs.me.reload == NO_STAR.reload and obs.me.torpedoes == NO_STAR.torpedoes - 1
    assert one_frame(game).me.reload == NO_STAR.reload - 1  # frames to wait, counting down


def test_observation_units_and_own_side():
    heavy = Game(Rules(), seeds=[0], rounds=1)
    obs = heavy.observe(0, 0)
    assert obs.star_mu == 2.5e-7 and obs.star_pos.tolist() == [0.0, 0.0]
    assert obs.star_capture == 8 / 1024
    assert obs.me.fuel == 1000.0 and obs.me.torpedoes == 32 and obs.me.hyperspace == 8
    assert obs.me.angular_velocity == 0.0 and obs.me.charge == 0.0
    assert (obs.frame, obs.round_frame, obs.round, obs.score, obs.seat) == (0, 0, 0, (0, 0), 0)
    assert Game(Rules(star="light"), seeds=[0]).observe(0, 0).star_mu == 2.5e-7 / 4
    assert Game(NO_STAR, seeds=[0]).observe(0, 0).star_mu == 0.0
    other = heavy.observe(0, 1)  # the other seat sees itself as me
    assert other.seat == 1 and other.me.pos.tolist() == obs.enemy.pos.tolist()
    assert other.enemy.pos.tolist() == obs.me.pos.tolist()


def test_geometry_exports_and_their_re_exports():
    for name in geometry.__all__:
        assert hasattr(geometry, name), name
    namespace = {}
    exec("from spacewar.bots.geometry import *", namespace)
    assert {"torus_delta", "angle_diff", "wrap", "periapsis", "lead_straight"} <= set(namespace)
    from spacewar import bots
    from spacewar.bots import angle_diff as re_exported, torus_delta as delta

    assert delta is geometry.torus_delta and re_exported is geometry.angle_diff
    for name in bots.GEOMETRY_EXPORTS:
        assert getattr(bots, name) is getattr(geometry, name)
    with pytest.raises(AttributeError, match="no_such_helper"):
        bots.no_such_helper


def test_importing_the_bots_package_does_not_load_the_engine():
    code = "import sys, spacewar.bots; print('engine' in sys.modules, 'numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=120).stdout.split()
    assert out == ["False", "False"]


def test_importing_the_bot_helpers_and_the_chaser_does_not_load_the_engine():
    """A bot built on the geometry helpers starts without numba (a confined process is ready
    in tenths of a second); only a prediction along a conic loads the compiled Kepler solver."""
    code = ("import sys, spacewar.bots.geometry as g, spacewar.bots.chaser\n"
            "print('engine' in sys.modules, 'numba' in sys.modules)\n"
            "g.predict_path([0.2, 0.1], [1e-4, 2e-4], 2.5e-7, [1.0, 2.0])\n"
            "print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=120).stdout.split()
    assert out == ["False", "False", "True"]


def test_the_helpers_wrap_is_the_engines_bit_for_bit():
    from engine import space

    rng = np.random.default_rng(5)
    x = np.concatenate([rng.uniform(-3.0, 3.0, 10_000), [-0.5, 0.5, 0.49999999999999994,
                                                          -0.5000000000000001, 1.5, -1.5, 0.0]])
    np.testing.assert_array_equal(geometry.wrap(x), space.wrap(x, 1.0))
    d = rng.uniform(-0.5, 0.5, (1000, 2)), rng.uniform(-0.5, 0.5, (1000, 2))
    np.testing.assert_array_equal(geometry.torus_delta(*d), space.nearest_image(d[1] - d[0], 1.0))
    assert geometry.wrap(0.7) == space.wrap(0.7, 1.0)


# -- new-bot ----------------------------------------------------------------------------------
def test_class_names_and_sources():
    assert [class_name_for(n) for n in ("hunter", "my_bot", "bot2", "_x", "_", "myBot")] == \
        ["Hunter", "MyBot", "Bot2", "X", "Bot", "MyBot"]
    source = starter_source("my_bot")
    compile(source, "my_bot.py", "exec")
    assert "class MyBot:" in source and "spacewar check my_bot.py:MyBot" in source
    assert "__" + "CLASS__" not in source and "__" + "SPEC__" not in source


@on_linux
def test_new_bot_writes_a_bot_that_loads_confined_and_beats_idle(shared_dir, monkeypatch,
                                                                 capsys):
    monkeypatch.chdir(shared_dir)
    assert main(["new-bot", "hunter"]) == 0
    out = capsys.readouterr().out
    assert "wrote hunter.py" in out
    assert "spacewar match --p1 hunter.py:Hunter --p2 idle" in out
    assert "spacewar check hunter.py:Hunter" in out
    assert (shared_dir / "hunter.py").stat().st_mode & 0o044 == 0o044  # others may read it
    seat = open_seat("hunter.py:Hunter", 0, ROOMY)
    try:  # a file bot: its own confined process, which imports and builds it
        assert isinstance(seat, ProcessSeat) and seat.wait_ready() is None
    finally:
        seat.close()
    result, _, _ = play_match("hunter.py:Hunter", "idle", seed=0, rounds=2, limits=ROOMY)
    assert result["winner"] == "hunter.py:Hunter" and result["score"][0] > result["score"][1]
    assert result["faults"][0]["total"] == 0 and result["forfeits"] == [False, False]


def test_the_starter_trades_hits_with_chaser(shared_dir):
    """In this process (the test trusts it): with seed 0 it destroys chaser's ship, and
    chaser takes some of its torpedoes' hits too, without a fault."""
    path, spec = write_starter("hunter", str(shared_dir))
    assert path == str(shared_dir / "hunter.py") and spec == f"{path}:Hunter"
    chaser_deaths = []

    def watch(game):
        alive = bool(game.observe(0, 1).me.alive)
        if chaser_deaths[-1:] != [alive]:
            chaser_deaths.append(alive)

    result, _, _ = play_match(make_bot(spec), "chaser", seed=0, rounds=1, on_frame=watch)
    assert False in chaser_deaths  # chaser's ship was destroyed
    assert result["faults"][0]["total"] == 0 and result["forfeit"] is None


def test_new_bot_refuses_to_overwrite_and_bad_names(shared_dir, monkeypatch, capsys):
    monkeypatch.chdir(shared_dir)
    mine = shared_dir / "hunter.py"
    mine.write_text("# my own work\n")
    assert main(["new-bot", "hunter"]) == 2
    assert "refusing to overwrite 'hunter.py'" in capsys.readouterr().err
    assert mine.read_text() == "# my own work\n"
    for name, words in (("2fast", "not starting with a digit), got '2fast'"),
                        ("my-bot", "got 'my-bot'"),
                        ("class", "keyword, got 'class'"), ("json", "'json' is the name of a "
                                                                   "standard-library module")):
        assert main(["new-bot", name]) == 2
        assert words in capsys.readouterr().err
    assert main(["new-bot", "x", "--out", "x.txt"]) == 2
    assert "--out must be a .py file or an existing directory, got 'x.txt'" in \
        capsys.readouterr().err
    assert main(["new-bot", "x", "--out", "missing/x.py"]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert sorted(p.name for p in shared_dir.iterdir()) == ["hunter.py"]  # nothing else made
    (shared_dir / "bots").mkdir()
    assert main(["new-bot", "hunter", "--out", "bots"]) == 0
    assert "class Hunter:" in (shared_dir / "bots" / "hunter.py").read_text()
    with pytest.raises(FileExistsError, match="hunter.py"):
        write_starter("hunter", str(shared_dir / "bots"))
    assert [p.name for p in (shared_dir / "bots").iterdir()] == ["hunter.py"]  # no temporary


# -- check ------------------------------------------------------------------------------------
@on_linux
def test_check_passes_the_starter(shared_dir):
    path, spec = write_starter("hunter", str(shared_dir))
    seen = []
    report = check_bot(spec, opponents=["idle", "chaser"], rules=SHORT, limits=ROOMY,
                       on_match=seen.append)
    assert report.passed and report.reasons == [] and report.load_error is None
    assert report.deterministic is True and "identical" in report.determinism
    assert [(m["opponent"], m["seat"]) for m in report.matches] == \
        [("idle", 0), ("idle", 1), ("chaser", 0), ("chaser", 1)]
    assert [m.get("repeat", False) for m in seen] == [False] * 4 + [True]
    assert sum(report.faults.values()) == 0 and report.forfeits == 0
    act = report.act
    assert act["count"] >= sum(m["frames"] for m in report.matches)
    assert 0 < act["p50"] <= act["p95"] <= act["p99"] <= act["max"]
    assert report.budget == ROOMY.budget and report.over_budget == 0
    text = report.format()
    assert text.startswith(f"PASS: {spec}") and "p99" in text and "deterministic: yes" in text
    json.dumps(report.to_dict())  # plain data


@on_linux
def test_check_cli_exit_codes(shared_dir, monkeypatch, capsys):
    monkeypatch.chdir(shared_dir)
    write_starter("hunter")
    common = ["--opponents", "idle", "--budget-ms", "2000", "--startup-s", "60", "--star", "none"]
    assert main(["check", "hunter.py:Hunter", *common, "--no-progress"]) == 0
    assert capsys.readouterr().out.startswith("PASS: hunter.py:Hunter")
    assert main(["check", "nothere.py:Hunter", *common, "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["passed"] is False and report["matches"] == []
    assert "bot file 'nothere.py' does not exist" in report["load_error"]
    assert main(["check", "hunter.py:Hunter", "--opponents", "nosuch"]) == 2
    assert "unknown bot 'nosuch'" in capsys.readouterr().err


@on_linux
def test_check_fails_a_raising_bot_with_its_fault_kind(shared_dir, capsys):
    spec = write_bot(shared_dir, """
        class Raiser:
            def act(self, obs):
                raise RuntimeError("no idea what to do")
    """) + ":Raiser"
    report = check_bot(spec, opponents=["idle"], rules=SHORT, limits=ROOMY, max_faults=5)
    assert not report.passed and report.load_error is None
    assert report.faults == {"raised": 10, "invalid": 0, "timeout": 0, "crashed": 0,
                             "startup": 0, "memory": 0}  # 5 a match, then it forfeits
    assert report.forfeits == 2 and [m["outcome"] for m in report.matches] == ["loss", "loss"]
    assert report.reasons[0].startswith("10 fault(s) in 2 matches (10 raised); the first: "
                                        "raised: RuntimeError: no idea what to do")
    assert "it forfeited 2 of 2 matches" in report.reasons
    assert report.fault_examples[0]["frame"] == 0 and report.fault_examples[0]["seat"] == 0
    assert report.deterministic is True  # it fails the same way every time
    assert main(["check", spec, "--opponents", "idle", "--budget-ms", "2000",
                 "--startup-s", "60", "--max-faults", "5", "--no-progress"]) == 1
    out = capsys.readouterr().out
    assert out.startswith(f"FAIL: {spec}") and "faults: 10 (raised 10); forfeits: 2" in out


@on_linux
def test_check_fails_hostile_answers_and_a_bot_that_dies(shared_dir):
    spec = write_bot(shared_dir, """
        import os

        from spacewar import NOOP


        class Forger:
            def act(self, obs):
                return "thrust please"


        class Quitter:
            def act(self, obs):
                if obs.frame == 3:
                    os._exit(0)
                return NOOP
    """)
    forger = check_bot(f"{spec}:Forger", opponents=["idle"], rules=SHORT, limits=ROOMY,
                       max_faults=3)
    assert not forger.passed and forger.faults["invalid"] == 6
    assert "6 invalid" in forger.reasons[0] and "not an Action: str" in forger.reasons[0]
    quitter = check_bot(f"{spec}:Quitter", opponents=["idle"], rules=SHORT, limits=ROOMY)
    assert not quitter.passed and quitter.faults["crashed"] == 2 and quitter.forfeits == 2
    assert "it forfeited 2 of 2 matches" in quitter.reasons


@on_linux
@pytest.mark.parametrize("bot, kind", [("ForgedTurn", "invalid"), ("RawBytes", "invalid"),
                                       ("ExitInAct", "raised")])
def test_check_fails_the_catalogue_s_attackers(bot, kind):
    """Bots from tests/spacewar/hostile_bots.py (a module found from the repository's root,
    where the tests run), each loaded confined as a tournament would."""
    spec = f"tests.spacewar.hostile_bots:{bot}"
    report = check_bot(spec, opponents=["idle"], rules=TINY, limits=ROOMY, max_faults=3)
    assert not report.passed and report.load_error is None and report.faults[kind] > 0
    assert f"{report.faults[kind]} {kind}" in report.reasons[0]


@on_linux
def test_check_fails_a_nondeterministic_bot_and_names_the_frame(shared_dir):
    spec = write_bot(shared_dir, """
        import random

        from spacewar import Action


        class Dice:
            def act(self, obs):  # an unseeded generator: seeded from the OS at import
                return Action(turn=random.choice((-1, 0, 1)), fire=random.random() < 0.1)
    """) + ":Dice"
    report = check_bot(spec, opponents=["idle"], rules=SHORT, limits=ROOMY)
    assert report.deterministic is False and not report.passed
    assert sum(report.faults.values()) == 0
    reason = [r for r in report.reasons if r.startswith("it is not deterministic")]
    assert len(reason) == 1 and "seed 0 against idle from seat 1, played twice" in reason[0]
    assert "its action at frame " in reason[0] and "random.Random(seed)" in reason[0]


@on_linux
def test_check_fails_a_bot_whose_slow_tail_lives_on_the_overage_bank(shared_dir):
    """One action in ten sleeps 60 ms against a 50 ms budget: no timeout (the bank is large),
    but the p99 is over the budget, which a long match would not survive."""
    spec = write_bot(shared_dir, """
        import time

        from spacewar import NOOP


        class Ponderer:
            def act(self, obs):
                if obs.frame % 10 == 0:
                    time.sleep(0.06)
                return NOOP
    """) + ":Ponderer"
    limits = Limits(budget=0.05, overage=600.0, startup=60.0)
    report = check_bot(spec, opponents=["idle"], rules=TINY, limits=limits)
    assert report.faults["timeout"] == 0
    assert report.act["p99"] > 0.06 and report.over_budget >= report.act["count"] // 10
    assert not report.passed
    assert any(r.startswith("p99 action time") and "over the budget of 50 ms" in r
               for r in report.reasons)


@pytest.mark.serial  # the 99th percentile of its answer times, on the wall clock, under a budget
@on_linux
def test_warnings_do_not_fail_a_bot(shared_dir):
    """One slow answer a match (paid from the bank) and printed output that differs between
    two plays of a seed: warned about, and still a pass."""
    spec = write_bot(shared_dir, """
        import time

        from spacewar import NOOP


        class Chatty:
            def act(self, obs):
                print(time.perf_counter_ns())
                if obs.frame == 5:
                    time.sleep(0.6)
                return NOOP
    """) + ":Chatty"
    # a budget far above what an answer of this bot needs, except the one that sleeps
    limits = Limits(budget=0.5, overage=600.0, startup=60.0)
    report = check_bot(spec, opponents=["idle"], rules=TINY, limits=limits)
    assert report.passed and report.reasons == [] and report.deterministic is True
    assert report.over_budget >= 2 and report.act["p99"] < limits.budget < report.act["max"]
    assert len(report.warnings) == 2 and report.output_bytes > 0
    assert report.warnings[0].startswith("what it prints differs between two plays")
    assert report.warnings[1].endswith("went over the budget of 500 ms (paid from the overage "
                                       "bank)")


@on_linux
def test_check_fails_a_bot_that_times_out(shared_dir):
    spec = write_bot(shared_dir, """
        import time

        from spacewar import NOOP


        class Sleeper:
            def act(self, obs):
                time.sleep(0.5)
                return NOOP
    """) + ":Sleeper"
    fast = Limits(budget=0.02, overage=0.0, startup=60.0, stop_after=5.0)
    report = check_bot(spec, opponents=["idle"], rules=SHORT, limits=fast, max_faults=3)
    assert not report.passed and report.faults["timeout"] == 6 and report.forfeits == 2
    assert "6 timeout" in report.reasons[0]


@on_linux
@pytest.mark.parametrize("source, words", [
    ("raise ImportError('missing a dependency')\n", "ImportError: missing a dependency"),
    ("import os\nos._exit(7)\n", "died while starting"),
    ("class Bot:\n    def __init__(self):\n        raise ValueError('bad config')\n"
     "    def act(self, obs):\n        return None\n", "ValueError: bad config"),
])
def test_check_reports_a_bot_that_does_not_load(shared_dir, source, words):
    spec = write_bot(shared_dir, source) + ":Bot"
    report = check_bot(spec, opponents=["idle"], rules=SHORT, limits=ROOMY)
    assert not report.passed and report.matches == [] and report.deterministic is None
    assert words in report.load_error and report.reasons == [f"it does not load: "
                                                             f"{report.load_error}"]
    assert report.format().startswith(f"FAIL: {spec}\n  reason: it does not load: ")


def test_check_refuses_bad_arguments_before_playing():
    with pytest.raises(ValueError, match="games must be an int >= 1, got 0"):
        check_bot("idle", games=0)
    with pytest.raises(ValueError, match="seed must be an int >= 0, got -1"):
        check_bot("idle", seed=-1)
    with pytest.raises(ValueError, match="rounds must be an int >= 1, got 0"):
        check_bot("idle", rounds=0)
    with pytest.raises(ValueError, match="opponents must name at least one bot"):
        check_bot("idle", opponents=[])
    with pytest.raises(BotLoadError, match="unknown bot 'nobody'"):
        check_bot("idle", opponents=["idle", "nobody"])
    with pytest.raises(TypeError, match=r"the class Idle: pass an instance, Idle\(\)"):
        check_bot(type("Idle", (), {"act": lambda self, obs: NOOP}))
    with pytest.raises(TypeError, match="rules must be a spacewar.Rules"):
        check_bot("idle", rules={"star": "none"})
    with pytest.raises(ValueError, match="isolation must be auto or process, got 'inline'"):
        check_bot("idle", isolation="inline")


def test_check_takes_bot_objects_and_built_in_names():
    class Steady:
        def act(self, obs):
            return Action(turn=1)

    report = check_bot(Steady(), opponents=["idle"], rules=SHORT)
    assert report.passed and report.bot.endswith("Steady") and report.deterministic is True
    assert check_bot("chaser", opponents=["idle"], rules=SHORT).passed


def test_play_fingerprint_sees_the_play_not_the_output():
    result, replay, _ = play_match("chaser", "idle", seed=2, rounds=1, rules=SHORT, record=True)
    base = play_fingerprint(result, replay)
    printed = {**result, "output": [{"text": "hello", "bytes": 5, "truncated": False}] * 2}
    assert play_fingerprint(printed, replay) == base
    assert play_fingerprint(result, {**replay, "final_state_sha256": "0" * 64}) != base
    assert play_fingerprint({**result, "score": [9, 9]}, replay) != base


def test_act_time_summary_percentiles():
    summary = act_time_summary(np.arange(101) / 1000.0)
    assert summary == {"count": 101, "mean": pytest.approx(0.05), "p50": 0.05, "p95": 0.095,
                       "p99": 0.099, "max": 0.1}
    assert act_time_summary([]) == {"count": 0, "mean": None, "p50": None, "p95": None,
                                    "p99": None, "max": None}


# -- how module:Class is found ----------------------------------------------------------------
HUNTER = """
from spacewar import Action


class Hunter:
    def act(self, obs):
        return Action(turn=1, fire=obs.me.reload == 0)
"""


@on_linux
def test_a_module_in_the_current_directory_loads_confined(shared_dir, monkeypatch, capsys):
    write_bot(shared_dir, HUNTER, "mybot.py")
    monkeypatch.chdir(shared_dir)
    read, listed, home = locate("mybot:Hunter")
    assert read == [str(shared_dir / "mybot.py")] and listed == [str(shared_dir)]
    assert home == str(shared_dir)
    assert main(["match", "--p1", "mybot:Hunter", "--p2", "idle", "--rounds", "1",
                 "--startup-s", "60", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["bots"] == ["mybot:Hunter", "idle"] and result["faults"][0]["total"] == 0
    assert result["forfeits"] == [False, False]
    seat = open_seat("mybot:Hunter", 0, ROOMY)
    try:
        assert isinstance(seat, ProcessSeat) and seat.wait_ready() is None
    finally:
        seat.close()


@on_linux
def test_a_module_found_on_sys_path_loads_from_that_directory(shared_dir, monkeypatch):
    """Found through this process's sys.path (as PYTHONPATH would put it there), which the
    bot's clean environment lacks: its process imports it from the directory found."""
    bots = shared_dir / "bots"
    bots.mkdir()
    bots.chmod(0o755)
    write_bot(bots, HUNTER, "farbot.py")
    elsewhere = shared_dir / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    monkeypatch.syspath_prepend(str(bots))
    assert locate("farbot:Hunter")[2] == str(bots)
    result, _, _ = play_match("farbot:Hunter", "idle", seed=0, rounds=1, rules=SHORT,
                              limits=ROOMY)
    assert result["faults"][0]["total"] == 0 and result["forfeits"] == [False, False]


@on_linux
def test_a_local_module_named_like_a_loaded_one_gets_a_clear_message(shared_dir, monkeypatch):
    write_bot(shared_dir, HUNTER, "random.py")
    write_bot(shared_dir, HUNTER, "numpy.py")
    monkeypatch.chdir(shared_dir)
    with pytest.raises(BotLoadError, match="'random' in the current directory has the name of "
                                           "a standard-library module"):
        locate("random:Hunter")
    assert make_bot("random") is not None  # the built-in name still means the built-in bot
    result, _, _ = play_match("numpy:Hunter", "idle", seed=0, rounds=1, rules=SHORT,
                              limits=ROOMY)
    (fault,) = result["faults"][0]["examples"]
    assert fault["kind"] == "startup" and "module 'numpy' for bot 'numpy:Hunter' is already " \
                                          "loaded from" in fault["message"]
    assert result["forfeits"] == [True, False]


def test_lookup_order_built_in_names_then_files_then_modules(shared_dir, monkeypatch):
    write_bot(shared_dir, HUNTER, "idle.py")
    monkeypatch.chdir(shared_dir)
    assert locate("idle") == ([], [], None)  # the built-in bot, whatever the directory holds
    assert locate("idle.py:Hunter") == ([str(shared_dir / "idle.py")], [], None)  # the file
    assert locate("idle:Hunter")[2] == str(shared_dir)  # the module in this directory
    with pytest.raises(BotLoadError, match="no module named 'nothere' in the current "
                                           "directory or on sys.path"):
        locate("nothere:Hunter")


# -- play_match from Python -------------------------------------------------------------------
class Spinner:
    def act(self, obs):
        return Action(turn=1, fire=obs.me.reload == 0)


def test_play_match_with_bot_objects_returns_what_it_documents():
    from spacewar import replay as replay_io

    assert spacewar.play_match is play_match and spacewar.check_bot is check_bot
    result, replay, timing = play_match(Spinner(), "chaser", seed=7, rounds=2, rules=SHORT,
                                        record=True, act_seconds=True)
    assert set(result) == {"bots", "winner", "winner_seat", "score", "rounds", "steps",
                           "forfeit", "forfeits", "error", "faults", "seed", "rounds_asked",
                           "rules", "output"}
    assert result["bots"] == [f"{__name__}.Spinner", "chaser"]
    assert result["seed"] == 7 and result["rounds_asked"] == 2 and result["rules"] == \
        SHORT.to_dict()
    assert replay["result"] == result and replay_io.check(replay)[0]
    assert set(timing) == {"wall_seconds", "frames_per_second", "startup_seconds",
                           "play_seconds", "play_frames_per_second", "act", "act_seconds"}
    assert 0 <= timing["startup_seconds"] <= timing["wall_seconds"]
    assert timing["play_seconds"] <= timing["wall_seconds"] - timing["startup_seconds"] + 1e-9
    assert timing["play_frames_per_second"] == result["steps"] / timing["play_seconds"]
    for seat in (0, 1):  # every frame asked both seats once
        assert timing["act"][seat]["count"] == result["steps"] == len(timing["act_seconds"][seat])
        assert timing["act"][seat]["max"] == timing["act_seconds"][seat].max()
    again, none, timing_again = play_match(Spinner(), "chaser", seed=7, rounds=2, rules=SHORT)
    assert none is None and "act_seconds" not in timing_again
    assert json.dumps(again, sort_keys=True) == json.dumps(result, sort_keys=True)


def test_play_match_refuses_what_cannot_be_a_bot():
    with pytest.raises(TypeError, match=r"p1 must .* got the class Spinner: pass an instance, "
                                        r"Spinner\(\)"):
        play_match(Spinner, "idle")
    with pytest.raises(TypeError, match="p2 must be a bot specification .* got int 42"):
        play_match("idle", 42)
