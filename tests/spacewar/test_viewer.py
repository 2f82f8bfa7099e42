"""Scrubbing replays: checkpoints, the timeline (headless), the pacing, the replay window.

The window runs under SDL's dummy video driver with scripted keys; everything it shows is
checked against a straight re-simulation of the replay, bit for bit (``state_hash``).
"""
import os

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ["SDL_AUDIODRIVER"] = "dummy"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import random  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from spacewar.view import keys as K  # noqa: E402
from spacewar import replay as replay_io  # noqa: E402
from spacewar.game.game import Checkpoint, Game  # noqa: E402
from spacewar.arena.match import play_match  # noqa: E402
from spacewar.rules import Rules  # noqa: E402
from spacewar.replay.timeline import ReplayTimeline  # noqa: E402
from spacewar.view.replay_view import ReplayView  # noqa: E402
from spacewar.view.window import NoDisplayError, Pace, check_display, check_speed  # noqa: E402


def straight_hashes(rep):
    """The state hash after every frame of a plain re-simulation: frame f at index f."""
    hashes = []
    replay_io.simulate(rep, lambda game: hashes.append(game.state_hash(0)))
    return hashes


@pytest.fixture(scope="module")
def classic():
    _, rep, _ = play_match("chaser", "random", seed=9, rounds=1, record=True)
    return rep, straight_hashes(rep)


@pytest.fixture(scope="module")
def electric():
    _, rep, _ = play_match("chaser", "sniper", seed=2, rounds=1, rules=Rules(mode="electric"),
                           record=True)
    return rep, straight_hashes(rep)


@pytest.fixture(scope="module")
def newtonian():
    _, rep, _ = play_match("sniper", "dodger", seed=4, rounds=1, rules=Rules(mode="newtonian"),
                           record=True)
    return rep, straight_hashes(rep)


# -- Game.checkpoint / Game.restore -----------------------------------------------------------
@pytest.mark.parametrize("mode", ["classic", "newtonian", "electric"])
def test_restoring_a_checkpoint_then_stepping_is_bit_identical(mode):
    rules = Rules(mode=mode)
    codes = np.random.default_rng(5).integers(0, 48 if mode == "electric" else 24,
                                              size=(400, 2, 2))
    game = Game(rules, seeds=[11, 12], rounds=2)
    saved, straight = {}, []
    for i, row in enumerate(codes):
        if i % 100 == 0:
            saved[i] = game.checkpoint(1)
        game.step(row)
        straight.append(game.state_hash(1))
    # into match 0 of another game of the same rules (another seed: the stream is restored too)
    other = Game(rules, seeds=[99], rounds=2)
    other.restore(saved[200], 0)
    assert other.checkpoint(0).frame == saved[200].frame == 200
    for i in range(200, 400):
        other.step(codes[i][1:2])
        assert other.state_hash(0) == straight[i]
    # and back into the same game, whose match 0 is left alone
    untouched = game.state_hash(0)
    game.restore(saved[100], 1)
    for i in range(100, 150):
        game.step(codes[i])
        assert game.state_hash(1) == straight[i]
    assert game.state_hash(0) != untouched  # match 0 kept playing its own codes


def test_a_checkpoint_is_read_only_and_small():
    game = Game(Rules(), seeds=[1])
    saved = game.checkpoint()
    assert isinstance(saved, Checkpoint) and saved.frame == 0
    assert all(not a.flags.writeable for a in saved.arrays)
    with pytest.raises(ValueError):
        saved.arrays[0][0, 0, 0] = 1.0
    assert 3000 < saved.nbytes < 8000  # about 5 KB under the 1962 rules


def test_restore_checks_everything_before_changing_anything():
    game = Game(Rules(), seeds=[1], rounds=3)
    for _ in range(30):
        game.step(np.full((1, 2), 4))
    before = game.state_hash()
    for other in (Game(Rules(mode="electric"), seeds=[1], rounds=3),
                  Game(Rules(), seeds=[1], rounds=5),
                  Game(Rules(torpedoes=8), seeds=[1], rounds=3)):
        with pytest.raises(ValueError, match="other rules, rounds or force layout"):
            game.restore(other.checkpoint(), 0)
        assert game.state_hash() == before
    with pytest.raises(TypeError, match="Checkpoint"):
        game.restore({"frame": 0}, 0)
    for m in (1, -1, True, 0.0):
        with pytest.raises(ValueError, match=rf"m must be a match index in \[0, 1\), got {m!r}"):
            game.restore(game.checkpoint(), m)
    assert game.state_hash() == before


