"""Files written to attack the organizer's process that reads them (tests/spacewar/
test_hostile_files.py plays each). A stranger controls every byte of a policy file, a replay
or a league's results: each writer below makes one such file, small on disk, that would make
a careless reader allocate gigabytes, block for ever, or feed out-of-range numbers to the
compiled game.

The catalogue is grouped by the kind of file; each group maps an attack's name to a function
``write(path) -> path`` that writes the file at ``path`` (a ``pathlib.Path``). Add new kinds
(league results, cluster copies) as new groups with their own writers."""
import io
import json
import os
import struct
import zlib

import numpy as np

MIB = 1 << 20

# -- zip archives written byte by byte (so that sizes and methods can lie) ------------------
ZIP_STORED, ZIP_DEFLATED, ZIP_LZMA = 0, 8, 14


class Member:
    """One archive member as it is stored: ``data`` already compressed by ``method``;
    ``crc`` and ``size`` are what the archive declares for the uncompressed bytes."""

    def __init__(self, name, data, method, crc, size):
        self.name, self.data, self.method, self.crc, self.size = name, data, method, crc, size


def write_zip(path, members):
    """A plain (not Zip64) archive of ``members``, exactly as declared; returns ``path``."""
    out, central = io.BytesIO(), io.BytesIO()
    for m in members:
        name = m.name.encode()
        offset = out.tell()
        fields = (20, 0, m.method, 0, 0, m.crc, len(m.data), m.size, len(name), 0)
        out.write(struct.pack("<IHHHHHIIIHH", 0x04034B50, *fields) + name + m.data)
        central.write(struct.pack("<IHHHHHHIIIHHHHHII", 0x02014B50, 20, *fields, 0, 0, 0, 0,
                                  offset) + name)
    start, directory = out.tell(), central.getvalue()
    out.write(directory)
    out.write(struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, len(members), len(members),
                          len(directory), start, 0))
    path.write_bytes(out.getvalue())
    return path


