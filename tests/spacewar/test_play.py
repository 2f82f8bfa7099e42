"""Tests for spacewar.view.live: people and bots in the window, run headless with scripted keys.

No test here reads the wall clock: the window's pace is driven by a fake clock that moves
only when a picture is drawn (``FakeWallClock``), so how many window ticks (and so game frames)
each pass of the loop plays, when ``max_seconds`` ends a session and what ``wall_seconds``
says are exact, whatever the machine's load. Scripts give keys per window tick.
"""
import contextlib
import os
import types

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ["SDL_AUDIODRIVER"] = "dummy"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import pytest  # noqa: E402

from engine.clock import FixedStepClock  # noqa: E402
from spacewar.view import keys as K  # noqa: E402
from spacewar.view import live as play_module  # noqa: E402
from spacewar import replay as replay_io  # noqa: E402
from spacewar.view import window as viewer  # noqa: E402
from spacewar.arena.match import play_match  # noqa: E402
from spacewar.view.live import (format_summary, held_keys_code, play, play_script_source, watch)  # noqa: E402
from spacewar.protocol import Action  # noqa: E402
from spacewar.rules import Rules  # noqa: E402
from spacewar.sandbox.limits import Limits  # noqa: E402

# A confined bot's budget here: an action of a test bot in its own process took 0.13-0.19 ms
# at the median and 3.8-5.3 ms at the 99th percentile (measured on this 2-core machine while
# it ran other test suites: play_match(..., act_seconds=True), 1119-1197 actions each), so
# 0.6 s is over 100x the p99 and a loaded machine cannot turn an answer into a timeout (and
# so change the match that ``watch`` is compared with).
CONFINED = Limits(budget=0.6)


class FakeWallClock:
    """Wall time that moves only when the window shows a picture: each picture takes exactly
    ``1 / draw_rate`` s (``now = draws / draw_rate``, one correctly rounded division, so
    ``FixedStepClock``'s tolerance makes every tick count exact)."""

    def __init__(self, draw_rate):
        self.draw_rate = draw_rate
        self.draws = 0

    def __call__(self):
        return self.draws / self.draw_rate


@contextlib.contextmanager
def fake_window_clock(draw_rate=30):
    """Drive ``spacewar.view.live``'s window with a ``FakeWallClock``: its pace (``viewer.Pace``'s
    wall clock, an ``engine.clock.FixedStepClock`` given the fake clock) and ``run_window``'s
    ``max_seconds`` and ``wall_seconds`` read it, and every ``Window.show`` advances it."""
    clock = FakeWallClock(draw_rate)
    real_show = viewer.Window.show

    class FakePace(viewer.Pace):
        def __init__(self, fps, speed=1.0):
            super().__init__(fps, speed)
            real = self.wall  # the same step and cap, on the fake clock
            self.wall = FixedStepClock(dt=real.dt, max_steps_per_frame=real.max_steps_per_frame,
                                       clock=clock)
            self.wall.tick()  # starts the measurement, as Pace does

    def show(self, prims):
        real_show(self, prims)
        clock.draws += 1

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(play_module, "Pace", FakePace)
        mp.setattr(viewer, "time", types.SimpleNamespace(perf_counter=clock))
        mp.setattr(viewer.Window, "show", show)
        yield clock


@pytest.fixture(autouse=True)
def window_clock():
    with fake_window_clock() as clock:
        yield clock


@pytest.fixture(scope="module")
def pygame():
    """pygame (the optional [viz] extra), for the tests that open a window."""
    return pytest.importorskip("pygame")


@pytest.fixture(scope="module", autouse=True)
def compiled_frames():
    """The compiled frame is compiled (or loaded from the cache) once, before the tests."""
    play_match("chaser", "sniper", rounds=1, rules=Rules(max_round_frames=20, post_round_delay=2))


def test_keys_to_actions():
    assert held_keys_code(frozenset()) == Action().code()
    assert held_keys_code(frozenset({"a"})) == Action(turn=1).code()
    assert held_keys_code(frozenset({"right"})) == Action(turn=-1).code()
    assert held_keys_code(frozenset({"up", "space"})) == Action(thrust=True, fire=True).code()
    assert held_keys_code(frozenset({"w", "s", "f"})) == Action(thrust=True, fire=True, flip=True).code()
    # both turn keys at once is hyperspace, as on the 1962 control boxes
    assert held_keys_code(frozenset({"a", "d"})) == Action(hyperspace=True).code()
    assert held_keys_code(frozenset({"h"})) == Action(hyperspace=True).code()


