"""Compiling ahead (``engine.compile_ahead``): tasks run in worker processes fill the cache,
their records say when they are fresh, and a stale record sends the task back to work."""
import json

import pytest

from engine import compile_ahead
from engine.compile_ahead import Task

EULER = Task("tour-euler", "engine.__main__:first_runs", ("euler",))


@pytest.fixture()
def cold_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))  # the workers inherit it
    monkeypatch.delenv("NBODY_COMPILE_AHEAD", raising=False)
    return tmp_path


def test_a_task_runs_once_and_is_then_fresh(cold_cache, capsys):
    assert EULER in compile_ahead.TOUR
    assert not compile_ahead.fresh(EULER)
    done = compile_ahead.run([EULER], jobs=1)
    assert list(done) == ["tour-euler"] and done["tour-euler"] > 0.0
    assert compile_ahead.fresh(EULER)
    with open(compile_ahead.record_path(EULER), encoding="utf-8") as f:
        record = json.load(f)
    # what the task entered from Python, each with the stamp of the sources it is built from
    from engine import cache
    from engine.integrators import euler

    assert record["entered"]["engine.integrators.euler:advance"] == \
        cache.dependency_stamp(euler.advance)
    assert compile_ahead.run([EULER], jobs=1) == {}  # nothing left to do

    # a source of one of them changed: the record's stamp is no longer the current one
    record["entered"]["engine.integrators.euler:advance"] = "0" * 64
    with open(compile_ahead.record_path(EULER), "w", encoding="utf-8") as f:
        json.dump(record, f)
    assert not compile_ahead.fresh(EULER)

    compile_ahead.main(compile_ahead.parser().parse_args(["--list"]), [EULER])
    assert capsys.readouterr().out.split() == ["tour-euler", "to", "compile"]


def test_a_record_of_other_arguments_or_garbage_is_not_fresh(cold_cache):
    path = compile_ahead.record_path(EULER)
    (cold_cache / "compiled" / "ahead").mkdir(parents=True)
    for text in ("not json", "[]", json.dumps({"args": ["rk4"], "entered": {"x:y": "0"}}),
                 json.dumps({"args": ["euler"], "entered": {}}),
                 json.dumps({"args": ["euler"], "entered": {"engine.nothing:here": "0"}})):
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)
        assert not compile_ahead.fresh(EULER), text


def test_switched_off_by_the_environment(cold_cache, monkeypatch):
    monkeypatch.setenv("NBODY_COMPILE_AHEAD", "0")
    assert compile_ahead.run([EULER]) == {}
    assert not (cold_cache / "compiled" / "ahead").exists()


def test_jobs_must_be_positive():
    with pytest.raises(SystemExit, match="--jobs must be at least 1, got 0"):
        compile_ahead.main(compile_ahead.parser().parse_args(["--jobs", "0"]), [EULER])
