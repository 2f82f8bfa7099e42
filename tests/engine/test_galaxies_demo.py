"""``python -m engine galaxies``: the colliding disk galaxies GIF demo."""
import json
import math
import sys

import numpy as np
import pytest

from engine import __main__ as cli
from engine import analytic
from engine import galaxies_demo as demo

TINY = ["--bodies", "2000", "--frames", "3", "--steps-per-frame", "2", "--width", "96",
        "--height", "80", "--no-progress"]


# ---------------------------------------------------------------- the picture, on known input

def test_bodies_land_in_the_pixels_they_fall_in_y_up_and_galaxy_by_index():
    # 4 x 2 pixels of side 0.5 over [-1, 1] x [-0.5, 0.5]; row 0 is the top (y > 0)
    x = np.array([-0.9, -0.9, 0.1, 0.99, 2.0, 0.1])
    y = np.array([0.4, 0.4, -0.1, 0.01, 0.0, -0.1])
    counts = demo.pixel_counts(x, y, first=3, width=4, height=2, half_width=1.0)
    want = np.zeros((2, 2, 4), dtype=int)
    want[0, 0, 0] = 2      # two of the first galaxy, top left
    want[0, 1, 2] = 1      # one of the first galaxy, bottom, third column
    want[1, 0, 3] = 1      # the second galaxy: top right; x = 2 is outside and dropped
    want[1, 1, 2] = 1
    assert counts.shape == (2, 2, 4)
    assert np.array_equal(counts, want)


def test_brightness_is_log_scaled_and_saturates():
    level = demo.brightness(np.array([0, 1, 3, 7, 100]), saturation=3.0)
    # log(1 + c) / log(4): 0, 1/2, 1, then clipped at 1
    assert np.allclose(level, [0.0, 0.5, 1.0, 1.0, 1.0], rtol=0, atol=1e-15)
    # the saturation count is SATURATION_DENSITY n bodies per unit area over one pixel
    assert demo.saturation_count(200_000, 480, 9.0) == pytest.approx(
        0.4 / (2 * math.pi * 0.25) * 200_000 * (18.0 / 480) ** 2, rel=1e-12)
    assert demo.saturation_count(10, 480, 9.0) == 1.0


def test_a_frame_of_known_bodies_has_the_colours_the_formula_gives(optional):
    optional("PIL")
    Image, ImageDraw = demo.require_pillow()
    n_first = 3
    pos = np.zeros((5, 3))
    pos[:3] = (-0.45, 0.45, 7.0)   # first galaxy: 3 bodies in the top-left pixel (z ignored)
    pos[3] = (0.45, -0.45, 0.0)    # second galaxy: 1 body in the bottom-right pixel
    pos[4] = (-0.45, 0.45, 0.0)    # ... and 1 on top of the first galaxy's pixel
    img = demo.draw_frame(pos, n_first, 10, 10, 0.5, "", Image, ImageDraw)
    assert img.size == (10, 10) and img.mode == "RGB"
    rgb = np.asarray(img).astype(float)
    sat = demo.saturation_count(5, 10, 0.5)   # 0.255 x 5 x 0.01 < 1: one body saturates
    assert sat == 1.0
    bg, warm, cool = (np.array(c, float) for c in (demo.BACKGROUND, *demo.COLOURS))
    assert np.array_equal(rgb[0, 0], np.clip(bg + warm + cool, 0, 255))   # both, added
    assert np.array_equal(rgb[9, 9], np.clip(bg + cool, 0, 255))
    others = np.ones((10, 10), bool)
    others[0, 0] = others[9, 9] = False
    assert np.all(rgb[others] == bg)
    # below saturation, log-scaled: 4000 bodies (all but 3 far outside the picture) saturate
    # a pixel of side 0.05 at 0.2546 x 4000 x 0.0025 = 2.546 bodies
    many = np.full((4000, 3), 1e3)
    many[0] = (-0.475, 0.475, 0.0)          # the centre of pixel (row 90, column 90)
    many[1:3] = (0.025, -0.025, 0.0)        # two in pixel (100, 100)
    img = demo.draw_frame(many, 4000, 200, 200, 5.0, "", Image, ImageDraw)
    sat = demo.saturation_count(4000, 200, 5.0)
    assert sat == pytest.approx(2.546, abs=1e-3)
    rgb = np.asarray(img).astype(float)
    for (row, col), count in (((90, 90), 1), ((100, 100), 2)):
        level = math.log1p(count) / math.log1p(sat)   # 0.547 and 0.867
        assert np.allclose(rgb[row, col], np.rint(bg + level * warm), rtol=0, atol=0.5)
    assert np.count_nonzero(np.any(rgb != bg, axis=2)) == 2