def test_scripts():
    held = play_script_source([(10, {"W"}), (0, set()), (20, ["space", "a"])])
    assert held(0) == frozenset() and held(9) == frozenset()
    assert held(10) == {"w"} and held(19) == {"w"}
    assert held(500) == {"space", "a"}
    assert play_script_source(lambda f: "escape")(3) == {"escape"}
    with pytest.raises(ValueError, match="unknown key"):
        play_script_source([(0, {"x"})])
    with pytest.raises(ValueError):
        play_script_source(42)


THRUST_AND_FIRE = [(0, {"w"}), (20, {"w", "space"}), (70, {"a"}), (80, set())]


def thrust_and_fire(clock, draw_rate):
    """Three seconds of the fake clock at 60 window ticks a second, drawn ``draw_rate`` times a
    second: the summary and the number of pictures drawn."""
    clock.draw_rate = draw_rate
    result = play(p2="idle", script=THRUST_AND_FIRE, max_seconds=3, scale=360)
    return result, clock.draws


def check_thrust_and_fire(result, draws, draw_rate):
    """What the session must have done, exactly: the first pass draws before any time has gone
    by; each later one is ``60 / draw_rate`` ticks late, of which the clock plays at most 6
    (``Pace``: a tenth of a second at 60 fps) and drops the rest; the pass at 3 s is the last,
    and the session's time is read after its picture."""
    passes = 3 * draw_rate  # passes 1 .. 3 * draw_rate each play their ticks
    due = 60 // draw_rate
    assert result["reason"] == "time", result["reason"]
    assert draws == passes + 1, (draws, passes + 1)
    assert result["wall_seconds"] == draws / draw_rate
    assert result["frames"] == passes * min(due, 6), result["frames"]
    assert result["dropped_steps"] == passes * max(due - 6, 0), result["dropped_steps"]
    assert result["paused_frames"] == 0
    # fire held from tick 20 to 69 with a reload of 16 frames: shots at 20, 36, 52 and 68
    assert result["torpedoes_fired"] == [4, 0]
    assert result["distance"][0] > 0.05 > result["distance"][1]  # thrust vs the star's pull
    assert result["scores"] == [0, 0] and not result["over"] and result["winner"] is None
    assert result["bot_faults"] == 0


@pytest.mark.parametrize("draw_rate", [30, 5])
def test_scripted_thrust_and_fire_against_idle(pygame, window_clock, draw_rate):
    """At 30 pictures a second every tick is played (180 frames in 3 s); at 5 a second the
    drawing falls behind and the clock drops half of every pass's 12 ticks (90 played, 90
    dropped)."""
    result, draws = thrust_and_fire(window_clock, draw_rate)
    check_thrust_and_fire(result, draws, draw_rate)


def test_the_thrust_and_fire_check_fails_on_a_pace_that_drops_no_ticks(pygame, window_clock,
                                                                      monkeypatch):
    """Positive control: with the cap on ticks per pass lifted (a planted bug in the pace),
    the slow drawing plays every tick and the exact counts above catch it."""
    real = play_module.Pace

    class Uncapped(real):
        def __init__(self, fps, speed=1.0):
            super().__init__(fps, speed)
            self.wall = FixedStepClock(dt=self.wall.dt, max_steps_per_frame=1000,
                                       clock=window_clock)
            self.wall.tick()

    monkeypatch.setattr(play_module, "Pace", Uncapped)
    result, draws = thrust_and_fire(window_clock, 5)
    assert (result["frames"], result["dropped_steps"]) == (180, 0)  # not (90, 90)
    with pytest.raises(AssertionError):
        check_thrust_and_fire(result, draws, 5)


def test_escape_quits_early(pygame, window_clock):
    result = play(p2="idle", script=[(0, {"space"}), (20, {"escape"})], max_seconds=10, scale=256)
    assert result["reason"] == "quit"
    assert result["frames"] == 20
    # 2 ticks a picture at 30 pictures a second: tick 20 (the escape) is the first of the pass
    # after the 11th picture; that pass draws the 12th, so 0.4 s went by (of the 10 allowed)
    assert window_clock.draws == 12 and result["wall_seconds"] == 12 / 30
    # the same with a callable script
    result = play(p2="idle", script=lambda f: {"escape"} if f >= 5 else set(), max_seconds=10,
                  scale=256)
    assert result["reason"] == "quit" and result["frames"] == 5