# -- the timeline, headless -------------------------------------------------------------------
@pytest.mark.parametrize("which", ["classic", "newtonian", "electric"])
def test_seeking_in_any_order_gives_the_straight_run(which, request):
    rep, hashes = request.getfixturevalue(which)
    timeline = ReplayTimeline(rep, checkpoint_every=32)
    total = timeline.total
    assert total == rep["frames"] == len(hashes) - 1
    order = list(range(0, total + 1, 7)) + list(range(total, -1, -5))
    order += random.Random(3).sample(range(total + 1), 60)
    for frame in order:
        assert timeline.seek(frame) == frame == timeline.frame
        assert timeline.game.state_hash(0) == hashes[frame], frame
    timeline.seek(total)
    assert timeline.game.state_hash(0) == rep["final_state_sha256"]
    assert timeline.at_recorded_end() is True
    timeline.seek(total - 1)
    assert timeline.at_recorded_end() is None


def test_stepping_back_frame_by_frame_is_restored_not_re_simulated(classic, monkeypatch):
    rep, hashes = classic
    timeline = ReplayTimeline(rep, checkpoint_every=64, segment_limit=100)
    timeline.seek(300)
    steps = []
    real_step = timeline.game.step
    monkeypatch.setattr(timeline.game, "step", lambda codes: (steps.append(1), real_step(codes)))
    timeline.step(-1)  # from the checkpoint at 256 up to 299
    assert len(steps) == 299 - 256 and timeline.game.state_hash(0) == hashes[299]
    steps.clear()
    for frame in range(298, 256, -1):  # the frames kept on the way: no step at all
        assert timeline.step(-1) == -1
        assert timeline.game.state_hash(0) == hashes[frame]
    assert steps == []
    timeline.step(-1)  # 256 is the checkpoint itself
    assert steps == [] and timeline.game.state_hash(0) == hashes[256]
    timeline.step(-1)  # a new stretch: from 192
    assert len(steps) == 255 - 192 and timeline.game.state_hash(0) == hashes[255]


def test_checkpoint_memory_is_bounded(classic):
    rep, hashes = classic
    timeline = ReplayTimeline(rep, checkpoint_every=4, max_checkpoints=5, segment_limit=6)
    one = timeline.game.checkpoint(0).nbytes
    rng = random.Random(8)
    for frame in [timeline.total] + [rng.randrange(timeline.total + 1) for _ in range(80)]:
        timeline.seek(frame)
        assert timeline.game.state_hash(0) == hashes[frame]
        assert len(timeline.checkpoints) <= 5 and len(timeline.segment) <= 6
        assert timeline.stored_bytes <= (5 + 6) * one
    # the spacing doubled until five checkpoints cover the whole match
    assert timeline.interval >= timeline.total / 5
    assert all(f % timeline.interval == 0 for f in timeline.checkpoint_frames)
    assert timeline.checkpoint_frames[0] == 0


@pytest.mark.parametrize("bad", [-1, 10 ** 9, 2.0, "5", None, True])
def test_bad_seek_targets_raise_naming_the_value(classic, bad):
    rep, hashes = classic
    timeline = ReplayTimeline(rep)
    timeline.seek(40)
    with pytest.raises(ValueError, match="frame must be") as error:
        timeline.seek(bad)
    assert repr(bad) in str(error.value) or str(bad) in str(error.value)
    assert timeline.frame == 40 and timeline.game.state_hash(0) == hashes[40]


def test_step_stops_at_the_ends_and_checks_its_argument(classic):
    rep, hashes = classic
    timeline = ReplayTimeline(rep)
    assert timeline.step(-5) == 0 and timeline.frame == 0
    assert timeline.step(timeline.total + 50) == timeline.total
    assert timeline.game.state_hash(0) == hashes[-1]
    with pytest.raises(ValueError, match="n must be an int"):
        timeline.step(1.5)


@pytest.mark.parametrize("option, value", [("checkpoint_every", 0), ("max_checkpoints", 1),
                                           ("segment_limit", -1), ("checkpoint_every", 2.5)])
def test_bad_timeline_options(classic, option, value):
    with pytest.raises(ValueError, match=rf"{option} must be an int >= \d+, got {value!r}"):
        ReplayTimeline(classic[0], **{option: value})


def test_actions_past_the_end_are_a_replay_error_when_reached(classic):
    rep = dict(classic[0])
    codes = replay_io.actions(rep)
    extra = np.concatenate([codes, codes[-1:]]).astype(np.uint8)
    import base64

    rep["actions"] = base64.b64encode(extra.tobytes()).decode("ascii")
    rep["faults"] = base64.b64encode(base64.b64decode(rep["faults"]) + bytes(2)).decode("ascii")
    rep["frames"] += 1
    timeline = ReplayTimeline(rep)
    timeline.seek(rep["frames"] - 1)  # the last recorded frame of the match is fine
    with pytest.raises(replay_io.ReplayError, match="past the end of the match"):
        timeline.seek(rep["frames"])


