"""The hostile files of tests/spacewar/hostile_files.py, each played against the organizer's
reader: refused with a clear error naming the field (never a traceback, never a hang), within
a stated memory bound. Every load of a bomb runs in a child process under an address-space
limit (RLIMIT_AS), so that a regression fails the test instead of taking the machine down;
the child reports its peak resident memory (VmHWM) above what it held before the load."""
import json
import math
import os
import subprocess
import sys

import pytest

from spacewar import replay
from spacewar.policy import LOAD_MEMORY_BOUND, MAX_ARRAY_BYTES, Policy, PolicyError
from spacewar.rules import FRAMES_MAX, RANGES, Rules
from tests.spacewar import hostile_files

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MIB = 1 << 20
#: address space a child may add to what it holds after its imports (numba maps ~470 MiB)
CHILD_LIMIT = 512 * MIB
#: a child that blocks is a failure, not a hang of the suite
CHILD_TIMEOUT = 120

# The child: imports first (a policy's validation imports numba), then the limit, then the
# load. It prints what the loader raised, whether a MemoryError was behind it, and its peak.
_LOAD_CHILD = r"""
import functools, importlib, json, resource, sys
path, extra, loader, *preload = sys.argv[1:]
for name in preload:
    importlib.import_module(name)
module, attribute = loader.split(":")
load = functools.reduce(getattr, attribute.split("."), importlib.import_module(module))

def status(key):
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1]) * 1024

limit = status("VmSize") + int(extra)
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
before = status("VmRSS")
report = {"error": None, "message": "", "memory_error": False}
try:
    load(path)
except BaseException as exc:
    chain = [exc, exc.__cause__, exc.__context__]
    report.update(error=type(exc).__name__, message=str(exc),
                  memory_error=any(isinstance(e, MemoryError) for e in chain))
report["growth"] = status("VmHWM") - before
print(json.dumps(report))
"""


def load_in_child(path, loader="spacewar.policy:Policy.load", preload=("spacewar.learn.batch",)):
    """What ``loader(path)`` did in a child under ``CHILD_LIMIT`` (``preload``: modules
    imported before the limit): a dict with the exception's name (``error``, None if it
    loaded), its ``message``, whether a MemoryError was behind it and the peak resident
    memory ``growth`` in bytes over the load."""
    done = subprocess.run([sys.executable, "-c", _LOAD_CHILD, str(path), str(CHILD_LIMIT),
                           loader, *preload],
                          capture_output=True, text=True, timeout=CHILD_TIMEOUT, cwd=ROOT)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout)


# -- policy files -------------------------------------------------------------------------
POLICY_REFUSALS = {
    "wide_text": r"declare 2147483776 bytes or more uncompressed, over the 67108864",
    "huge_npy_header": r"declare 2147483660 bytes or more uncompressed, over the 67108864",
    "ratio_1000": r"field 'w0' declares 67108992 bytes stored in \d+, over the 100:1",
    "wide_integers": r"declare 134217856 bytes or more uncompressed, over the 67108864",
    "lying_size": r"Bad CRC-32 for file 'w0.npy'",
    "lzma_dictionary": r"field 'w0' is compressed with zip method 14",
    "bzip2": r"field 'w0' is compressed with zip method 12",
    "text_array": r"field 'format' must be a text of at most 65536 characters .* shape \(3,\)",
    "long_npy_header": r"field 'w0' has a .npy header of 1048576 bytes, over the 4096",
    "directory_flood": r"the archive may list 1000000 members; a policy has at most 64",
}


def test_every_policy_bomb_has_its_expected_refusal():
    assert set(POLICY_REFUSALS) == set(hostile_files.POLICY_BOMBS)