def test_pause_and_resume_by_script(pygame):
    script = [(10, {"p"}), (11, set()), (40, {"p"}), (41, set()), (60, {"escape"})]
    result = play(p2="chaser", script=script, max_seconds=10, scale=256)
    assert result["reason"] == "quit"
    assert result["paused_frames"] == 30  # frames 10 to 39 of the script's time line
    assert result["frames"] == 30


def test_the_real_keyboard_path(pygame, monkeypatch):
    """No script: keys come from pygame's key state and events (faked here, headless)."""
    thrust = pygame.K_w

    class Pressed:
        def __getitem__(self, code):
            return code == thrust

    monkeypatch.setattr(pygame.key, "get_pressed", lambda: Pressed())
    draws = {"n": 0}
    real_draw = play_module._draw

    def draw(*args, **kwargs):
        real_draw(*args, **kwargs)
        draws["n"] += 1
        if draws["n"] == 60:
            pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_ESCAPE))

    monkeypatch.setattr(play_module, "_draw", draw)
    result = play(p2="idle", max_seconds=10, scale=256)
    assert result["reason"] == "quit"
    assert result["frames"] > 10
    assert result["distance"][0] > result["distance"][1]
    assert result["torpedoes_fired"] == [0, 0]


def test_a_game_played_to_the_end_returns_the_result(pygame):
    # short rounds that time out: the match ends on its own and play returns
    from spacewar.rules import Rules

    rules = Rules(torpedoes=2, post_round_delay=8, max_round_frames=60)
    result = play(p2="idle", rules=rules, rounds=1, fps=500, script=[(0, {"space"})],
                  max_seconds=10, scale=256)
    assert result["reason"] == "over" and result["over"]
    assert result["rounds"] >= 1
    assert result["winner"] in ("human", "bot", None)


def test_bad_arguments():
    with pytest.raises(ValueError):
        play(fps=0)
    with pytest.raises(ValueError):
        play(scale=10)
    with pytest.raises(ValueError):
        play(max_seconds=-1)
    with pytest.raises(ValueError):
        play(script=[(0, {"nope"})])


def test_missing_pygame_says_how_to_install(monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "pygame", None)
    with pytest.raises(ImportError, match=r"\.\[viz\]"):
        play_module.require_pygame()


# -- two people, one person in either seat ----------------------------------------------------
def recorded_codes(path):
    """The (frames, 2) action codes of a replay file the window recorded."""
    return replay_io.actions(replay_io.load(path))


def test_two_people_at_one_keyboard_each_fly_their_own_ship(pygame, tmp_path):
    path = tmp_path / "two.json"
    script = [(0, {"w", "left", "down"}),  # player 1 thrusts; player 2 turns left and fires
              (30, {"a", "kp8", "rctrl"}),  # player 1 turns; player 2 on the keypad and RCtrl
              (60, {"e", "rshift"}),  # both jump to hyperspace
              (61, set())]
    # short rounds, so that the match ends by itself at 2 x 100 frames and is recorded
    rules = Rules(max_round_frames=100, post_round_delay=0)
    result = play(p1="human", p2="human", rules=rules, rounds=2, script=script, max_seconds=60,
                  scale=256, record_to=path)
    assert result["reason"] == "over" and result["replay_path"] == str(path)
    assert result["players"] == ["human 1", "human 2"] and result["bot"] is None
    codes = recorded_codes(path)
    assert codes.shape == (result["frames"], 2) and result["frames"] >= 70
    assert set(codes[:30, 0]) == {Action(thrust=True).code()}
    assert set(codes[:30, 1]) == {Action(turn=1, fire=True).code()}  # arrows are player 2's
    assert set(codes[30:60, 0]) == {Action(turn=1).code()}
    assert set(codes[30:60, 1]) == {Action(thrust=True, fire=True).code()}
    assert list(codes[60]) == [Action(hyperspace=True).code()] * 2
    assert result["hyperspace_jumps"] == [1, 1]
    assert result["torpedoes_fired"][1] >= 2 and result["torpedoes_fired"][0] == 0