def test_a_saved_replay_file_is_loaded_and_checked(classic, tmp_path):
    path = tmp_path / "game.json"
    replay_io.save(path, classic[0])
    assert ReplayTimeline(str(path)).total == classic[0]["frames"]
    path.write_text(path.read_text().replace('"seed":9', '"seed":10'))
    with pytest.raises(replay_io.ReplayError, match="content does not match"):
        ReplayTimeline(path)


# -- pacing -------------------------------------------------------------------------------------
def test_pace_turns_ticks_into_frames_at_each_speed():
    pace = Pace(60)
    assert [pace.frames() for _ in range(3)] == [1, 1, 1]
    pace.slower(), pace.slower(), pace.slower()
    assert pace.speed == 0.125
    assert [pace.frames() for _ in range(16)] == [0] * 7 + [1] + [0] * 7 + [1]
    pace.slower()
    assert pace.speed == 0.125  # the slowest
    for _ in range(7):
        pace.faster()
    assert pace.speed == 8.0
    assert pace.frames() == 8
    pace.rewinding = True
    assert pace.frames() == -8
    pace.rewinding, pace.paused = False, True
    assert pace.frames() == 0 and pace.alpha == 1.0
    pace.normal()
    assert pace.speed == 1.0


@pytest.mark.parametrize("bad", [3, 0, -1, "2", True, 0.3])
def test_speeds_are_checked(bad):
    with pytest.raises(ValueError, match="speed must be one of"):
        check_speed(bad)


def test_the_display_check():
    clean = {}
    with pytest.raises(NoDisplayError, match="no display: DISPLAY and WAYLAND_DISPLAY"):
        check_display(clean, "linux")
    for env in ({"DISPLAY": ":0"}, {"WAYLAND_DISPLAY": "wayland-0"}, {"SDL_VIDEODRIVER": "dummy"}):
        check_display(env, "linux")
    for platform in ("darwin", "win32"):
        check_display(clean, platform)


# -- the replay window --------------------------------------------------------------------------
def test_what_the_replay_window_says(classic):
    rep, _ = classic
    view = ReplayView(ReplayTimeline(rep), Pace(60), 480)
    text = "\n".join(line for line, _ in view._footer())
    assert f"frame 0 / {rep['frames']}" in text and "speed 1x" in text
    assert "paused" not in text
    for keys in ("Space", "hold R", "Esc", "[ ]"):
        assert keys in text
    view.press({"space", "]", "end"})
    text = view._footer()[0][0]
    assert f"frame {rep['frames']} / {rep['frames']}" in text and "speed 2x" in text
    assert "paused" in text and "end: final state as recorded" in text
    view.press({"1", ","})
    assert "speed 1x" in view._footer()[0][0] and view.timeline.frame == rep["frames"] - 1


@pytest.fixture(scope="module")
def pygame(optional):
    return optional("pygame")


def scripted_view(rep, script, **options):
    """The replay window run by ``script`` (its tests ask for the ``pygame`` fixture)."""
    from spacewar.view.replay_view import view_replay

    log = {}

    def on_tick(tick, view):
        log[tick] = dict(view.status(), state=view.timeline.game.state_hash(0))

    summary = view_replay(rep, fps=options.pop("fps", 120), scale=256, script=script,
                          on_tick=on_tick, **options)
    return summary, log


def test_replay_window_pauses_steps_speeds_up_and_rewinds_exactly(classic, pygame):
    rep, hashes = classic
    script = [(30, {"space"}), (31, set()), (40, {"."}), (41, set()), (42, {"."}), (43, set()),
              (44, {","}), (45, set()), (50, {"space"}), (51, {"]"}), (52, set()),
              (70, {"r"}), (90, set()), (95, {"p"}), (96, set()), (100, {"escape"})]
    summary, log = scripted_view(rep, script)
    assert summary["reason"] == "quit" and summary["ticks"] == 100
    assert log[29]["frame"] == 30 and not log[29]["paused"]
    assert all(log[t]["frame"] == 30 and log[t]["paused"] for t in range(30, 40))
    assert [log[t]["frame"] for t in (40, 42, 44)] == [31, 32, 31]  # single steps both ways
    assert log[50]["frame"] == 32 and not log[50]["paused"]
    assert log[51]["frame"] == 34 and log[51]["speed"] == 2.0  # fast forward
    assert log[69]["frame"] == 70
    assert log[70]["rewinding"] and log[70]["frame"] == 68
    assert log[89]["frame"] == 30  # 20 ticks back at 2x
    assert log[94]["frame"] == 40 and log[95]["paused"]
    for tick, entry in log.items():  # every frame shown is the straight run's, bit for bit
        assert entry["state"] == hashes[entry["frame"]], tick
    assert summary["frame"] == 40 and summary["state_sha256"] == hashes[40]
    assert summary["recorded_end"] is None