@pytest.mark.parametrize("name", sorted(hostile_files.POLICY_BOMBS))
def test_a_policy_bomb_is_refused_from_its_declared_sizes(tmp_path, name):
    """Refused naming the field and the bound, by the checks made before inflating (not by
    running out of memory), with no more memory than the file itself and a few MiB."""
    import re

    path = hostile_files.POLICY_BOMBS[name](tmp_path / f"{name}.npz")
    report = load_in_child(path)
    assert report["error"] == "PolicyError", report
    assert re.search(POLICY_REFUSALS[name], report["message"]), report["message"]
    assert not report["memory_error"], report
    assert report["growth"] <= os.path.getsize(path) + 16 * MIB, report


def test_the_largest_legal_policy_loads_within_the_stated_bound(tmp_path):
    """An honest policy filling the 64 MiB byte budget loads, within LOAD_MEMORY_BOUND."""
    script = ("import pathlib, sys; from tests.spacewar.hostile_files import "
              "largest_legal_policy; largest_legal_policy(pathlib.Path(sys.argv[1]))")
    path = tmp_path / "largest.npz"
    subprocess.run([sys.executable, "-c", script, str(path)], check=True, cwd=ROOT,
                   timeout=CHILD_TIMEOUT)
    assert os.path.getsize(path) > MAX_ARRAY_BYTES - MIB
    report = load_in_child(path)
    assert report["error"] is None, report
    assert report["growth"] <= LOAD_MEMORY_BOUND, report


def test_a_policy_whose_rules_are_out_of_range_is_refused(tmp_path):
    path = hostile_files.out_of_range_rules_policy(tmp_path / "thrust.npz")
    with pytest.raises(PolicyError, match=r"'rules' is not valid rules: thrust must be in "
                                          r"\[0.0, 1.0\], got 1e\+308"):
        Policy.load(str(path))


# -- replays ------------------------------------------------------------------------------
def spacewar_command(*args, limit=CHILD_LIMIT):
    """``python -m spacewar ARGS`` in a child under an address-space limit and a timeout."""
    script = ("import resource, runpy, sys\n"
              "limit = int(sys.argv.pop(1))\n"
              "resource.setrlimit(resource.RLIMIT_AS, (limit, limit))\n"
              "sys.argv[0] = 'spacewar'\n"
              "runpy.run_module('spacewar', run_name='__main__')\n")
    # numba alone maps ~470 MiB: the limit is on top of a generous 1 GiB for the imports
    return subprocess.run([sys.executable, "-c", script, str(limit + 1024 * MIB), *args],
                          capture_output=True, text=True, timeout=CHILD_TIMEOUT, cwd=ROOT)


def test_a_fifo_replay_is_refused_at_once_without_blocking(tmp_path):
    fifo = hostile_files.fifo_replay(tmp_path / "game.json")
    done = spacewar_command("replay", str(fifo), "--check")
    assert done.returncode == 2, done.stderr[-2000:]
    assert "not a regular file" in done.stderr and "Traceback" not in done.stderr


def test_a_device_or_an_oversized_replay_is_refused_before_it_is_read(tmp_path):
    with pytest.raises(replay.ReplayError, match="not a regular file"):
        replay.load("/dev/zero")
    big = hostile_files.oversized_replay(tmp_path / "big.json")
    with pytest.raises(replay.ReplayError, match=f"has {65 * MIB} bytes, over the "
                                                 f"{replay.MAX_FILE_BYTES} a replay may have"):
        replay.load(str(big))


def test_a_replay_of_many_tiny_json_values_is_refused_before_it_is_parsed(tmp_path):
    """60 MiB of '[],' inside a replay's JSON parse into 21 million lists (measured: +1.5 GiB
    resident before the structure bound); it is refused by counting, with the memory of the
    file's bytes alone."""
    path = tmp_path / "lists.json"
    count = 60 * MIB // 3
    with open(path, "wb") as f:
        f.write(b'{"format": "spacewar-replay", "actions": [' + b"[]," * (count - 1) + b"[]]}")
    report = load_in_child(path, "spacewar.replay:load", preload=())
    assert report["error"] == "ReplayError" and not report["memory_error"], report
    assert f"could hold {2 * count + 2} JSON values, over the {replay.MAX_JSON_VALUES}" in \
        report["message"]
    assert report["growth"] <= 60 * MIB + 16 * MIB, report  # the bytes read, not a parse


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """A short match's replay (built-in bots, in this process)."""
    from spacewar.arena.match import play_match

    _, rep, _ = play_match("idle", "random", seed=2, rounds=1, record=True)
    path = tmp_path_factory.mktemp("replay") / "game.json"
    replay.save(path, rep)
    return replay.load(path)