def test_the_tilted_camera_sees_z_as_up():
    pos = np.array([[1.0, 2.0, 3.0]])
    x, y = demo.project(pos, 0.0)
    assert (x[0], y[0]) == (1.0, 2.0)
    x, y = demo.project(pos, math.pi / 2)  # edge-on: the orbit plane is a line, z is up
    assert x[0] == 1.0 and y[0] == pytest.approx(3.0, abs=1e-15)


# ---------------------------------------------------------------- the scene

def test_before_they_meet_the_galaxies_move_as_two_point_masses():
    """Their centres follow the Kepler orbit galaxy_pair sets them on (q = 2, e = 0.95, from
    8 apart) while they are far apart: measured 0.005 off at t = 4 (of 6.3)."""
    sim, first = demo.build_scene(bodies=2000, seed=0)
    assert first == 1000 and sim.integrator == "leapfrog" and sim.dt == demo.DT
    d, q, e = 8.0, 2.0, 0.95
    v_t = math.sqrt(q * (1 + e)) / d
    v_r = -math.sqrt(2 / d - (1 - e) / q - v_t * v_t)
    sim.integrate(4.0)
    rel = sim.pos[first:].mean(axis=0) - sim.pos[:first].mean(axis=0)
    kepler, _ = analytic.kepler(np.array([d, 0.0]), np.array([v_r, v_t]), 1.0, 4.0)
    assert np.linalg.norm(rel[:2] - kepler) < 0.02
    assert abs(rel[2]) < 0.01


# ---------------------------------------------------------------- the command

def test_a_tiny_run_writes_a_gif_of_the_frames_asked_for(tmp_path, capsys, optional):
    PIL = optional("PIL.Image")
    out = tmp_path / "galaxies.gif"
    cli.main(["galaxies", "--out", str(out)] + TINY)
    with PIL.open(out) as gif:
        assert gif.format == "GIF" and gif.size == (96, 80) and gif.n_frames == 3
        assert gif.info["duration"] == 1000 // demo.FPS
        frames = []
        for k in range(3):
            gif.seek(k)
            frames.append(np.asarray(gif.convert("RGB")).astype(int))
    background = np.array(demo.BACKGROUND)
    for frame in frames:
        lit = np.any(frame != background, axis=2)
        assert lit[:16].sum() > 50      # the label (measured about 240 pixels)
        assert lit[20:].sum() > 250     # bodies below it, not a blank frame (measured 510)
        warm = (frame[..., 0] > frame[..., 2] + 40).sum()
        cool = (frame[..., 2] > frame[..., 0] + 40).sum()
        assert warm > 50 and cool > 50  # both galaxies in their colours (measured 160, 200)
    assert np.any(frames[0] != frames[2])   # they moved
    printed = capsys.readouterr().out
    assert "estimated" in printed and str(out) in printed and "t = 0.2" in printed
    assert not [p for p in tmp_path.iterdir() if p.name != "galaxies.gif"]  # no temporary left


