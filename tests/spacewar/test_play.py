"""Tests for spacewar.play: the human-against-bot window, run headless with scripted keys."""
import os

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ["SDL_AUDIODRIVER"] = "dummy"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import pytest  # noqa: E402

pygame = pytest.importorskip("pygame")

from spacewar import play as play_module  # noqa: E402
from spacewar.play import action_code, play, script_source  # noqa: E402
from spacewar.protocol import Action  # noqa: E402


def test_keys_to_actions():
    assert action_code(frozenset()) == Action().code()
    assert action_code(frozenset({"a"})) == Action(turn=1).code()
    assert action_code(frozenset({"right"})) == Action(turn=-1).code()
    assert action_code(frozenset({"up", "space"})) == Action(thrust=True, fire=True).code()
    assert action_code(frozenset({"w", "s", "f"})) == Action(thrust=True, fire=True, flip=True).code()
    # both turn keys at once is hyperspace, as on the 1962 control boxes
    assert action_code(frozenset({"a", "d"})) == Action(hyperspace=True).code()
    assert action_code(frozenset({"h"})) == Action(hyperspace=True).code()


def test_scripts():
    held = script_source([(10, {"W"}), (0, set()), (20, ["space", "a"])])
    assert held(0) == frozenset() and held(9) == frozenset()
    assert held(10) == {"w"} and held(19) == {"w"}
    assert held(500) == {"space", "a"}
    assert script_source(lambda f: "escape")(3) == {"escape"}
    with pytest.raises(ValueError, match="unknown key"):
        script_source([(0, {"x"})])
    with pytest.raises(ValueError):
        script_source(42)


def test_scripted_thrust_and_fire_against_idle():
    script = [(0, {"w"}), (20, {"w", "space"}), (70, {"a"}), (80, set())]
    result = play(p2="idle", script=script, max_seconds=3, scale=360)
    assert result["reason"] == "time"
    # 60 frames a second for 3 s, less any the clock dropped if drawing fell behind
    assert 90 <= result["frames"] <= 200
    assert result["frames"] + result["dropped_steps"] >= 150
    assert result["torpedoes_fired"][0] >= 3  # fire held 50 frames, reload 16
    assert result["torpedoes_fired"][1] == 0
    assert result["distance"][0] > 0.05 > result["distance"][1]  # thrust vs the star's pull
    assert result["scores"] == [0, 0] and not result["over"] and result["winner"] is None
    assert result["bot_faults"] == 0


def test_escape_quits_early():
    result = play(p2="idle", script=[(0, {"space"}), (20, {"escape"})], max_seconds=10, scale=256)
    assert result["reason"] == "quit"
    assert result["frames"] == 20
    assert result["wall_seconds"] < 5
    # the same with a callable script
    result = play(p2="idle", script=lambda f: {"escape"} if f >= 5 else set(), max_seconds=10,
                  scale=256)
    assert result["reason"] == "quit" and result["frames"] == 5


def test_pause_and_resume_by_script():
    script = [(10, {"p"}), (11, set()), (40, {"p"}), (41, set()), (60, {"escape"})]
    result = play(p2="chaser", script=script, max_seconds=10, scale=256)
    assert result["reason"] == "quit"
    assert result["paused_frames"] == 30  # frames 10 to 39 of the script's time line
    assert result["frames"] == 30


def test_the_real_keyboard_path(monkeypatch):
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


def test_a_game_played_to_the_end_returns_the_result():
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
