"""Hostile policy files: refused quickly, with the field named, before their data is read;
never a hang on a FIFO, never unbounded memory."""
import io
import os
import resource
import threading
import zipfile

import numpy as np
import pytest

from spacewar.bots.batch import checked_codes
from spacewar.policy import Policy, PolicyError


def _archive(path, members, compression=zipfile.ZIP_STORED):
    with zipfile.ZipFile(path, "w", compression=compression) as z:
        for name, data in members.items():
            z.writestr(name, data)
    return str(path)


def _npy(value):
    buffer = io.BytesIO()
    np.save(buffer, value)
    return buffer.getvalue()


def _header_only(dtype, shape):
    buffer = io.BytesIO()
    np.lib.format.write_array_header_1_0(buffer, {"descr": dtype, "fortran_order": False,
                                                  "shape": shape})
    return buffer.getvalue()


def _load_within(path, seconds=20):
    """Policy.load(path) in a thread: the error it raised, or a failure if it hangs."""
    out = {}

    def run():
        try:
            Policy.load(path)
        except BaseException as exc:  # noqa: BLE001 - what it raised is the answer
            out["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(seconds)
    assert not thread.is_alive(), f"Policy.load({path!r}) hung"
    return out.get("error")


def test_a_fifo_or_a_device_is_refused_without_blocking(tmp_path):
    fifo = str(tmp_path / "fifo.npz")
    os.mkfifo(fifo)
    error = _load_within(fifo)
    assert isinstance(error, PolicyError) and "not a regular file" in str(error)
    error = _load_within("/dev/zero")
    assert isinstance(error, PolicyError) and "not a regular file" in str(error)


@pytest.mark.parametrize("members, message", [
    # 16 elements of 64 MiB raw bytes each: a few KB compressed, gigabytes if read
    ({"w0.npy": _header_only("|V67108864", (16,)) + bytes(1 << 20)}, "'w0' must be float32"),
    ({"junk.npy": _npy(np.zeros(1 << 16))}, "unexpected member 'junk.npy'"),
    ({"metadata.npy": _header_only("<U268435456", ())}, "'metadata' must be a text of at most"),
    ({"w0.npy": _header_only("<f4", (1 << 13, 1 << 13))}, "over the"),
    ({"w0.npy": _npy(np.zeros(4, np.float32))[:-8]}, "declares .* bytes|cannot be read"),
])
def test_bombs_are_refused_from_their_headers(tmp_path, members, message):
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    path = _archive(tmp_path / "bomb.npz", members)
    error = _load_within(path)
    assert isinstance(error, PolicyError), error
    assert __import__("re").search(message, str(error)), str(error)
    grown_mib = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024
    assert grown_mib < 200


def test_an_unreadable_member_is_a_policy_error(tmp_path):
    path = tmp_path / "corrupt.npz"
    weights = np.random.default_rng(0).random(1000).astype(np.float32)
    _archive(path, {"w0.npy": _npy(weights)}, zipfile.ZIP_DEFLATED)
    data = bytearray(path.read_bytes())
    start = 30 + len(b"w0.npy")  # the member's compressed stream, after its local header
    data[start + 40:start + 60] = bytes(20)
    path.write_bytes(bytes(data))
    assert isinstance(_load_within(str(path)), PolicyError)


class _Sneaky(np.ndarray):
    """An int64 array whose own methods would end the process."""

    def astype(self, *args, **kwargs):
        raise SystemExit("astype")

    def __getitem__(self, item):
        raise SystemExit("getitem")


def test_an_array_subclass_answer_is_copied_before_it_is_read():
    answer = np.array([1, 2, 3], dtype=np.int64).view(_Sneaky)
    codes = checked_codes(answer, 3)
    assert type(codes) is np.ndarray and codes.tolist() == [1, 2, 3]


def test_the_match_command_refuses_a_bad_policy_file_at_once(tmp_path, capsys):
    from spacewar.cli import main

    path = _archive(tmp_path / "bad.npz", {"junk.npy": _npy(np.zeros(3))})
    assert main(["match", "--p1", path, "--p2", "idle", "--rounds", "1"]) == 2
    assert "unexpected member 'junk.npy'" in capsys.readouterr().err