def test_a_gif_size_beyond_the_bound_is_refused_before_any_work(tmp_path, recorded):
    from spacewar.render import MAX_SIZE, render_gif

    path = tmp_path / "game.json"
    replay.save(path, recorded)
    done = spacewar_command("replay", str(path), "--gif", str(tmp_path / "out.gif"),
                            "--size", "1000000")
    assert done.returncode == 2, done.stderr[-2000:]
    assert f"must be in [64, {MAX_SIZE}], got 1000000" in done.stderr
    assert "bytes a pixel" in done.stderr and "Traceback" not in done.stderr
    with pytest.raises(ValueError, match=r"size must be an int in \[64, 4096\]"):
        render_gif(recorded, tmp_path / "out.gif", size=MAX_SIZE + 1)
    assert not (tmp_path / "out.gif").exists()


@pytest.mark.parametrize("name, message", [
    ("int64_wrap", r"max_round_frames must be in \[0, 1073741824\], got 9223372036854775808"),
    ("huge_thrust", r"thrust must be in \[0.0, 1.0\], got 1e\+308"),
])
def test_a_replay_with_rules_out_of_range_is_refused(tmp_path, recorded, name, message):
    path = hostile_files.FORGED_REPLAYS[name](tmp_path / f"{name}.json", recorded)
    with pytest.raises(replay.ReplayError, match=message):
        replay.load(str(path))
    done = spacewar_command("replay", str(path), "--check")
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr[-2000:]
    assert "rules are invalid" in done.stderr


# -- the rules' ranges ----------------------------------------------------------------------
def _companions(name, value):
    """Other fields, each within its range, that ``value`` needs to be judged by its own
    range alone (fuel_burn_max >= fuel_burn_min)."""
    def within(other, wanted):
        low, high = RANGES[other]
        return min(max(wanted, low), high)

    if name == "fuel_burn_min":
        return {"fuel_burn_max": within("fuel_burn_max", max(value, Rules().fuel_burn_max))}
    if name == "fuel_burn_max":
        return {"fuel_burn_min": within("fuel_burn_min", min(value, Rules().fuel_burn_min))}
    return {}


def _past(value, direction):
    """The next value beyond a bound: an int's neighbour, a float's next float."""
    if isinstance(value, int):
        return value + direction
    return math.nextafter(value, direction * math.inf)


@pytest.mark.parametrize("name", sorted(RANGES))
def test_every_rules_field_is_accepted_at_its_bounds_and_refused_just_past(name):
    low, high = RANGES[name]
    for value in (low, high):
        assert getattr(Rules(**{name: value, **_companions(name, value)}), name) == value
    for value in (_past(low, -1), _past(high, +1)):
        with pytest.raises(ValueError, match=rf"^{name} must be in \[.*\], got "):
            Rules(**{name: value, **_companions(name, value)})


@pytest.mark.parametrize("value", [math.inf, math.nan, 10 ** 400, "1.0", True])
def test_a_rules_number_that_is_not_a_finite_number_is_a_value_error(value):
    with pytest.raises(ValueError, match="^thrust must be"):
        Rules(thrust=value)


def test_frame_counts_fit_in_int64_for_any_replays_rounds():
    """The largest match a replay can ask for: rounds < 2^31 plus every extra round, each as
    long as the rules allow, counts fewer than 2^63 frames."""
    rounds = replay.MAX_ROUNDS + RANGES["max_extra_rounds"][1]
    assert rounds * (2 * FRAMES_MAX + 1) < 2 ** 63