def test_one_person_in_seat_2_gets_both_hands_keys(pygame, tmp_path):
    path = tmp_path / "seat2.json"
    rules = Rules(max_round_frames=40, post_round_delay=0)
    result = play(p1="idle", p2="human", rules=rules, rounds=1, script=[(0, {"left", "w"})],
                  max_seconds=60, scale=256, record_to=path)
    assert result["players"] == ["idle", "human"] and result["bot"] == "idle"
    codes = recorded_codes(path)
    assert set(codes[:, 1]) == {Action(turn=1, thrust=True).code()}
    assert set(codes[:, 0]) == {Action().code()}
    assert replay_io.check(replay_io.load(path))[0]


def test_a_match_left_before_its_end_writes_no_replay(pygame, tmp_path):
    path = tmp_path / "left.json"
    result = play(p2="idle", script=[(0, {"w"}), (30, {"escape"})], max_seconds=20, scale=256,
                  record_to=path)
    assert result["reason"] == "quit" and result["replay_path"] is None
    assert result["replay_skipped"] and not path.exists()
    assert "no replay written: the match was left before its end" in format_summary(result)


@pytest.mark.parametrize("keyset, key, action", [
    (K.PLAYER_1, "a", Action(turn=1)), (K.PLAYER_1, "d", Action(turn=-1)),
    (K.PLAYER_1, "w", Action(thrust=True)), (K.PLAYER_1, "space", Action(fire=True)),
    (K.PLAYER_1, "s", Action(fire=True)), (K.PLAYER_1, "e", Action(hyperspace=True)),
    (K.PLAYER_1, "f", Action(flip=True)), (K.PLAYER_1, "left", Action()),
    (K.PLAYER_2, "left", Action(turn=1)), (K.PLAYER_2, "kp6", Action(turn=-1)),
    (K.PLAYER_2, "up", Action(thrust=True)), (K.PLAYER_2, "kp5", Action(fire=True)),
    (K.PLAYER_2, "down", Action(fire=True)), (K.PLAYER_2, "kp0", Action(hyperspace=True)),
    (K.PLAYER_2, "return", Action(flip=True)), (K.PLAYER_2, "kp_enter", Action(flip=True)),
    (K.PLAYER_2, "w", Action()), (K.SOLO, "h", Action(hyperspace=True)),
])
def test_each_key_set(keyset, key, action):
    assert held_keys_code(frozenset({key}), keyset) == action.code()
    both_turns = keyset.left | keyset.right
    assert held_keys_code(frozenset(both_turns), keyset) == Action(hyperspace=True).code()


def test_the_key_sets_do_not_share_a_key():
    assert not K.PLAYER_1.names & K.PLAYER_2.names
    assert not (K.PLAYER_1.names | K.PLAYER_2.names) & (K.PLAY_PAUSE | K.PLAY_QUIT)


# -- watching two bots --------------------------------------------------------------------------
@pytest.fixture(scope="module")
def watched(pygame, tmp_path_factory):
    path = tmp_path_factory.mktemp("watch") / "watched.json"
    with fake_window_clock():  # module-scoped: the function-scoped clock is not yet in place
        summary = watch("chaser", "sniper", seed=7, rounds=1, fps=240, speed=8.0, scale=256,
                        script=[], max_seconds=120, record_to=path)
    return summary, path


def test_watch_plays_the_match_spacewar_match_plays(watched):
    summary, path = watched
    assert summary["reason"] == "over" and summary["over"]
    result, rep, _ = play_match("chaser", "sniper", seed=7, rounds=1, record=True)
    assert summary["result"] == result
    assert summary["scores"] == result["score"] and summary["frames"] == result["steps"]
    saved = replay_io.load(path)
    assert saved["actions"] == rep["actions"]
    assert saved["final_state_sha256"] == rep["final_state_sha256"]
    ok, details = replay_io.check(saved)
    assert ok, details


