"""Validation's outputs: paths checked before the work starts, files written atomically."""
import json
import os

import pytest

from validation import bench


def _no_run(*args, **kwargs):
    raise AssertionError("the work started although the output path is bad")


@pytest.mark.parametrize("args, message", [
    (["--json", "/nonexistent-dir/bench.json"], "does not exist"),
    (["--markdown", "/nonexistent-dir/bench.md"], "does not exist"),
    (["--json", "{tmp}"], "existing directory"),
    (["--json", "{tmp}/report.md"], "holds text, not JSON"),
    (["--markdown", "{tmp}/plot.gif"], "holds a GIF image"),
    (["--json", "{tmp}/same", "--markdown", "{tmp}/same"], "same file"),
])
def test_bench_refuses_a_bad_output_path_before_benchmarking(tmp_path, monkeypatch, capsys,
                                                             args, message):
    (tmp_path / "report.md").write_text("# kept\n")
    (tmp_path / "plot.gif").write_bytes(b"GIF89a kept")
    monkeypatch.setattr(bench, "run", _no_run)
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    with pytest.raises(SystemExit) as info:
        bench.main(args)
    assert info.value.code == 2
    assert message in capsys.readouterr().err
    assert (tmp_path / "report.md").read_text() == "# kept\n"
    assert (tmp_path / "plot.gif").read_bytes() == b"GIF89a kept"


def test_bench_writes_json_and_markdown_atomically(tmp_path, monkeypatch):
    fake = {"machine": {}, "quick": True}
    monkeypatch.setattr(bench, "run", lambda quick, sections: fake)
    monkeypatch.setattr(bench, "format_report", lambda r: "report")
    monkeypatch.setattr(bench, "format_markdown", lambda r, c: "# Performance\n")
    old = os.umask(0o022)
    try:
        assert bench.main(["--json", str(tmp_path / "b.json"),
                           "--markdown", str(tmp_path / "b.md")]) == 0
    finally:
        os.umask(old)
    assert json.loads((tmp_path / "b.json").read_text()) == fake
    assert (tmp_path / "b.md").read_text() == "# Performance\n"
    for name in ("b.json", "b.md"):
        assert (tmp_path / name).stat().st_mode & 0o777 == 0o644
    assert sorted(os.listdir(tmp_path)) == ["b.json", "b.md"]

    # a failure while producing the Markdown keeps the previous file whole
    def boom(r, c):
        raise RuntimeError("formatting failed")

    monkeypatch.setattr(bench, "format_markdown", boom)
    with pytest.raises(RuntimeError):
        bench.main(["--markdown", str(tmp_path / "b.md")])
    assert (tmp_path / "b.md").read_text() == "# Performance\n"
    assert sorted(os.listdir(tmp_path)) == ["b.json", "b.md"]


# -- the report ---------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def report(optional):
    """validation.report, imported plainly (an ImportError of our own code is a failure), once
    the matplotlib of its extra is there."""
    optional("matplotlib")
    from validation import report

    return report


@pytest.mark.parametrize("setup, message", [
    (lambda d: (d / "out").write_text("a file"), "not a directory"),
    (lambda d: (d / "out").mkdir() or (d / "out" / "report.md").mkdir(), "existing directory"),
    (lambda d: (d / "out").mkdir() or (d / "out" / "results.json").write_bytes(b"GIF89a"),
     "holds a GIF image"),
    (lambda d: (d / "out").mkdir() or (d / "out" / "energy_drift.png").write_text("notes"),
     "holds text, not a PNG"),
])
def test_report_refuses_a_bad_output_directory_before_running(tmp_path, monkeypatch, capsys,
                                                              setup, message, report):
    setup(tmp_path)
    monkeypatch.setattr(report, "collect", _no_run)
    with pytest.raises(SystemExit) as info:
        report.main(["--out", str(tmp_path / "out"), "--no-progress"])
    assert info.value.code == 2
    assert message in capsys.readouterr().err


def test_report_missing_parent_fails_before_running(monkeypatch, capsys, report):
    monkeypatch.setattr(report, "collect", _no_run)
    with pytest.raises(SystemExit):
        report.main(["--out", "/proc/version/sub", "--no-progress"])
    assert "not a directory" in capsys.readouterr().err


def test_report_files_are_written_atomically(tmp_path, monkeypatch, report):
    out = tmp_path / "out"
    out.mkdir()
    (out / "report.md").write_text("previous report")

    def boom(res, level, figs):
        raise RuntimeError("markdown failed")

    monkeypatch.setattr(report, "markdown", boom)
    res = {"meta": {}, "timings": {}}
    with pytest.raises(RuntimeError, match="markdown failed"):
        report.write(str(out), res, report.LEVELS["smoke"])
    assert (out / "report.md").read_text() == "previous report"
    assert sorted(os.listdir(out)) == ["report.md", "results.json"]
    assert json.loads((out / "results.json").read_text()) == res


def test_plots_are_written_atomically(tmp_path, optional):
    plt = optional("matplotlib.pyplot")
    from validation import plots

    path = tmp_path / "plot.png"
    path.write_bytes(b"\x89PNG\r\n\x1a\nold")
    fig = plt.figure()

    def failing_savefig(f, **kwargs):
        f.write(b"\x89PNG partial")
        raise RuntimeError("renderer failed")

    fig.savefig = failing_savefig
    with pytest.raises(RuntimeError, match="renderer failed"):
        plots._save(fig, str(path))
    assert path.read_bytes() == b"\x89PNG\r\n\x1a\nold"
    assert os.listdir(tmp_path) == ["plot.png"]
    fig = plt.figure()
    plots._save(fig, str(path))
    assert path.read_bytes().startswith(b"\x89PNG\r\n\x1a\n") and len(path.read_bytes()) > 100