def test_a_png_out_gets_the_last_frame(tmp_path, optional):
    PIL = optional("PIL.Image")
    out = tmp_path / "last.png"
    summary = demo.run(out, bodies=2000, frames=2, steps_per_frame=1, width=64, height=64,
                       log=lambda *a: None, progress=False)
    assert summary["frames"] == 1 and summary["steps"] == 1
    assert summary["t"] == pytest.approx(demo.DT, rel=1e-12)
    with PIL.open(out) as png:
        assert png.format == "PNG" and png.size == (64, 64)


@pytest.mark.parametrize("problem", ["missing directory", "a directory", "a JSON file",
                                     "a GIF to a PNG"])
def test_a_bad_output_path_fails_before_any_work(tmp_path, monkeypatch, capsys, problem):
    out = {"missing directory": tmp_path / "nowhere" / "galaxies.gif",
           "a directory": tmp_path,
           "a JSON file": tmp_path / "results.json",
           "a GIF to a PNG": tmp_path / "old.png"}[problem]
    if problem == "a JSON file":
        out.write_text(json.dumps({"keep": "me"}))
    if problem == "a GIF to a PNG":
        out.write_bytes(b"GIF89a" + bytes(20))

    def no_work(*args, **kwargs):
        raise AssertionError("work started before the output path was checked")

    monkeypatch.setattr(demo, "build_scene", no_work)
    monkeypatch.setattr(demo, "require_pillow", no_work)
    with pytest.raises(SystemExit) as exit_:
        cli.main(["galaxies", "--out", str(out)] + TINY)
    assert exit_.value.code == 2
    assert str(out) in capsys.readouterr().err
    if problem == "a JSON file":
        assert json.loads(out.read_text()) == {"keep": "me"}


def test_without_pillow_it_says_which_extra_to_install(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "PIL", None)  # import PIL now raises ImportError

    def no_work(*args, **kwargs):
        raise AssertionError("the scene was built without Pillow to draw it")

    monkeypatch.setattr(demo, "build_scene", no_work)
    with pytest.raises(SystemExit) as exit_:
        cli.main(["galaxies", "--out", str(tmp_path / "g.gif")])
    assert exit_.value.code == 2
    assert "[viz]" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("flag, value", [
    ("--bodies", "2001"), ("--bodies", "2"), ("--bodies", "many"), ("--frames", "0"),
    ("--steps-per-frame", "-3"), ("--theta", "2.5"), ("--theta", "-0.1"), ("--dt", "0"),
    ("--dt", "nan"), ("--softening", "-1"), ("--seed", "-1"), ("--tilt", "95"),
    ("--view", "inf"), ("--width", "8"), ("--fps", "60")])
def test_bad_arguments_are_refused_naming_the_flag_and_value(tmp_path, monkeypatch, capsys,
                                                             flag, value):
    monkeypatch.setattr(demo, "build_scene", lambda *a, **k: pytest.fail("work started"))
    with pytest.raises(SystemExit) as exit_:
        cli.main(["galaxies", "--out", str(tmp_path / "g.gif"), flag, value])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert flag in err and value in err
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("field, value, error", [
    ("bodies", 2001, ValueError), ("bodies", 2000.0, TypeError), ("frames", 0, ValueError),
    ("steps_per_frame", True, TypeError), ("dt", -0.1, ValueError),
    ("softening", float("nan"), ValueError), ("theta", 2.0, ValueError),
    ("fps", 51, ValueError), ("width", 10, ValueError), ("tilt", 91.0, ValueError)])
def test_run_refuses_bad_values_naming_them_before_any_work(tmp_path, monkeypatch, field,
                                                            value, error):
    monkeypatch.setattr(demo, "build_scene", lambda *a, **k: pytest.fail("work started"))
    with pytest.raises(error, match=field) as raised:
        demo.run(tmp_path / "g.gif", **{field: value})
    assert repr(value) in str(raised.value)
    assert not list(tmp_path.iterdir())