def test_the_summary_is_a_table(watched):
    summary, path = watched
    text = format_summary(summary)
    lines = text.splitlines()
    assert lines[0].split() == ["seat", "1", "(needle)", "seat", "2", "(wedge)"]
    assert lines[1].split() == ["player", "chaser", "sniper"]
    assert lines[2].split() == ["score", *map(str, summary["scores"])]
    assert lines[3].split() == ["faults", "0", "0"]
    winner = summary["winner_seat"]
    expected = ("none (a draw)" if winner is None else
                f"{summary['players'][winner]} (seat {winner + 1})")
    assert f"winner: {expected}" in text
    assert f"rounds: {summary['rounds']} of 1" in text and f"frames: {summary['frames']}" in text
    assert "ended: the match is over" in text and f"replay written to {path}" in text
    assert "{" not in text


def test_a_bot_from_elsewhere_plays_confined_exactly_as_in_a_match(pygame, monkeypatch):
    from spacewar.arena.seats import InlineSeat
    from spacewar.sandbox.process import ProcessSeat

    opened = []
    real_open = play_module.open_seat

    def spy(*args, **kwargs):
        opened.append(real_open(*args, **kwargs))
        return opened[-1]

    monkeypatch.setattr(play_module, "open_seat", spy)
    spec = "tests.spacewar.bots_for_tests:SometimesRaising"  # faults on frames 5, 6 and 7
    summary = watch(spec, "idle", seed=3, rounds=1, fps=240, speed=8.0, scale=256, script=[],
                    max_seconds=120, limits=CONFINED)
    assert isinstance(opened[0], ProcessSeat) and isinstance(opened[1], InlineSeat)
    result, _, _ = play_match(spec, "idle", seed=3, rounds=1, limits=CONFINED)
    assert summary["result"] == result
    assert summary["faults"] == [3, 0] and summary["bot_faults"] == 3
    assert [ex["frame"] for ex in result["faults"][0]["examples"]] == [5, 6, 7]


def test_a_bot_that_faults_too_often_forfeits_the_watched_match(pygame):
    spec = "tests.spacewar.bots_for_tests:Raising"
    summary = watch(spec, "chaser", seed=1, rounds=1, max_faults=3, fps=240, scale=256,
                    script=[], max_seconds=120, limits=CONFINED)
    assert summary["reason"] == "over" and summary["forfeits"] == [True, False]
    assert summary["winner_seat"] == 1 and summary["frames"] == 2
    assert summary["result"]["faults"][0]["raised"] == 3  # every fault of its kind
    result, _, _ = play_match(spec, "chaser", seed=1, rounds=1, max_faults=3, limits=CONFINED)
    assert summary["result"] == result
    assert "yes" in format_summary(summary).splitlines()[4]  # the forfeited row


def test_watch_pauses_steps_and_changes_speed(pygame):
    script = [(10, {"space"}), (11, set()), (12, {"."}), (13, set()), (14, {"."}),
              (15, set()), (20, {"p"}), (21, set()), (30, {"]"}), (31, set()),
              (40, {"["}), (41, set()), (42, {"["}), (43, set()), (44, {"1"}), (45, set()),
              (50, {"q"})]
    result = watch("chaser", "idle", script=script, fps=240, max_seconds=30, scale=256)
    assert result["reason"] == "quit"
    # ticks 0..9: 10 frames; paused for ticks 10..19 with 2 single steps; ticks 20..29: 10
    # frames; 30..39 at 2x: 20; 40..41 at 1x: 2; 42..43 at 1/2x: 1; 44..49 at 1x: 6
    assert result["paused_frames"] == 10
    assert result["frames"] == 10 + 2 + 10 + 20 + 2 + 1 + 6
    assert result["speed"] == 1.0


def test_watch_is_for_bots_and_checks_its_speed():
    with pytest.raises(ValueError, match="watch is for two bots"):
        watch("human", "chaser")
    with pytest.raises(ValueError, match="speed must be one of"):
        watch("chaser", "idle", speed=3)
    with pytest.raises(ValueError, match="unknown key"):
        watch("chaser", "idle", script=[(0, {"w"})])  # a flying key means nothing here


# -- no display, the command line -----------------------------------------------------------------
@pytest.mark.parametrize("argv", [["play"], ["play", "--p1", "human", "--p2", "human"],
                                  ["watch", "--p1", "chaser", "--p2", "sniper"]])
def test_no_display_is_one_line_and_exit_status_2(argv, monkeypatch, capsys):
    from spacewar.cli import main

    for name in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER"):
        monkeypatch.delenv(name, raising=False)
    opened = []
    monkeypatch.setattr(play_module, "open_seat", lambda *a, **k: opened.append(a))
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith(f"spacewar {argv[0]}: no display: DISPLAY and WAYLAND_DISPLAY")
    assert opened == []  # found out before any bot started


