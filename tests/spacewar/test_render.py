"""Tests for spacewar.render: replays to GIFs, single frames, the frame-to-frame effects."""
import os

import numpy as np
import pytest

from spacewar import render
from spacewar.game.game import Game
from spacewar.arena.match import play_match
from spacewar.render import Effects, render_frame, render_gif
from spacewar.replay import save
from spacewar.rules import Rules

SIZE = 320


@pytest.fixture(scope="module")
def Image(optional):
    """Pillow's Image module, for the tests that draw."""
    return optional("PIL.Image")


@pytest.fixture(scope="module")
def replay():
    _, rep, _ = play_match("chaser", "random", seed=1, rounds=1, record=True)
    return rep


@pytest.fixture(scope="module")
def starless_replay():
    _, rep, _ = play_match("chaser", "random", seed=1, rounds=1, rules=Rules(star="none"),
                           record=True)
    return rep


def frames_of(path):
    """Every frame of a GIF as an RGB array (Pillow composes the delta frames)."""
    from PIL import Image

    out = []
    with Image.open(path) as im:
        for k in range(im.n_frames):
            im.seek(k)
            out.append(np.asarray(im.convert("RGB")).copy())
    return out


def centre(frame, half=1):
    c = frame.shape[0] // 2
    return frame[c - half:c + half + 1, c - half:c + half + 1]


