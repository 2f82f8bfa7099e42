"""The repository cites original sources, never files outside it.

The reference notes the project was started from are not part of the repository, so a path to
them means nothing to a reader of a checkout: code and documentation cite the original sources
(the lecture, the 1962 Spacewar! program, the published papers) instead.
"""
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
SUFFIXES = (".py", ".md", ".toml")
# Spelled in pieces so that this file does not match itself.
FORBIDDEN = ("shared" + "/reference", ".." + "/shared")


def _repository_files():
    """Tracked files, plus new ones not yet committed (but not the ignored ones)."""
    try:
        out = subprocess.run(
            ["git", "-C", str(ROOT), "ls-files", "-z", "--cached", "--others",
             "--exclude-standard"],
            check=True, capture_output=True, timeout=60,
        ).stdout
    except (OSError, subprocess.SubprocessError):
        pytest.skip("not a git checkout: the repository's file list is unknown")
    names = [name for name in out.decode("utf-8", "surrogateescape").split("\0") if name]
    return [ROOT / name for name in names if name.endswith(SUFFIXES) and (ROOT / name).is_file()]


def test_no_file_cites_paths_outside_the_repository():
    files = _repository_files()
    assert files, "no .py/.md/.toml file found"
    hits = []
    for path in files:
        text = path.read_text(encoding="utf-8", errors="replace")
        for number, line in enumerate(text.splitlines(), 1):
            if any(word in line for word in FORBIDDEN):
                hits.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert not hits, "cite the original source instead of a file outside the repository:\n" + \
        "\n".join(hits)


def test_nothing_refers_to_the_project_s_issue_numbers():
    """A reader of the code, the docs or the program's output has no access to the tracker the
    work was planned in: say what a thing is, not which ticket asked for it."""
    import re

    # spelled in pieces so that this file does not match itself
    pattern = re.compile(r"\bissues?" + r"\s*#?\d+", re.IGNORECASE)
    hits = []
    for path in _repository_files():
        text = path.read_text(encoding="utf-8", errors="replace")
        for number, line in enumerate(text.splitlines(), 1):
            if pattern.search(line):
                hits.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert not hits, "internal references:\n" + "\n".join(hits)