def deflated(prefix, zeros):
    """A member's body of ``prefix`` then ``zeros`` zero bytes, deflated without ever
    holding the zeros: after a full flush the compressor starts afresh, so every MiB of
    zeros compresses to the same bytes, which are repeated. Returns (data, crc, size)."""
    block = bytes(MIB)
    compressor = zlib.compressobj(9, zlib.DEFLATED, -15)
    head = compressor.compress(prefix) + compressor.flush(zlib.Z_FULL_FLUSH)
    body = compressor.compress(block) + compressor.flush(zlib.Z_FULL_FLUSH)
    assert zeros % MIB == 0
    crc = zlib.crc32(prefix)
    for _ in range(zeros // MIB):
        crc = zlib.crc32(block, crc)
    tail = compressor.flush()
    return head + body * (zeros // MIB) + tail, crc, len(prefix) + zeros


def npy_header(descr, shape, version=1):
    """A ``.npy`` magic and header declaring ``descr`` and ``shape`` (no data)."""
    buffer = io.BytesIO()
    header = {"descr": descr, "fortran_order": False, "shape": shape}
    writer = np.lib.format.write_array_header_1_0 if version == 1 else \
        np.lib.format.write_array_header_2_0
    writer(buffer, header)
    return buffer.getvalue()


# -- policy files ---------------------------------------------------------------------------
def wide_text_policy(path):
    """The red team's 2 MiB file: ``metadata`` as 8192 texts of 65536 wide characters
    (256 KiB each: 2 GiB of zeros) passes a count of *elements* and inflates 1000:1."""
    count = 8192
    data, crc, size = deflated(npy_header("<U65536", (count,)), count * 65536 * 4)
    return write_zip(path, [Member("metadata.npy", data, ZIP_DEFLATED, crc, size)])


def huge_npy_header_policy(path):
    """A version-2 ``.npy`` header that declares 4 GiB of header, fed by 2 GiB of zeros:
    NumPy reads the whole header before it checks its length."""
    prefix = b"\x93NUMPY\x02\x00" + struct.pack("<I", 0xFFFFFF00)
    data, crc, size = deflated(prefix, 2048 * MIB)
    return write_zip(path, [Member("w0.npy", data, ZIP_DEFLATED, crc, size)])


def ratio_policy(path):
    """A legal-looking weight matrix (16 Mi float32 zeros, 64 MiB) that inflates 1000:1."""
    data, crc, size = deflated(npy_header("<f4", (1 << 24,)), 64 * MIB)
    return write_zip(path, [Member("w0.npy", data, ZIP_DEFLATED, crc, size)])


def wide_integers_policy(path):
    """``inputs`` of 16 Mi int64 (128 MiB): within a count of numbers, twice a byte budget."""
    data, crc, size = deflated(npy_header("<i8", (1 << 24,)), 128 * MIB)
    return write_zip(path, [Member("inputs.npy", data, ZIP_DEFLATED, crc, size)])


def lying_size_policy(path):
    """A member that declares 1 KiB uncompressed and inflates to 64 MiB."""
    data, crc, _ = deflated(npy_header("<f4", (256,)), 64 * MIB)
    return write_zip(path, [Member("w0.npy", data, ZIP_DEFLATED, crc, 1024)])


def lzma_dictionary_policy(path):
    """An LZMA member whose properties ask for a 4 GiB dictionary, allocated by the
    decompressor before the first byte comes out."""
    props = b"\x09\x14\x05\x00" + bytes([0x5D]) + struct.pack("<I", 0xFFFFFFFF)
    data = props + bytes(64)
    return write_zip(path, [Member("w0.npy", data, ZIP_LZMA, 0, 1 << 20)])


def scalar_text_array_policy(path):
    """``format`` as an array of three texts instead of one (a text member must be 0-d)."""
    value = np.array(["spacewar-policy"] * 3)
    buffer = io.BytesIO()
    np.save(buffer, value)
    data = buffer.getvalue()
    return write_zip(path, [Member("format.npy", data, ZIP_STORED, zlib.crc32(data), len(data))])


def long_npy_header_policy(path):
    """A version-2 ``.npy`` header of 1 MiB (stored, so every size the archive declares is
    honest): a policy's header is under 1 KiB."""
    body = b"\x93NUMPY\x02\x00" + struct.pack("<I", MIB) + b" " * MIB
    return write_zip(path, [Member("w0.npy", body, ZIP_STORED, zlib.crc32(body), len(body))])


def directory_flood_policy(path, entries=1_000_000):
    """One small member listed a million times in the central directory (52 MiB): a zip
    reader makes an object for each entry before any name is checked."""
    body = npy_header("<f4", (1,)) + bytes(4)
    name = b"w0.npy"
    fields = (20, 0, ZIP_STORED, 0, 0, zlib.crc32(body), len(body), len(body), len(name), 0)
    local = struct.pack("<IHHHHHIIIHH", 0x04034B50, *fields) + name + body
    entry = struct.pack("<IHHHHHHIIIHHHHHII", 0x02014B50, 20, *fields, 0, 0, 0, 0, 0) + name
    end = struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, 0xFFFF, 0xFFFF, len(entry) * entries,
                      len(local), 0)
    with open(path, "wb") as f:
        f.write(local)
        f.write(entry * entries)
        f.write(end)
    return path


def bzip2_policy(path):
    """A bzip2 member: zipfile inflates a bzip2 chunk whole, however large it comes out."""
    import bz2

    data = npy_header("<f4", (256,)) + bytes(1024)
    return write_zip(path, [Member("w0.npy", bz2.compress(data), 12, zlib.crc32(data),
                                   len(data))])


def policy_parts(rules=None, hidden=16, seed=0):
    """``(arrays, metadata)`` of a legal two-layer policy under ``rules`` (default: the
    1962 rules) with ``hidden`` units, small random weights."""
    from spacewar.learn.batch import learning_layout, learning_length
    from spacewar.policy import ACTION_FORMAT, FORMAT_VERSION, NVEC, default_inputs, \
        layout_sha256
    from spacewar.rules import Rules

    rules = Rules() if rules is None else rules
    inputs = default_inputs(rules)
    rng = np.random.default_rng(seed)
    arrays = {"inputs": inputs,
              "w0": (0.01 * rng.standard_normal((inputs.size, hidden))).astype(np.float32),
              "b0": np.zeros(hidden, np.float32),
              "w1": (0.01 * rng.standard_normal((hidden, sum(NVEC)))).astype(np.float32),
              "b1": np.zeros(sum(NVEC), np.float32)}
    metadata = {"observation_length": learning_length(rules), "rules": rules.to_dict(),
                "rounds": 3, "layout_sha256": layout_sha256(learning_layout(rules)),
                "action_format": ACTION_FORMAT, "nvec": list(NVEC), "activation": "tanh",
                "layers": 2, "frame_skip": 1, "format_version": FORMAT_VERSION,
                "training": {"by": "tests/spacewar/hostile_files.py"}}
    return arrays, metadata


def largest_legal_policy(path):
    """A legal policy whose arrays fill the byte budget (``MAX_ARRAY_BYTES``) to within one
    hidden unit: the most memory an honest file can make ``Policy.load`` use."""
    from spacewar.policy import MAX_ARRAY_BYTES, save_policy

    arrays, metadata = policy_parts(hidden=1)
    fixed = 8 * arrays["inputs"].size + 4 * len("spacewar-policy") + 8 + 4 * 9 \
        + 4 * len(json.dumps(metadata, sort_keys=True))
    hidden = (MAX_ARRAY_BYTES - fixed) // (4 * (arrays["inputs"].size + 1 + 9))
    arrays, metadata = policy_parts(hidden=hidden)
    save_policy(path, arrays, metadata)
    return path


def out_of_range_rules_policy(path):
    """A policy whose metadata's rules carry ``thrust = 1e308`` (written by np.savez, past
    ``save_policy``'s own check)."""
    from spacewar.policy import FORMAT, FORMAT_VERSION

    arrays, metadata = policy_parts()
    metadata["rules"]["thrust"] = 1e308
    with open(path, "wb") as f:
        np.savez(f, format=np.array(FORMAT), format_version=np.array(FORMAT_VERSION, np.int64),
                 metadata=np.array(json.dumps(metadata, sort_keys=True)), **arrays)
    return path


POLICY_BOMBS = {
    "wide_text": wide_text_policy,
    "huge_npy_header": huge_npy_header_policy,
    "ratio_1000": ratio_policy,
    "wide_integers": wide_integers_policy,
    "lying_size": lying_size_policy,
    "lzma_dictionary": lzma_dictionary_policy,
    "text_array": scalar_text_array_policy,
    "long_npy_header": long_npy_header_policy,
    "directory_flood": directory_flood_policy,
    "bzip2": bzip2_policy,
}


# -- replays --------------------------------------------------------------------------------
def fifo_replay(path):
    """A named pipe: ``open()`` blocks until a writer comes, which never does."""
    os.mkfifo(path)
    return path


def oversized_replay(path, size=65 * MIB):
    """A sparse file larger than any replay (no disk used)."""
    with open(path, "wb") as f:
        f.truncate(size)
    return path


def forged_rules_replay(path, replay, **rules):
    """``replay`` (a replay dict) with ``rules`` changed in its rules and its result's rules,
    its content digest recomputed (as a forger who knows the format would)."""
    from spacewar.replay import DIGEST_FIELD, digest

    data = json.loads(json.dumps(replay))
    data["rules"].update(rules)
    data["result"]["rules"].update(rules)
    data.pop(DIGEST_FIELD, None)
    data[DIGEST_FIELD] = digest(data)
    path.write_text(json.dumps(data))
    return path


def int64_wrap_replay(path, replay):
    """Rules whose round length does not fit in int64: ``max_round_frames = 2**63``."""
    return forged_rules_replay(path, replay, max_round_frames=2 ** 63)


def huge_thrust_replay(path, replay):
    """Rules whose thrust overflows the first frame's velocity: ``thrust = 1e308``."""
    return forged_rules_replay(path, replay, thrust=1e308)


REPLAY_FILES = {"fifo": fifo_replay, "oversized": oversized_replay}
FORGED_REPLAYS = {"int64_wrap": int64_wrap_replay, "huge_thrust": huge_thrust_replay}

__all__ = ["Member", "write_zip", "deflated", "npy_header", "POLICY_BOMBS", "REPLAY_FILES",
           "FORGED_REPLAYS", "forged_rules_replay"]