def test_gif_of_a_real_match(tmp_path, replay, Image):
    out = tmp_path / "match.gif"
    info = render_gif(replay, out, every=2, size=SIZE, max_frames=200)
    assert out.exists() and info["bytes"] == out.stat().st_size
    assert info["drawn"] == min(200, replay["frames"] // 2 + 1)
    with Image.open(out) as im:
        assert im.format == "GIF"
        assert im.size == (SIZE, SIZE)
        assert im.n_frames == info["frames"]
        assert im.info.get("loop") == 0
    frames = frames_of(out)
    assert len(frames) >= 0.9 * info["drawn"]  # few frames are so alike that they merge
    # the ships move: frames far apart differ, and nearly every frame differs from the last
    assert not np.array_equal(frames[0], frames[len(frames) // 2])
    changed = sum(not np.array_equal(a, b) for a, b in zip(frames, frames[1:]))
    assert changed == len(frames) - 1  # identical frames are merged into one
    # the heavy star is always drawn at the centre
    assert all(centre(f).max() > 100 for f in frames)
    # both ships' colours appear at the start
    first = frames[0].reshape(-1, 3)
    for rgb in render.SHIP_COLOURS:
        assert (first == rgb).all(axis=1).any()
    # only the GIF is left in the directory: the temporary file was moved into place
    assert os.listdir(tmp_path) == ["match.gif"]
    assert (out.stat().st_mode & 0o777) == 0o666 & ~_umask()


def _umask():
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def test_a_whole_match_to_the_end(tmp_path, replay, Image):
    out = tmp_path / "whole.gif"
    info = render_gif(replay, out, every=4, size=96)
    assert info["game_frames"] == replay["frames"]  # drawn to the last frame
    with Image.open(out) as im:
        assert im.size == (96, 96)
        im.seek(im.n_frames - 1)
        assert im.info["duration"] >= render.FINAL_HOLD_MS  # the final score stays up a moment


def test_no_star_leaves_the_centre_dark(tmp_path, starless_replay, Image):
    out = tmp_path / "nostar.gif"
    render_gif(starless_replay, out, size=SIZE, max_frames=5)
    frames = frames_of(out)
    assert frames and all(centre(f, half=3).max() == 0 for f in frames)


def test_every_and_max_frames_and_a_replay_file(tmp_path, replay, Image):
    path = tmp_path / "match.json"
    save(path, replay)
    out = tmp_path / "short.gif"
    info = render_gif(str(path), out, every=3, size=SIZE, fps=20, max_frames=12)
    assert info["drawn"] == 12
    assert info["game_frames"] == 33  # frames 0, 3, ..., 33
    with Image.open(out) as im:
        assert im.n_frames == info["frames"] <= 12
        im.seek(1)
        assert im.info["duration"] == 50  # 20 frames a second


def test_a_crash_mid_render_leaves_no_partial_file(tmp_path, replay, monkeypatch, Image):
    out = tmp_path / "keep.gif"
    out.write_bytes(b"GIF89a the previous file")  # a GIF may be replaced by a new GIF
    calls = {"n": 0}
    from spacewar.view import gif

    real = gif.render_frame

    def failing(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 20:
            raise RuntimeError("boom")
        return real(*args, **kwargs)

    monkeypatch.setattr(gif, "render_frame", failing)  # the GIF writer's own name for it
    with pytest.raises(RuntimeError, match="boom"):
        render_gif(replay, out, size=SIZE)
    assert out.read_bytes() == b"GIF89a the previous file"
    assert os.listdir(tmp_path) == ["keep.gif"]


def test_fallback_without_the_streaming_encoder(tmp_path, replay, monkeypatch, Image):
    from PIL import GifImagePlugin

    monkeypatch.delattr(GifImagePlugin, "getdata")
    out = tmp_path / "fallback.gif"
    info = render_gif(replay, out, size=SIZE, max_frames=15)
    frames = frames_of(out)
    assert info["drawn"] == 15 and 2 <= len(frames) <= 15
    assert all(centre(f).max() > 100 for f in frames)


def test_bad_arguments(tmp_path, replay, Image):
    for kwargs in ({"every": 0}, {"size": 10}, {"fps": 60}, {"fps": 0}, {"max_frames": 0}):
        with pytest.raises(ValueError):
            render_gif(replay, tmp_path / "x.gif", **kwargs)
    assert os.listdir(tmp_path) == []


# -- single frames ------------------------------------------------------------------------
def snapshot(**ship0):
    snap = Game(Rules(), seeds=[3], rounds=1).snapshot(0)
    snap["ships"][0].update(ship0)
    return snap


def colours(image, below=40):
    """The colours in the play area (below the score line, which uses the ships' colours)."""
    pixels = np.asarray(image.convert("RGB"))[below:]
    return {tuple(int(v) for v in c) for c in np.unique(pixels.reshape(-1, 3), axis=0)}


def test_render_frame_draws_the_ships_and_hides_one_in_hyperspace(Image):
    image = render_frame(snapshot(), 400)
    assert image.size == (400, 400) and image.mode == "P"
    assert set(render.SHIP_COLOURS) <= colours(image)
    hidden = render_frame(snapshot(in_hyperspace=True), 400)
    assert render.SHIP_COLOURS[0] not in colours(hidden)
    assert render.SHIP_COLOURS[1] in colours(hidden)


def test_flame_and_explosion(Image):
    assert render.FLAME_COLOURS[0] in colours(render_frame(snapshot(thrusting=True), 400))
    assert render.FLAME_COLOURS[0] not in colours(render_frame(snapshot(), 400))
    snap = snapshot(alive=False, killed_at=0)
    snap["frame"] = 6
    exploding = colours(render_frame(snap, 400))
    assert render.SHIP_COLOURS[0] not in exploding
    assert len(exploding & set(render.FIRE)) >= 2
    snap["frame"] = render.EXPLOSION_FRAMES + 1  # long over
    assert not colours(render_frame(snap, 400)) & set(render.FIRE[:4])


def test_a_ship_on_the_edge_is_drawn_on_both_sides(Image):
    image = np.asarray(render_frame(snapshot(pos=[-0.499, 0.1], heading=0.0), 400).convert("RGB"))
    blue = (image == render.SHIP_COLOURS[0]).all(axis=2)
    cols = np.flatnonzero(blue.any(axis=0))
    assert cols.min() < 10 and cols.max() > 390


def test_effects_see_hyperspace_and_vanished_torpedoes():
    effects = Effects()
    a = snapshot()
    a["torpedoes"] = [{"pos": [0.1, 0.1], "owner": 0}, {"pos": [0.2, 0.2], "owner": 0}]
    a["ships"][0]["torpedoes"] = 30
    effects.update(a)
    b = snapshot(in_hyperspace=True)
    b["frame"] = 1
    b["round_frame"] = 1
    # the first torpedo went on, the second vanished, and a new one was launched
    b["torpedoes"] = [{"pos": [0.104, 0.1], "owner": 0}, {"pos": [-0.3, 0.2], "owner": 0}]
    b["ships"][0]["torpedoes"] = 29
    effects.update(b)
    kinds = sorted((e[0], e[1]) for e in effects.current(1))
    assert kinds == [("burst", 0), ("jump", 0)]
    burst = [e for e in effects.current(1) if e[0] == "burst"][0]
    assert burst[2:4] == (0.2, 0.2)
    assert effects.current(1 + render.HYPERSPACE_FLASH_FRAMES) == []
    # a new round clears everything (torpedoes vanish then, nothing bursts)
    c = snapshot()
    c["frame"], c["round"] = 2, 1
    effects.update(c)
    assert effects.current(2) == []


def test_missing_pillow_says_how_to_install(monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "PIL", None)
    with pytest.raises(ImportError, match=r"\.\[viz\]"):
        render.require_pillow()


def test_single_frame_gif(tmp_path, replay, Image):
    out = tmp_path / "one.gif"
    info = render_gif(replay, out, size=SIZE, max_frames=1)
    assert info["frames"] == 1
    with Image.open(out) as im:
        assert im.n_frames == 1 and im.size == (SIZE, SIZE)


# -- what the top of the screen shows (frame_snapshot) ----------------------------------------
def played(rules, frames=90, seed=3):
    """A game after both ships thrusted and fired for ``frames`` frames (ship 1 flips its
    charge first in the electric mode)."""
    from spacewar.protocol import Action

    game = Game(rules, seeds=[seed], rounds=2)
    for i in range(frames):
        game.step([[Action(turn=1, thrust=True, fire=True),
                    Action(fire=True, thrust=i < 40, flip=i == 0 and rules.mode == "electric")]])
    return game


def rgb(image):
    return np.asarray(image.convert("RGB"))


def mask(pixels, colour):
    return (pixels == colour).all(axis=2)


def test_frame_snapshot_adds_what_the_gauges_need():
    game = played(Rules(mode="electric"))
    snap = render.frame_snapshot(game)
    assert snap["mode"] == "electric" and snap["fuel_capacity"] == game.rules.fuel
    assert snap["torpedo_capacity"] == 32 and snap["hyperspace_capacity"] == 8
    assert [s["hyperspace"] for s in snap["ships"]] == [8, 8]
    assert snap["torpedoes"] and all(t["charge"] != 0 for t in snap["torpedoes"])
    # a torpedo carries its launcher's charge: ship 1 flipped before it fired, so the charges
    # of both ships' torpedoes have the same sign
    signs = {t["owner"]: np.sign(t["charge"]) for t in snap["torpedoes"]}
    assert signs[0] == signs[1] == np.sign(snap["ships"][0]["charge"])
    base = game.snapshot(0)
    assert {k: v for k, v in snap.items() if k in base and k not in ("ships", "torpedoes")} == \
        {k: v for k, v in base.items() if k not in ("ships", "torpedoes")}


def test_the_gauges_show_mode_fuel_torpedoes_and_charge(Image):
    size = 480
    top = int(render.hud_bottom(size))
    game = played(Rules(mode="electric"))
    electric = rgb(render_frame(render.frame_snapshot(game), size))[:top]
    plain = rgb(render_frame(game.snapshot(0), size))[:top]
    # the gauges line: text in both ships' colours under the score line
    line = slice(int(render.font_pixels(size) * 1.6), top)
    for seat, colour in enumerate(render.SHIP_COLOURS):
        half = electric[line, :size // 2] if seat == 0 else electric[line, size // 2:]
        assert mask(half, colour).sum() > 40
        assert mask(plain[line], colour).sum() == 0
    # the mode's name in the middle, the charge signs (a plus and a minus) at the edges
    middle = electric[line, size // 2 - 40:size // 2 + 40]
    assert mask(middle, render.DIM_TEXT).sum() > 20
    plus, minus = render.CHARGE_COLOURS
    assert mask(electric[line, :40], plus).sum() >= 8  # ship 0 is positive
    assert mask(electric[line, -40:], plus).sum() + mask(electric[line, -40:], minus).sum() >= 4
    classic = rgb(render_frame(render.frame_snapshot(played(Rules())), size))[:top]
    assert not mask(classic, plus).any() and not mask(classic, minus).any()


def test_the_fuel_bar_is_as_long_as_the_fuel_left(Image):
    size = 480
    snap = render.frame_snapshot(Game(Rules(), seeds=[1]))
    lengths = {}
    for fraction in (1.0, 0.5, 0.25):
        snap["ships"][0]["fuel"] = fraction * snap["fuel_capacity"]
        pixels = rgb(render_frame(snap, size))
        rows = mask(pixels[:int(render.hud_bottom(size))], render.SHIP_COLOURS[0])
        bar_row = rows[int(render.font_pixels(size) * 1.75 + render.footer_pixels(size) * 1.3) + 1]
        lengths[fraction] = int(bar_row.sum())
    full = 0.2 * size  # the bar is a fifth of the image wide
    for fraction, length in lengths.items():
        assert abs(length - fraction * full) <= 2, lengths


def test_torpedoes_are_visible_dots_at_480_pixels(Image):
    snap = render.frame_snapshot(Game(Rules(), seeds=[3]))
    snap["torpedoes"] = [{"pos": [0.2, -0.2], "owner": 0, "charge": 0.0}]
    pixels = rgb(render_frame(snap, 480))
    dot = mask(pixels, render.TORPEDO_COLOURS[0])
    assert dot.sum() >= 16  # about 5 pixels across, not one
    rows, cols = np.nonzero(dot)
    assert rows.max() - rows.min() >= 4 and cols.max() - cols.min() >= 4
    x, y = render.to_pixels(0.2, -0.2, 480)
    assert abs(rows.mean() - y) < 1 and abs(cols.mean() - x) < 1


def test_electric_torpedoes_wear_their_charge(Image):
    snap = render.frame_snapshot(Game(Rules(mode="electric"), seeds=[3]))
    snap["torpedoes"] = [{"pos": [0.2, -0.2], "owner": 1, "charge": -4e-4}]
    pixels = rgb(render_frame(snap, 480))
    x, y = (int(round(v)) for v in render.to_pixels(0.2, -0.2, 480))
    around = pixels[y - 8:y + 9, x - 8:x + 9]
    assert mask(around, render.CHARGE_COLOURS[1]).sum() >= 8
    assert mask(around, render.TORPEDO_COLOURS[1]).sum() >= 12


def test_the_gif_shows_the_gauges(tmp_path, Image):
    _, rep, _ = play_match("chaser", "sniper", seed=2, rounds=1, rules=Rules(mode="electric"),
                           record=True)
    out = tmp_path / "electric.gif"
    render_gif(rep, out, size=480, max_frames=40)
    last = frames_of(out)[-1][:int(render.hud_bottom(480))]
    for colour in render.SHIP_COLOURS:
        assert mask(last, colour).sum() > 100
    assert mask(last, render.CHARGE_COLOURS[0]).any() and mask(last, render.CHARGE_COLOURS[1]).any()
