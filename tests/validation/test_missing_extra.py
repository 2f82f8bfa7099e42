"""Without the [validation] extra, the commands that need it say which extra to install."""
import sys

import pytest

from validation.__main__ import main


@pytest.mark.parametrize("command, absent", [("report", "matplotlib"), ("report", "rebound"),
                                             ("bench", "rebound")])
def test_a_command_without_its_extra_names_the_extra(command, absent, monkeypatch, capsys,
                                                     tmp_path):
    monkeypatch.setitem(sys.modules, absent, None)  # import of it now raises ImportError
    out = tmp_path / "report"
    args = [command, "--quick"] + (["--out", str(out)] if command == "report" else [])
    assert main(args) == 2
    err = capsys.readouterr().err
    assert absent in err and "[validation]" in err and "pip install" in err
    assert not out.exists()


def test_help_needs_no_extra(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "rebound", None)
    with pytest.raises(SystemExit) as exit_:
        main(["bench", "--help"])
    assert exit_.value.code == 0 and "--only" in capsys.readouterr().out


def test_bench_sections_without_rebound_need_no_extra(monkeypatch):
    from validation.__main__ import missing_modules

    monkeypatch.setitem(sys.modules, "rebound", None)
    assert missing_modules("bench", ["--quick", "--only", "spacewar,batch"]) == []
    assert missing_modules("bench", ["--only=learning"]) == []
    assert missing_modules("bench", ["--only", "spacewar,planets"]) == ["rebound"]
    assert missing_modules("bench", ["--quick"]) == ["rebound"]


def test_the_bench_needs_what_its_sections_declare(monkeypatch):
    from validation.__main__ import NEEDS, bench_needs, missing_modules

    assert bench_needs() == NEEDS["bench"]
    monkeypatch.setitem(sys.modules, "rebound", None)
    # the contact section's gas runs in REBOUND too; the tree's skips a code that is missing
    assert missing_modules("bench", ["--only", "contact"]) == ["rebound"]
    assert missing_modules("bench", ["--only", "tree"]) == []
