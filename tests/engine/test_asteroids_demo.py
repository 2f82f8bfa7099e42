"""``python -m engine asteroids``: the belt of rocks that bounce and merge."""
import pytest

from engine import __main__ as cli
from engine import asteroids_demo


def test_the_belt_bounces_and_merges_keeping_its_mass(tmp_path, optional):
    PIL = optional("PIL.Image")
    out = tmp_path / "belt.gif"
    summary = asteroids_demo.run(str(out), rocks=150, frames=30, size=160,
                                 log=lambda text: None)
    assert summary["bounces"] > 0 and summary["merges"] > 0
    assert summary["rocks_left"] == 150 - summary["merges"]  # every merge takes one rock
    assert summary["mass"] == pytest.approx(summary["mass0"], rel=1e-13)
    with PIL.open(out) as gif:
        assert gif.n_frames == 30 and gif.size == (160, 160)
    assert [p.name for p in tmp_path.iterdir()] == ["belt.gif"]  # no temporary left


def test_a_bad_output_path_fails_before_any_work(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["asteroids", "--out", str(tmp_path / "missing" / "belt.gif")])
    assert info.value.code == 2
    assert "missing" in capsys.readouterr().err
