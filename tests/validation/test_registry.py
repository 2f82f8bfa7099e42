"""The report's and the bench's sections are declared once, each in its own module, and
everything else is built from the declarations: a section added to a registry shows up in the
run, the files, the Markdown and the text without another edit."""
import types

import pytest

from validation import bench
from validation.bench import registry as bench_registry

REPORT_DECLARES = ("NAME", "CONTENTS", "PHASE", "FIGURES", "jobs", "gather", "plots",
                   "markdown", "glance")
BENCH_DECLARES = ("NAME", "KEYS", "NEEDS", "run", "text", "markdown", "targets")


@pytest.fixture(scope="module")
def report(optional):
    optional("matplotlib")
    from validation import report

    return report


def test_every_report_section_declares_the_whole_interface(report):
    from validation.report import registry

    assert report.SECTIONS == registry.SECTIONS == tuple(m.NAME for m in registry.MODULES)
    for module in registry.MODULES:
        assert module.__name__ == f"validation.report.{module.NAME}"
        missing = [name for name in REPORT_DECLARES if not hasattr(module, name)]
        assert not missing, f"{module.__name__} does not declare {missing}"
        assert module.PHASE in registry.PHASES
        assert all(name.endswith(".png") for name in module.FIGURES.values())
    files = [name for module in registry.MODULES for name in module.FIGURES.values()]
    assert len(files) == len(set(files))
    assert list(report.output_files()) == ["report.md", "results.json"] + files


def test_every_bench_section_declares_the_whole_interface():
    modules = bench_registry.MODULES
    for module in modules:
        missing = [name for name in BENCH_DECLARES if not hasattr(module, name)]
        assert not missing, f"{module.__name__} does not declare {missing}"
    assert bench.SECTIONS == tuple(m.NAME for m in modules)
    assert len(set(bench.SECTIONS)) == len(modules)
    keys = [key for module in modules for key in module.KEYS]
    assert len(keys) == len(set(keys)) and not {"machine", "quick"} & set(keys)
    for name, before in bench_registry.TARGETS_BEFORE.items():
        assert {name, before} <= set(bench.SECTIONS)


def _fake_report_section():
    def plots(sec, level, out_dir):
        (out_dir / "fake.png").write_bytes(b"\x89PNG\r\n\x1a\n" + b"0" * 100)
        return {"figure": "fake.png"}

    return types.SimpleNamespace(
        NAME="fake", CONTENTS="8. A fake section", PHASE="untimed",
        FIGURES={"figure": "fake.png"},
        jobs=lambda level: [], gather=lambda level, results, progress: {"answer": 42},
        plots=plots,
        markdown=lambda sec, level, figs: f"## 8. Fake: {sec['answer']} ({figs['figure']})\n",
        glance=lambda sec, level: ([f"- **Fake**: {sec['answer']}"], ["fake table", ""]))


def test_a_report_section_added_to_the_registry_is_written(report, tmp_path, monkeypatch):
    from validation.report import registry

    fake = _fake_report_section()
    monkeypatch.setattr(registry, "MODULES", registry.MODULES + (fake,))
    assert "fake.png" in report.output_files(("fake",))
    res = {"meta": {"level": "smoke", "engine_version": "0", "rebound_version": "0",
                    "numpy_version": "0", "numba_version": "0", "python_version": "3",
                    "machine": "x", "cpu_count": 1, "workers": 1, "scheduler": None},
           "fake": fake.gather(None, {}, False), "timings": {"wall_s": 1.0}}
    report.write(tmp_path, res, report.LEVELS["smoke"])
    md = (tmp_path / "report.md").read_text()
    assert "; 8. A fake section." in md
    assert "## At a glance\n\n- **Fake**: 42\n\nfake table\n" in md
    assert "## 8. Fake: 42 (fake.png)\n" in md
    assert (tmp_path / "fake.png").exists()


def test_a_bench_section_added_to_the_registry_is_run_and_shown(monkeypatch):
    fake = types.SimpleNamespace(
        NAME="fake", KEYS=("fake",), NEEDS=(),
        run=lambda quick: {"fake": {"quick": quick}},
        text=lambda r: ["\n13. fake", f"quick {r['fake']['quick']}"],
        markdown=lambda r: ["## 13. Fake", ""],
        targets=lambda r: [("fake target", "measured", True)])
    monkeypatch.setattr(bench_registry, "MODULES", bench_registry.MODULES + (fake,))
    r = bench.run(quick=True, sections=["fake"])
    assert set(r) == {"machine", "quick", "fake"} and r["fake"] == {"quick": True}
    assert bench.targets(r) == [("fake target", "measured", True)]
    text = bench.format_report(r)
    assert text.endswith("\n13. fake\nquick True\n\ntargets:\n  met  fake target: measured")
    md = bench.format_markdown(r, "python -m validation bench --only fake")
    assert "| fake target | measured | met |" in md and md.endswith("## 13. Fake\n")


def test_the_targets_keep_their_order():
    """The targets table lists the sections in their order, but the learning code's before
    the single match's (section 8's rows before section 6's), as it always has."""
    r = {"machine": {}, "spacewar": {"one_match_confined_bots": {"over_inline": 0.6},
                                     "confined_bot_ready_seconds": {"idle": 0.1}},
         "learning": {"matches": 8, "threads": {"1": {"match_frames_per_second": 1.0}},
                      "harness": {"harness_seconds_per_frame": 1e-6}},
         "terms": {"relative_to_gravity_alone": {"a": 1.0, "b": 1.2}}}
    names = [name for name, _, _ in bench.targets(r)]
    assert names[0] == "step cost follows the declared terms"
    assert names[1].startswith("one match of two idle Python bots")
    assert names[2].startswith("one match, both bots confined")
    assert names[3].startswith("a confined idle")
