"""``python -m engine cloth``: the pinned cloth and rope GIF demo."""
import json
import subprocess
import sys

import numpy as np
import pytest

from engine import __main__ as cli
from engine import cloth_demo


def test_the_demo_writes_a_gif_with_the_frames_asked_for(tmp_path, capsys, optional):
    PIL = optional("PIL.Image")
    out = tmp_path / "cloth.gif"
    cli.main(["cloth", "--out", str(out), "--frames", "4", "--grid", "6", "--width", "160",
              "--height", "120"])
    with PIL.open(out) as gif:
        assert gif.format == "GIF"
        assert gif.size == (160, 120)
        assert gif.n_frames == 4
        gif.seek(3)
        gif.load()
    printed = capsys.readouterr().out
    assert "stable_dt" in printed and str(out) in printed
    assert not [p for p in tmp_path.iterdir() if p.name != "cloth.gif"]  # no temporary left


def test_the_scene_hangs_from_its_pins_at_a_fraction_of_the_stable_step(tmp_path, optional):
    optional("PIL")  # run draws the GIF
    summary = cloth_demo.run(tmp_path / "c.gif", frames=3, grid=5, width=80, height=60,
                             log=lambda *a: None)
    assert 0.0 < summary["dt"] <= cloth_demo.SAFETY * summary["stable_dt"]
    sim, cloth, rope, _ = cloth_demo.build_scene(grid=5)
    pins = np.flatnonzero(sim.pinned)
    assert set(pins) == {int(cloth[0, 0]), int(cloth[-1, 0]), int(rope[0])}
    anchors = sim.pos[pins].copy()
    sim.dt = 0.5 * sim.stable_dt()
    sim.step(400)
    assert sim.pos[pins].tobytes() == anchors.tobytes()
    assert sim.pos[cloth[2, -1], 2] < -0.9  # the cloth hangs
    assert sim.pos[rope[-1], 2] < -0.05  # the rope has swung down from the horizontal
    first = np.linalg.norm(sim.pos[rope[1]] - sim.pos[rope[0]])
    assert abs(first - 0.75 / (len(rope) - 1)) < 0.2 * 0.75 / (len(rope) - 1)  # still attached


@pytest.mark.parametrize("problem", ["missing directory", "a directory", "a JSON file"])
def test_a_bad_output_path_fails_before_any_work(tmp_path, monkeypatch, capsys, problem):
    out = {"missing directory": tmp_path / "nowhere" / "cloth.gif",
           "a directory": tmp_path,
           "a JSON file": tmp_path / "replay.json"}[problem]
    if problem == "a JSON file":
        out.write_text(json.dumps({"keep": "me"}))

    def no_work(*args, **kwargs):
        raise AssertionError("the scene was built before the output path was checked")

    monkeypatch.setattr(cloth_demo, "build_scene", no_work)
    monkeypatch.setattr(cloth_demo, "require_pillow", no_work)
    with pytest.raises(SystemExit) as exit_:
        cli.main(["cloth", "--out", str(out), "--frames", "2"])
    assert exit_.value.code == 2
    assert str(out) in capsys.readouterr().err
    if problem == "a JSON file":
        assert json.loads(out.read_text()) == {"keep": "me"}


def test_without_pillow_it_says_which_extra_to_install(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "PIL", None)  # import PIL now raises ImportError

    def no_work(*args, **kwargs):
        raise AssertionError("the scene was built without Pillow to draw it")

    monkeypatch.setattr(cloth_demo, "build_scene", no_work)
    with pytest.raises(SystemExit) as exit_:
        cli.main(["cloth", "--out", str(tmp_path / "c.gif")])
    assert exit_.value.code == 2
    assert "[viz]" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("args", [["--frames", "0"], ["--frames", "x"], ["--grid", "1"],
                                  ["--safety", "0"], ["--safety", "1.5"], ["--wind", "-1"],
                                  ["--fps", "60"]])
def test_bad_arguments_are_refused(tmp_path, capsys, args):
    with pytest.raises(SystemExit) as exit_:
        cli.main(["cloth", "--out", str(tmp_path / "c.gif")] + args)
    assert exit_.value.code == 2
    assert args[0] in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_the_kepler_tour_still_runs_without_a_command():
    done = subprocess.run([sys.executable, "-m", "engine", "--orbits", "1", "--evaluations", "40"],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "Kepler problem" in done.stdout and "pefrl" in done.stdout
    helped = subprocess.run([sys.executable, "-m", "engine", "--help"], capture_output=True,
                            text=True, timeout=600)
    assert "cloth" in helped.stdout


def test_the_torn_sail_yields_and_tears_and_its_torn_triangles_are_not_drawn(tmp_path, optional):
    optional("PIL")
    summary = cloth_demo.run(str(tmp_path / "sail.gif"), frames=40, width=160, height=120,
                             grid=10, wind=60.0, tear=True, log=lambda text: None)
    assert summary["energy_ledger"] > 0.0  # yielding and breaking took energy out
    assert summary["broken"] > 0
    sim, cloth, _, _ = cloth_demo.build_scene(grid=10, tear=True)
    springs = cloth_demo.cloth_springs(sim)
    assert springs.plastic and sim.pinned[cloth[:, 0]].all()  # laced along the spar
    from engine import forces

    assert cloth_demo.intact(sim, forces.grid_triangles(cloth)).all()  # nothing torn yet