def test_a_video_driver_that_fails_is_the_same_clear_error(pygame, monkeypatch, capsys):
    from spacewar.cli import main

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setenv("SDL_VIDEODRIVER", "x11")
    assert main(["watch", "--p1", "idle", "--p2", "idle"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("spacewar watch: cannot open a window:") and err.count("\n") == 1


def test_a_display_that_is_not_there_is_not_drawn_to_invisibly(pygame, monkeypatch, capfd):
    from spacewar.cli import main

    monkeypatch.delenv("SDL_VIDEODRIVER", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setenv("DISPLAY", ":987")  # no X server there: SDL would fall back silently
    assert main(["watch", "--p1", "idle", "--p2", "idle"]) == 2
    ours = [line for line in capfd.readouterr().err.splitlines() if line.startswith("spacewar")]
    assert len(ours) == 1
    assert ours[0].startswith(("spacewar watch: no display: SDL found none it can use",
                               "spacewar watch: cannot open a window:"))


def test_help_lists_the_keys_and_the_defaults(capsys):
    from spacewar.cli import main

    for command, expected in (
            ("play", ["Keys, one person", "A/D or Left/Right", "Kp8", "RShift", "(default: human)",
                      "(default: chaser)", "(default: 720)", "(default: 50.0)"]),
            ("watch", ["Keys while watching", "(default: sniper)", "(default: 1.0)", "1/8x to 8x"]),
            ("replay", ["Keys of the replay window", "hold R or Backspace", "(default: 480)"])):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        out = capsys.readouterr().out
        for text in expected:
            assert text in out, (command, text)


def test_watch_from_the_command_line_to_the_end(pygame, tmp_path, monkeypatch, capsys):
    from spacewar.view import window as viewer
    from spacewar.cli import main

    real_poll = viewer.Window.poll

    def poll(self):  # a key is pressed all the time: at the end it closes the window
        pressed, clicks, closed = real_poll(self)
        return pressed | {"other"}, clicks, closed

    monkeypatch.setattr(viewer.Window, "poll", poll)
    path = tmp_path / "cli.json"
    assert main(["watch", "--p1", "chaser", "--p2", "idle", "--rounds", "1", "--speed", "8",
                 "--fps", "500", "--window-size", "200", "--replay", str(path)]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[1].split() == ["player", "chaser", "idle"]
    assert "ended: the match is over" in out
    assert replay_io.check(replay_io.load(path))[0]


def test_a_bad_replay_path_is_refused_before_anything_starts(tmp_path, monkeypatch, capsys):
    from spacewar.cli import main

    opened = []
    monkeypatch.setattr(play_module, "open_seat", lambda *a, **k: opened.append(a))
    (tmp_path / "keep.gif").write_bytes(b"GIF89a" + bytes(20))
    assert main(["watch", "--replay", str(tmp_path / "keep.gif")]) == 2
    assert "gif" in capsys.readouterr().err.lower() and opened == []
    assert (tmp_path / "keep.gif").read_bytes().startswith(b"GIF89a")


def test_a_match_left_before_its_end_names_no_winner(pygame):
    # chaser scores twice against an idle person in the first 1200 frames; quitting there
    # leaves the match unfinished, and the score so far is no win
    summary = play(p2="chaser", fps=600, script=[(1200, {"escape"})], max_seconds=60,
                   scale=256)
    assert summary["reason"] == "quit" and not summary["over"] and summary["frames"] == 1200
    assert summary["scores"][1] > summary["scores"][0]
    assert summary["winner"] is None and summary["winner_seat"] is None
    assert "winner: none (left before the end)" in format_summary(summary)


def test_a_bot_s_start_up_message_is_shown_escaped(tmp_path):
    path = tmp_path / "loud.py"
    path.write_text("raise ImportError('\\x1b[31mred\\x1b[0m')\n")
    with pytest.raises(ValueError, match="could not start") as failed:
        watch(f"{path}:Bot", "idle", seed=1, rounds=1, fps=240, scale=256, script=[],
              max_seconds=30)
    assert "\x1b" not in str(failed.value) and "\\x1b[31mred" in str(failed.value)