def test_replay_window_jumps_to_the_end_and_back_to_the_start(classic, pygame):
    rep, hashes = classic
    script = [(2, {"end"}), (3, set()), (5, {"home"}), (6, set()), (8, {"end"}), (9, set()),
              (10, {"left"}), (11, {"escape"})]
    summary, log = scripted_view(rep, script, fps=60)
    total = rep["frames"]
    assert log[2]["frame"] == total and log[2]["state"] == rep["final_state_sha256"]
    assert log[5]["frame"] == 1  # at the start, then one frame played
    assert log[10]["frame"] == total - 5 * 60 + 1
    assert summary["recorded_end"] is True
    assert summary["state_sha256"] == hashes[summary["frame"]]


def test_replay_window_rewinds_past_the_start_only_to_frame_0(classic, pygame):
    rep, hashes = classic
    script = [(0, {"]"}), (1, set()), (2, {"]"}), (3, set()), (10, {"backspace"}),
              (20, {"escape"})]
    summary, log = scripted_view(rep, script)
    # "]" at ticks 0 and 2 act before their ticks' frames: 2 + 2, then 8 ticks at 4x
    assert log[9]["speed"] == 4.0 and log[9]["frame"] == 2 + 2 + 4 * 8
    assert log[19]["frame"] == 0 and summary["state_sha256"] == hashes[0]


def test_clicking_the_bar_jumps_there(classic, pygame):
    rep, hashes = classic

    def click_at(fraction):
        def on_tick(tick, view):
            if tick == 3:
                left, right, top = view._bar()
                pos = (round(left + fraction * (right - left)), round(top + 2))
                pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, button=1, pos=pos))
            seen.append(view.timeline.frame)
        return on_tick

    from spacewar.view.replay_view import view_replay

    seen = []
    view_replay(rep, fps=60, scale=256, script=[(0, {"space"}), (1, set()), (12, {"q"})],
                on_tick=click_at(0.5))
    assert seen[:4] == [0, 0, 0, 0]
    target = seen[-1]
    assert abs(target - rep["frames"] / 2) <= rep["frames"] / 100  # a pixel's worth
    assert seen[-1] == seen[-2]  # paused there


def test_replay_view_without_a_display_exits_2(classic, tmp_path, monkeypatch, capsys):
    from spacewar.cli import main

    path = tmp_path / "game.json"
    replay_io.save(path, classic[0])
    for name in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER"):
        monkeypatch.delenv(name, raising=False)
    assert main(["replay", str(path), "--view"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("spacewar replay: no display:") and "\n" not in err


def test_replay_view_from_the_command_line(classic, tmp_path, monkeypatch, capsys, pygame):
    from spacewar.view import window as viewer
    from spacewar.cli import main

    path = tmp_path / "game.json"
    replay_io.save(path, classic[0])
    polls = {"n": 0}
    real_poll = viewer.Window.poll

    def poll(self):
        pressed, clicks, closed = real_poll(self)
        polls["n"] += 1
        if polls["n"] == 3:
            pressed = pressed | {"end"}
        if polls["n"] == 6:
            pressed = pressed | {"escape"}
        return pressed, clicks, closed

    monkeypatch.setattr(viewer.Window, "poll", poll)
    assert main(["replay", str(path), "--view", "--fps", "240", "--window-size", "200"]) == 0
    out = capsys.readouterr().out
    assert f"left the replay at frame {classic[0]['frames']} of {classic[0]['frames']}" in out
    assert "the final state is the recorded one" in out


def test_keys_help_lists_every_viewer_key():
    text = K.replay_epilog()
    for keys in ("Space or P", ". / ,", "hold R or Backspace", "Home / End", "click the bar",
                 "Esc or Q"):
        assert keys in text
    assert K.speed_label(0.125) == "1/8x" and K.speed_label(8.0) == "8x"


def _open_font_files():
    """How many of this process's descriptors are open on a font file (Linux's /proc)."""
    count = 0
    for fd in os.listdir("/proc/self/fd"):
        try:
            count += os.readlink(f"/proc/self/fd/{fd}").endswith((".ttf", ".otf"))
        except OSError:
            pass
    return count


def test_a_closed_window_keeps_no_font_file_open(pygame):
    """Each window's fonts held pygame's font file open after ``close``: a program opening
    window after window ran out of descriptors (the test suite left 42 open, and a confined
    bot host started after it got pipe numbers past its limit of 64)."""
    from spacewar.view.window import Window

    before = _open_font_files()
    for _ in range(3):
        window = Window(128, "fonts", ())
        window.show([("text", 10.0, 10.0, "frame 1", (255, 255, 255), "left", 12.0),
                     ("text", 10.0, 30.0, "frame 2", (255, 255, 255), "left", 20.0)])
        assert _open_font_files() > before  # the control: a shown text opens the font file
        window.close()
        assert _open_font_files() <= before  # (a font freed late elsewhere may lower it)
