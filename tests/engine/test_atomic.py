"""Output files are written atomically with the usual permissions, to paths checked first."""
import json
import os

import pytest

import engine
from engine.atomic import OutputPathError, atomic_write, check_output_dir, check_output_path


@pytest.fixture
def umask_027():
    old = os.umask(0o027)
    try:
        yield 0o027
    finally:
        os.umask(old)


def test_exported_from_engine():
    assert engine.atomic_write is atomic_write and engine.check_output_path is check_output_path
    assert issubclass(engine.OutputPathError, ValueError)


@pytest.mark.parametrize("data, mode", [("text ü\n", "w"), (b"\x00\x01bytes", "wb"),
                                        (lambda f: f.write("by a writer"), "w")])
def test_writes_the_content(tmp_path, data, mode):
    path = tmp_path / "out.dat"
    assert atomic_write(path, data, mode) == str(path)
    got = path.read_bytes()
    if callable(data):
        assert got == b"by a writer"
    else:
        assert got == (data.encode("utf-8") if isinstance(data, str) else data)
    assert os.listdir(tmp_path) == ["out.dat"]


def test_new_file_gets_0666_minus_umask_not_0600(tmp_path, umask_027):
    path = tmp_path / "new.json"
    atomic_write(path, "{}")
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask_027 == 0o640
    old = os.umask(0)
    try:
        atomic_write(path, "{}")
        assert path.stat().st_mode & 0o777 == 0o666
    finally:
        os.umask(old)


@pytest.mark.parametrize("mode", ["w", "wb"])
def test_failure_mid_write_keeps_the_old_file_and_leaves_no_temp(tmp_path, mode):
    path = tmp_path / "results.json"
    path.write_text("old content")

    def writer(f):
        f.write("half of the new" if mode == "w" else b"half of the new")
        f.flush()
        raise RuntimeError("disk on fire")

    with pytest.raises(RuntimeError, match="disk on fire"):
        atomic_write(path, writer, mode)
    assert path.read_text() == "old content"
    assert os.listdir(tmp_path) == ["results.json"]


def test_interrupt_mid_write_keeps_the_old_file(tmp_path):
    path = tmp_path / "plot.png"
    path.write_bytes(b"old")

    def writer(f):
        f.write(b"partial")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        atomic_write(path, writer, "wb")
    assert path.read_bytes() == b"old" and os.listdir(tmp_path) == ["plot.png"]


def test_failing_fsync_or_replace_keeps_the_old_file(tmp_path, monkeypatch):
    path = tmp_path / "report.md"
    path.write_text("old")
    real_replace = os.replace

    def broken_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match="No space"):
        atomic_write(path, "new")
    monkeypatch.setattr(os, "replace", real_replace)
    assert path.read_text() == "old" and os.listdir(tmp_path) == ["report.md"]


def test_wrong_data_type_is_refused_before_writing(tmp_path):
    with pytest.raises(TypeError, match="str"):
        atomic_write(tmp_path / "x", b"bytes", "w")
    with pytest.raises(ValueError, match="mode"):
        atomic_write(tmp_path / "x", "text", "a")
    assert os.listdir(tmp_path) == []


# -- check_output_path --------------------------------------------------------------------------
def test_good_paths_pass(tmp_path):
    assert check_output_path(tmp_path / "new.gif", "gif") == str(tmp_path / "new.gif")
    (tmp_path / "old.gif").write_bytes(b"GIF89a....")
    check_output_path(tmp_path / "old.gif", "gif")
    (tmp_path / "empty.json").write_bytes(b"")
    check_output_path(tmp_path / "empty.json", "replay")
    (tmp_path / "r.json").write_text(json.dumps({"format": "spacewar-replay", "version": 2}))
    check_output_path(tmp_path / "r.json", "replay")
    (tmp_path / "b.json").write_text('{"a": 1}')
    check_output_path(tmp_path / "b.json", "json")
    (tmp_path / "report.md").write_text("# Report\n[link](x)")
    check_output_path(tmp_path / "report.md", "markdown")
    check_output_path(tmp_path / "anything.bin")  # no kind: any regular file


def test_missing_directory(tmp_path):
    with pytest.raises(OutputPathError, match=r"directory .*nowhere.* does not exist"):
        check_output_path(tmp_path / "nowhere" / "out.json", "json")


def test_path_is_a_directory(tmp_path):
    with pytest.raises(OutputPathError, match="is an existing directory"):
        check_output_path(tmp_path, "json")
    with pytest.raises(OutputPathError, match="names a directory"):
        check_output_path(str(tmp_path / "sub") + os.sep, "json")


def test_parent_is_a_file(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(OutputPathError, match="not a directory"):
        check_output_path(tmp_path / "file" / "out.gif", "gif")


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write anywhere")
def test_directory_not_writable(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        with pytest.raises(OutputPathError, match="not writable"):
            check_output_path(ro / "out.json", "json")
    finally:
        ro.chmod(0o755)


def test_not_writable_is_detected_through_os_access(tmp_path, monkeypatch):
    # the same check as above, also when the tests run as root (who may write anywhere)
    real = os.access
    monkeypatch.setattr(os, "access", lambda p, m: False if os.fspath(p) == str(tmp_path)
                        else real(p, m))
    with pytest.raises(OutputPathError, match="not writable"):
        check_output_path(tmp_path / "out.json", "json")


@pytest.mark.parametrize("existing, kind, holds", [
    (json.dumps({"format": "spacewar-replay", "version": 2, "actions": ""}), "gif", "replay"),
    (json.dumps({"format": "spacewar-replay", "version": 1}), "png", "replay"),
    (b"GIF89a\x01\x00", "replay", "GIF"),
    (b"GIF87a\x01\x00", "json", "GIF"),
    (b"\x89PNG\r\n\x1a\n....", "gif", "PNG"),
    ('{"results": 1}', "markdown", "JSON"),
    ('{"results": 1}', "replay", "JSON"),
    ("# a report", "json", "text"),
    (b"\xff\xfe\x00binary", "markdown", "binary"),
])
def test_existing_file_of_another_kind_is_refused(tmp_path, existing, kind, holds):
    path = tmp_path / "game.json"
    if isinstance(existing, str):
        path.write_text(existing)
    else:
        path.write_bytes(existing)
    before = path.read_bytes()
    with pytest.raises(OutputPathError, match=rf"refusing.*{kind}.*holds.*{holds}"):
        check_output_path(path, kind)
    assert path.read_bytes() == before


def test_existing_read_only_file_is_refused(tmp_path, monkeypatch):
    path = tmp_path / "keep.json"
    path.write_text("{}")
    real = os.access
    monkeypatch.setattr(os, "access", lambda p, m: False if os.fspath(p) == str(path)
                        else real(p, m))
    with pytest.raises(OutputPathError, match="read-only"):
        check_output_path(path, "json")


@pytest.mark.parametrize("bad, error", [(None, TypeError), (3, TypeError), ("", OutputPathError)])
def test_bad_path_values(bad, error):
    with pytest.raises(error):
        check_output_path(bad, "json")


def test_unknown_kind():
    with pytest.raises(ValueError, match="kind"):
        check_output_path("x.out", "mp4")


def test_output_dir(tmp_path):
    assert check_output_dir(tmp_path) == str(tmp_path)
    check_output_dir(tmp_path / "a" / "b" / "c")  # made later with os.makedirs
    (tmp_path / "f").write_text("x")
    with pytest.raises(OutputPathError, match="not a directory"):
        check_output_dir(tmp_path / "f")
    with pytest.raises(OutputPathError, match="not a directory"):
        check_output_dir(tmp_path / "f" / "sub")
