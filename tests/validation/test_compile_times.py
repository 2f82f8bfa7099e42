"""``python -m validation compile-times``: a cold command's compiled functions, counted and timed
in a child process with an empty cache."""
import json
import os

import pytest

from engine.atomic import OutputPathError
from validation import compile_times

# A command that compiles ``square`` for two types (int64 twice: one specialisation) and
# ``outer``, whose compilation compiles ``inner`` inside it, then exits with code 3 (run as
# ``python -m``, its functions are named ``__main__.*``).
SCRIPT = """\
import sys
import numba

@numba.njit
def square(x):
    return x * x

@numba.njit
def inner(x):
    return x + 1.0

@numba.njit
def outer(x):
    return inner(x) * 2.0

square(2); square(2.5); square(3)
outer(1.0)
sys.exit(3)
"""


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    folder = tmp_path_factory.mktemp("command")
    (folder / "three_functions.py").write_text(SCRIPT)
    saved = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(folder), saved]))
    try:
        return compile_times.measure(["three_functions"])
    finally:
        if saved is None:
            del os.environ["PYTHONPATH"]
        else:
            os.environ["PYTHONPATH"] = saved


def test_each_specialisation_is_one_compilation_and_the_exit_code_is_kept(measured):
    summary = compile_times.summarise(measured, ["three_functions"], note="n")
    counts = {name: n for name, n, _ in summary["functions"]}
    assert counts == {"__main__.square": 2, "__main__.inner": 1,
                      "__main__.outer": 1}
    assert summary["compilations"] == 4 and summary["exit_code"] == 3
    assert summary["command"] == ["three_functions"] and summary["note"] == "n"
    assert summary["compile_seconds"] == pytest.approx(sum(r[2] for r in summary["functions"]),
                                                       abs=0.01)  # rounded to 10 ms
    assert [r[2] for r in summary["functions"]] == sorted((r[2] for r in summary["functions"]),
                                                          reverse=True)


def test_a_callee_compiled_inside_its_caller_is_not_counted_twice(measured):
    """``inner`` is compiled while ``outer`` is typed: outer's seconds exclude inner's."""
    records = {r["function"].split(".")[-1]: r for r in measured["records"]
               if "square" not in r["function"]}
    assert records["inner"]["nested"] and not records["outer"]["nested"]
    assert all(r["seconds"] > 0.0 for r in measured["records"])
    total = sum(r["seconds"] for r in measured["records"])
    assert total <= measured["wall_seconds"] * 1.05 + 0.5  # CPU seconds of one thread


def test_the_table_lists_the_longest_and_sums_the_rest(measured):
    summary = compile_times.summarise(measured, ["three_functions"])
    table = compile_times.format_table(summary, top=1).splitlines()
    first = summary["functions"][0]
    assert table[0].startswith("4 compilations of 3 functions: ")
    assert table[4] == f"| `{first[0]}` | {first[1]} | {first[2]:.2f} |"
    rest = sum(r[2] for r in summary["functions"][1:])
    assert table[5] == f"| 2 others | | {rest:.2f} |"


def test_a_bad_output_path_is_refused_before_the_command_runs(tmp_path, capsys):
    missing = tmp_path / "no" / "such" / "folder" / "out.json"
    with pytest.raises(OutputPathError, match="folder"):
        compile_times.main(["--out", str(missing), "--", "this_module_does_not_exist"])
    assert not missing.exists()


def test_the_command_after_the_separator_is_required(capsys):
    with pytest.raises(SystemExit):
        compile_times.main(["--top", "3"])
    assert "give the command after --" in capsys.readouterr().err


def test_a_measurement_is_written_as_json(tmp_path, monkeypatch, measured, capsys):
    monkeypatch.setattr(compile_times, "measure", lambda command: measured)
    out = tmp_path / "times.json"
    assert compile_times.main(["--out", str(out), "--top", "2", "--", "three_functions"]) == 3
    kept = json.loads(out.read_text())
    assert kept == compile_times.summarise(measured, ["three_functions"])
    assert "| `__main__." in capsys.readouterr().out


def test_the_bench_shows_each_command_before_and_after(measured):
    from validation.bench import compile_time_markdown

    after = compile_times.summarise(measured, ["three_functions"], note="after the change")
    before = dict(after, compile_seconds=99.5, note="the base")
    lines = compile_time_markdown({"three": after, "three.before": before, "other": after})
    rows = [line for line in lines if line.startswith("| `python -m three_functions` |")]
    assert rows[0] == (f"| `python -m three_functions` | 99.5 s in 3 functions (4 compilations)"
                       f" | {after['compile_seconds']:.1f} s in 3 functions (4 compilations) |")
    assert rows[1].startswith("| `python -m three_functions` | not measured | ")
    assert "Before (the base):" in lines and "after the change" in lines
    assert compile_time_markdown({}) == []
