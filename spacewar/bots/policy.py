"""Trained policies as ``.npz`` files: saving, safe loading, and NumPy inference (no JAX).

    from spacewar.policy import Policy, PolicyBot
    policy = Policy.load("policy.npz")             # validated; never unpickles anything
    codes = policy.act_batch(obs)                  # (K, D) float32 -> (K,) int64 action codes
    bot = PolicyBot("policy.npz")                  # a bot: bot.act(observation) -> Action

A policy file is a NumPy ``.npz`` archive written by ``spacewar.learn.train`` (``save_policy``): it
holds only numeric arrays and two texts, read here without NumPy's loader or pickle, so
loading one runs no code from it. Its fields:

- ``format`` (the text ``"spacewar-policy"``), ``format_version`` (int64, now 1);
- ``metadata``: a JSON object: ``observation_length`` (D), ``rules`` (``Rules.to_dict()``),
  ``rounds`` (the match length it was trained at), ``layout_sha256`` (of the learning layout's
  names), ``action_format`` (``"MultiDiscrete[3,2,2,2]"``), ``nvec`` ([3, 2, 2, 2]),
  ``activation`` (``"tanh"`` or ``"relu"``), ``layers`` (how many weight matrices),
  ``frame_skip`` (frames each decision is held for) and ``training`` (how it was made);
- ``inputs``: int64 indices of the learning observation entries the network reads (the
  entries scaled by the match's number of rounds are left out: a bot is not told that number);
- ``w0, b0, ..., w{L-1}, b{L-1}``: float32 weights and biases of the MLP
  ``h_{i+1} = act(h_i W_i + b_i)``, the last layer linear: 9 logits, the four categorical
  factors (turn 3, thrust 2, fire 2, hyperspace 2) side by side.

Every array is checked for its dtype, shape and finiteness before use; a bad file raises
``PolicyError`` naming the field.

A policy file comes from a stranger (a league loads every ``.npz`` in its submissions folder),
so it is bounded by bytes before anything in it is inflated or parsed: the file is a regular
file of at most ``MAX_FILE_BYTES`` (65 MiB: the largest legal policy stored uncompressed); its
members are stored or deflated (what NumPy writes), each declaring at most 100 times its
stored size once over 1 MiB, and together at most ``MAX_ARRAY_BYTES`` (64 MiB) uncompressed;
each member's ``.npy`` magic and header length are read first and a header over
``MAX_HEADER_BYTES`` (4 KiB) refused unread; its type and shape then give its bytes
(item size times count, the two texts 0-d and of at most ``MAX_TEXT`` characters), checked
against what is left of the 64 MiB before its data is read, a chunk at a time, and decoded
from the bytes read (``np.frombuffer``). So ``Policy.load`` adds at most
``LOAD_MEMORY_BOUND`` (about 161 MiB: the file, the arrays, the finiteness check's booleans
and a few MiB of buffers) to its process, whatever the file.
"""
import hashlib
import io
import json
import math
import os
import re
import zipfile

import numpy as np

from spacewar.codes import codes_from_parts
from spacewar.strangers_files import FileRefused, read_bounded

FORMAT = "spacewar-policy"
FORMAT_VERSION = 1
NVEC = (3, 2, 2, 2)
ACTION_FORMAT = "MultiDiscrete[3,2,2,2]"
ACTIVATIONS = ("tanh", "relu")
#: the learning observation entries a policy never reads (they are scaled by the match's
#: number of rounds, which ``Observation`` does not carry)
ROUND_SCALED = ("rounds_fraction", "score_difference")
MAX_ELEMENTS = 1 << 26  # no policy array is larger than 64 Mi numbers (256 MiB of float32)
MAX_LAYERS = 16
MAX_FRAME_SKIP = 64
_OFFSETS = np.cumsum((0,) + NVEC)  # where each factor's logits start


class PolicyError(ValueError):
    """A policy file that cannot be used (the message names the field and says why)."""


def layout_sha256(names):
    """SHA-256 of a learning layout's names (one per line): ties a policy to its inputs."""
    return hashlib.sha256("\n".join(names).encode()).hexdigest()


def default_inputs(rules):
    """Indices of the learning observation entries a policy reads under ``rules``."""
    from spacewar.game.features import learning_layout

    return np.array([k for k, name in enumerate(learning_layout(rules))
                     if name not in ROUND_SCALED], dtype=np.int64)


#: the learning observation's entries that are x or y components of a vector (positions,
#: velocities, headings' cosine and sine): those a half turn about the star negates
_VECTOR_FIELDS = ("vx", "vy", "cos_heading", "sin_heading", "star_dx", "star_dy", "dx", "dy",
                  "dvx", "dvy")


def seat_signs(rules):
    """+1 or -1 per learning observation entry: seat 1 seen as seat 0.

    The ships start at opposite corners, seat 1's start being seat 0's turned half way about
    the star (``core.ship_start``), and the game is the same under that half turn (the star
    sits at the origin of the torus; a half turn keeps the sense of rotation, so turning left
    stays left). So seat 1's observation with every vector negated is an observation seat 0
    could have had, and a policy trained in seat 0 plays seat 1 from it."""
    from spacewar.game.features import learning_layout

    return np.array([-1.0 if name.rsplit(".", 1)[-1] in _VECTOR_FIELDS else 1.0
                     for name in learning_layout(rules)], dtype=np.float32)


# -- saving ---------------------------------------------------------------------------------
def check_policy_path(path):
    """Raise unless ``path`` can receive a policy file (call it before training): its
    directory must be writable and an existing file there must be an ``.npz`` (zip)."""
    from engine.atomic import OutputPathError, check_output_path

    path = check_output_path(path)
    if os.path.isfile(path) and os.path.getsize(path) > 0:
        with open(path, "rb") as f:
            head = f.read(4)
        if head != b"PK\x03\x04":
            raise OutputPathError(f"refusing to write the policy {path!r}: the file exists and "
                                  "is not an .npz archive; choose another path or remove it")
    return path


def save_policy(path, weights, metadata):
    """Write a policy file atomically (temporary file, then ``os.replace``); return ``path``.

    ``weights`` maps ``w0, b0, ...`` and ``inputs`` to arrays; ``metadata`` is the JSON
    object described in the module's text. The result is loaded back and validated before it
    replaces anything at ``path``, so a policy file that is written can also be read."""
    from engine.atomic import atomic_write

    arrays = {"format": np.array(FORMAT), "format_version": np.array(FORMAT_VERSION, np.int64),
              "metadata": np.array(json.dumps(metadata, sort_keys=True))}
    for name, value in weights.items():
        arrays[name] = np.ascontiguousarray(value)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    data = buffer.getvalue()
    _parse(_read_npz(data, "the policy being saved"), "the policy being saved")
    return atomic_write(path, data, mode="wb")


# -- loading and validation -----------------------------------------------------------------
#: member names a policy archive may hold: the fixed fields and w0, b0 ... w15, b15
_MEMBER = re.compile(r"(format|format_version|metadata|inputs|[wb](?:[0-9]|1[0-5]))\.npy")
#: the exact (little-endian) types of the weights and biases; the other numbers are int64
_FIELD_TYPES = {"w": np.dtype("<f4"), "b": np.dtype("<f4")}
_TEXT_FIELDS = ("format", "metadata")
MAX_ARRAY_BYTES = 1 << 26  # all of a policy's arrays together: 64 MiB (16 Mi float32)
MAX_TEXT = 1 << 16  # characters of the format and metadata texts (each one 0-d text)
MAX_HEADER_BYTES = 4096  # a .npy member's header (NumPy writes < 1 KiB for a policy's)
#: the largest legal policy stored without compression: its arrays, a header each and the
#: archive's own records (36 members at most); a larger file cannot be a policy
MAX_FILE_BYTES = MAX_ARRAY_BYTES + (1 << 20)
#: a member over RATIO_FREE_BYTES may inflate at most MAX_RATIO times its stored size
#: (trained float32 weights barely compress: a larger ratio is a bomb, not a policy)
MAX_RATIO = 100
RATIO_FREE_BYTES = 1 << 20
#: central-directory signatures a file may hold: one per member (36 at most) with room for
#: the chance occurrences of these 4 bytes inside arrays
MAX_DIRECTORY_ENTRIES = 64
#: what NumPy writes (np.savez, np.savez_compressed); bzip2 and LZMA decompressors inflate
#: without an output bound (bzip2) or allocate a dictionary the file names (LZMA)
_METHODS = frozenset((zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED))
_READ_CHUNK = 1 << 20
#: the most memory ``Policy.load`` adds to its process: the file's bytes, the decoded arrays,
#: the finiteness check's booleans (one per float32) and a few MiB of chunks and zlib state
LOAD_MEMORY_BOUND = MAX_FILE_BYTES + MAX_ARRAY_BYTES + MAX_ARRAY_BYTES // 4 + (16 << 20)


def read_policy_bytes(path, where):
    """The bytes of the policy file at ``path``: a regular file (never a FIFO or device,
    which could block or never end), opened without blocking, of at most ``MAX_FILE_BYTES``,
    read from the descriptor that was checked (``strangers_files.read_bounded``)."""
    try:
        return read_bounded(path, MAX_FILE_BYTES)
    except FileRefused as exc:
        raise PolicyError({
            "not regular": f"{where} is not a regular file",
            "too large": f"{where} has {exc.size} bytes, over the {MAX_FILE_BYTES} a policy "
                         "file may have",
            "grew": f"{where} grew past the {MAX_FILE_BYTES} bytes a policy file may have "
                    "while it was read"}[exc.reason]) from None
    except OSError as exc:
        raise PolicyError(f"cannot read {where}: {exc.strerror or exc}") from None


def _read_npz(data, where):
    """Every array of an .npz (``data``: the file's bytes), each member's declared sizes,
    method and ``.npy`` header checked before its data is inflated, the arrays decoded from
    the bytes read; every failure is a ``PolicyError``."""
    try:
        return _read_checked_npz(data, where)
    except PolicyError:
        raise
    except MemoryError:
        raise PolicyError(f"{where} is too large to read") from None
    except zipfile.BadZipFile as exc:
        raise PolicyError(f"{where} is not an .npz archive: {exc}") from None
    except Exception as exc:  # zlib, zipfile: any archive that cannot be read
        raise PolicyError(f"{where} cannot be read as an .npz archive: "
                          f"{type(exc).__name__}: {exc}") from None


def _read_checked_npz(data, where):
    _check_directory_entries(data, where)
    arrays, budget = {}, MAX_ARRAY_BYTES
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        infos = archive.infolist()
        _check_members(infos, where)
        for info in infos:
            field = info.filename[:-4]
            with archive.open(info) as member:
                arrays[field] = _read_member(member, info.file_size, field, budget, where)
            budget -= arrays[field].nbytes
    return arrays


def _check_directory_entries(data, where):
    """Refuse an archive whose central directory could list more than
    ``MAX_DIRECTORY_ENTRIES`` members before ``zipfile`` reads it: it makes an object for each
    entry, and 64 MiB hold a million entries. Each entry starts with its 4-byte signature
    somewhere in the file, so their count bounds the entries."""
    entries = data.count(b"PK\x01\x02")
    if entries > MAX_DIRECTORY_ENTRIES:
        raise PolicyError(f"{where}: the archive may list {entries} members; a policy has at "
                          f"most {MAX_DIRECTORY_ENTRIES}")


def _check_members(infos, where):
    """Names, methods and declared sizes of every member, before any is opened."""
    names = [info.filename for info in infos]
    for name in names:
        if not _MEMBER.fullmatch(name):
            raise PolicyError(f"{where}: unexpected member {name[:100]!r} in the archive")
    if len(set(names)) != len(names):
        raise PolicyError(f"{where}: a member appears twice in the archive")
    declared = 0
    for info in infos:
        field = info.filename[:-4]
        if info.flag_bits & 0x1:
            raise PolicyError(f"{where}: field {field!r} is encrypted")
        if info.compress_type not in _METHODS:
            raise PolicyError(f"{where}: field {field!r} is compressed with zip method "
                              f"{info.compress_type}; a policy's members are stored or "
                              "deflated (as np.savez and np.savez_compressed write them)")
        declared += info.file_size
        if declared > MAX_ARRAY_BYTES + len(infos) * (MAX_HEADER_BYTES + 12):
            raise PolicyError(f"{where}: the members declare {declared} bytes or more "
                              f"uncompressed, over the {MAX_ARRAY_BYTES} a policy's arrays "
                              "may hold")
        if info.file_size > RATIO_FREE_BYTES \
                and info.file_size > MAX_RATIO * max(info.compress_size, 1):
            raise PolicyError(f"{where}: field {field!r} declares {info.file_size} bytes "
                              f"stored in {info.compress_size}, over the {MAX_RATIO}:1 a "
                              "policy's arrays compress to")


def _read_member(member, declared, field, budget, where):
    """The array of one ``.npy`` member: its magic and header length read and checked, then
    its header (at most ``MAX_HEADER_BYTES``), its type, shape and byte count (at most
    ``budget``), and only then its data, decoded from the bytes read."""
    magic = _read_exactly(member, 8, field, where)
    if magic[:6] != b"\x93NUMPY" or magic[6:] not in (b"\x01\x00", b"\x02\x00"):
        raise PolicyError(f"{where}: field {field!r} is not a NumPy .npy array of version 1 "
                          f"or 2 (it starts {magic!r})")
    width = 2 if magic[6] == 1 else 4
    length_field = _read_exactly(member, width, field, where)
    length = int.from_bytes(length_field, "little")
    if length > MAX_HEADER_BYTES:
        raise PolicyError(f"{where}: field {field!r} has a .npy header of {length} bytes, over "
                          f"the {MAX_HEADER_BYTES} a policy's array needs")
    header = magic + length_field + _read_exactly(member, length, field, where)
    shape, fortran, dtype = _parse_header(header, magic[6], field, where)
    _check_type(field, dtype, shape, where)
    if any(size < 0 for size in shape):
        raise PolicyError(f"{where}: field {field!r} has a negative size in its shape {shape}")
    nbytes = math.prod(shape) * dtype.itemsize
    if nbytes > budget:
        raise PolicyError(f"{where}: field {field!r} has shape {shape} and type {dtype.str}: "
                          f"{nbytes} bytes, over the {MAX_ARRAY_BYTES} a policy's arrays may "
                          "hold in all")
    if declared != len(header) + nbytes:
        raise PolicyError(f"{where}: field {field!r} declares {declared} bytes where its "
                          f"header says {len(header) + nbytes}")
    data = bytearray(nbytes)
    _read_into(member, memoryview(data), field, where)
    array = np.frombuffer(data, dtype=dtype, count=math.prod(shape))
    return array.reshape(shape, order="F" if fortran else "C")


def _read_exactly(member, count, field, where):
    data = bytearray(count)
    _read_into(member, memoryview(data), field, where)
    return bytes(data)


def _read_into(member, view, field, where):
    """Fill ``view`` from the member, a chunk at a time (the inflater never makes more than
    a chunk at once); refuse a member that ends early."""
    done = 0
    while done < len(view):
        chunk = member.read(min(_READ_CHUNK, len(view) - done))
        if not chunk:
            raise PolicyError(f"{where}: field {field!r} ends after {done} of the "
                              f"{len(view)} bytes its header declares")
        view[done:done + len(chunk)] = chunk
        done += len(chunk)


def _parse_header(header, version, field, where):
    """``(shape, fortran_order, dtype)`` of a bounded ``.npy`` header (NumPy's own parser,
    which evaluates literals only, given the bytes already read and checked)."""
    read = np.lib.format.read_array_header_1_0 if version == 1 else \
        np.lib.format.read_array_header_2_0
    stream = io.BytesIO(header)
    np.lib.format.read_magic(stream)
    try:
        return read(stream, max_header_size=MAX_HEADER_BYTES)
    except (ValueError, SyntaxError, TypeError) as exc:
        raise PolicyError(f"{where}: field {field!r} has no valid .npy header: "
                          f"{str(exc)[:200]}") from None


def _check_type(field, dtype, shape, where):
    """The type and, for the texts, the shape a policy's field must have."""
    if dtype.hasobject:
        raise PolicyError(f"{where}: field {field!r} holds Python objects (pickled data), "
                          "which a policy never does")
    if field in _TEXT_FIELDS:
        if dtype.kind != "U" or dtype.byteorder not in "<=|" or shape != () \
                or not 0 < dtype.itemsize <= 4 * MAX_TEXT:
            raise PolicyError(f"{where}: field {field!r} must be a text of at most {MAX_TEXT} "
                              f"characters (one, a 0-d array), got {dtype.str} of shape {shape}")
        return
    want = _FIELD_TYPES.get(field[0], np.dtype("<i8"))
    if dtype != want:
        raise PolicyError(f"{where}: field {field!r} must be {want.name}, got {dtype.str}")


def _field(arrays, name, where):
    if name not in arrays:
        raise PolicyError(f"{where}: missing field {name!r}")
    return arrays[name]


def _text(arrays, name, where):
    value = _field(arrays, name, where)
    if value.dtype.kind != "U" or value.shape != ():
        raise PolicyError(f"{where}: field {name!r} must be a text (0-d unicode array), got "
                          f"{value.dtype} of shape {value.shape}")
    return str(value)


def _meta(meta, key, kind, where, check=None, why=""):
    if key not in meta:
        raise PolicyError(f"{where}: metadata field {key!r} is missing")
    value = meta[key]
    if isinstance(value, bool) and kind is not bool or not isinstance(value, kind) \
            or (check is not None and not check(value)):
        raise PolicyError(f"{where}: metadata field {key!r} must be {why or kind.__name__}, "
                          f"got {value!r:.100}")
    return value


def _parse(arrays, where):
    """Validate loaded arrays; return ``(metadata, inputs, layers)`` or raise PolicyError."""
    from spacewar.game.features import learning_layout, learning_length
    from spacewar.rules import Rules

    fmt = _text(arrays, "format", where)
    if fmt != FORMAT:
        raise PolicyError(f"{where}: field 'format' must be {FORMAT!r}, got {fmt!r:.100}")
    version = _field(arrays, "format_version", where)
    if version.dtype != np.int64 or version.shape != ():
        raise PolicyError(f"{where}: field 'format_version' must be a 0-d int64, got "
                          f"{version.dtype} of shape {version.shape}")
    if int(version) != FORMAT_VERSION:
        raise PolicyError(f"{where}: field 'format_version' is {int(version)}; this version "
                          f"of spacewar reads version {FORMAT_VERSION}")
    try:
        meta = json.loads(_text(arrays, "metadata", where))
    except (ValueError, RecursionError) as exc:
        raise PolicyError(f"{where}: field 'metadata' is not valid JSON: {exc}") from None
    if not isinstance(meta, dict):
        raise PolicyError(f"{where}: field 'metadata' must be a JSON object")
    rules_dict = _meta(meta, "rules", dict, where, why="a JSON object of the rules")
    try:
        rules = Rules.from_dict(rules_dict)
    except (TypeError, ValueError, KeyError) as exc:
        raise PolicyError(f"{where}: metadata field 'rules' is not valid rules: {exc}") from None
    d = _meta(meta, "observation_length", int, where, lambda v: v == learning_length(rules),
              f"the learning observation length under its rules ({learning_length(rules)})")
    _meta(meta, "layout_sha256", str, where, lambda v: v == layout_sha256(learning_layout(rules)),
          "the SHA-256 of this version's learning layout (the observation's entries changed "
          "since the policy was trained: train it again)")
    _meta(meta, "rounds", int, where, lambda v: 1 <= v <= 10_000, "an int in [1, 10000]")
    _meta(meta, "action_format", str, where, lambda v: v == ACTION_FORMAT, repr(ACTION_FORMAT))
    _meta(meta, "nvec", list, where, lambda v: v == list(NVEC), str(list(NVEC)))
    _meta(meta, "activation", str, where, lambda v: v in ACTIVATIONS, f"one of {ACTIVATIONS}")
    n_layers = _meta(meta, "layers", int, where, lambda v: 1 <= v <= MAX_LAYERS,
                     f"an int in [1, {MAX_LAYERS}]")
    _meta(meta, "frame_skip", int, where, lambda v: 1 <= v <= MAX_FRAME_SKIP,
          f"an int in [1, {MAX_FRAME_SKIP}]")
    meta["rules_object"] = rules
    inputs = _field(arrays, "inputs", where)
    if inputs.dtype != np.int64 or inputs.ndim != 1 or inputs.size == 0:
        raise PolicyError(f"{where}: field 'inputs' must be a non-empty 1-d int64 array, got "
                          f"{inputs.dtype} of shape {inputs.shape}")
    if inputs.min() < 0 or inputs.max() >= d or np.any(np.diff(inputs) <= 0):
        raise PolicyError(f"{where}: field 'inputs' must be increasing indices in [0, {d})")
    expected = {"format", "format_version", "metadata", "inputs"}
    layers = []
    width = inputs.size
    for i in range(n_layers):
        w, b = _field(arrays, f"w{i}", where), _field(arrays, f"b{i}", where)
        last = i == n_layers - 1
        out = int(sum(NVEC)) if last else (w.shape[1] if w.ndim == 2 else -1)
        for name, value, shape in ((f"w{i}", w, (width, out)), (f"b{i}", b, (out,))):
            if value.dtype != np.float32:
                raise PolicyError(f"{where}: field {name!r} must be float32, got {value.dtype}")
            if value.shape != shape or out < 1:
                raise PolicyError(f"{where}: field {name!r} must have shape {shape}, got "
                                  f"{value.shape}")
            if not np.all(np.isfinite(value)):
                raise PolicyError(f"{where}: field {name!r} holds non-finite numbers")
        layers.append((w, b))
        expected |= {f"w{i}", f"b{i}"}
        width = out
    extra = sorted(set(arrays) - expected)
    if extra:
        raise PolicyError(f"{where}: unexpected fields {extra} (a policy of {n_layers} layers "
                          f"has {sorted(expected)})")
    return meta, inputs, layers


def _activation(name):
    if name == "tanh":
        return np.tanh
    return lambda x: np.maximum(x, 0.0)


class Policy:
    """A loaded, validated policy: NumPy inference of the MLP of the module's text."""

    def __init__(self, metadata, inputs, layers):
        self.metadata = {k: v for k, v in metadata.items() if k != "rules_object"}
        self.rules = metadata["rules_object"]
        self.observation_length = int(metadata["observation_length"])
        self.rounds = int(metadata["rounds"])
        self.frame_skip = int(metadata["frame_skip"])
        self.activation = metadata["activation"]
        self.inputs = inputs
        self.layers = [(np.asarray(w, np.float32), np.asarray(b, np.float32)) for w, b in layers]
        self._act = _activation(self.activation)
        self._seat_signs = seat_signs(self.rules)

    @classmethod
    def load(cls, path):
        """Read and validate a policy file (``np.load(..., allow_pickle=False)``)."""
        where = f"policy file {os.fspath(path)!r}"
        data = read_policy_bytes(path, where)
        return cls(*_parse(_read_npz(data, where), where))

    def logits(self, obs, seat=0):
        """The 9 logits (turn 3, thrust 2, fire 2, hyperspace 2) of each row of ``obs``
        ((K, D) learning observations of ``seat``), float32 (K, 9)."""
        obs = np.asarray(obs)
        if obs.ndim != 2 or obs.shape[1] != self.observation_length:
            raise ValueError(f"obs must have shape (K, {self.observation_length}), got {obs.shape}")
        if seat not in (0, 1):
            raise ValueError(f"seat must be 0 or 1, got {seat!r}")
        if seat == 1:  # trained in seat 0: seat 1's view turned half way (``seat_signs``)
            obs = obs * self._seat_signs
        h = obs[:, self.inputs].astype(np.float32, copy=False)
        with np.errstate(over="ignore", invalid="ignore"):  # huge weights: no warning flood
            for i, (w, b) in enumerate(self.layers):
                h = h @ w + b
                if i < len(self.layers) - 1:
                    h = self._act(h)
        return h

    def act_batch(self, obs, greedy=True, rng=None, seat=0):
        """Game action codes (K,) int64 for learning observations ``obs`` (K, D) float32.

        Greedy (each factor's most likely choice) by default; ``greedy=False`` samples each
        factor from its softmax with ``rng`` (a ``numpy.random.Generator``; required, so that
        sampling is always seeded). ``seat=1``: the observations are seat 1's (the policy
        was trained in seat 0; see ``seat_signs``)."""
        obs = np.asarray(obs)
        if obs.dtype != np.float32:
            raise ValueError(f"obs must be float32 learning observations, got {obs.dtype}")
        z = self.logits(obs, seat)
        parts = np.empty((z.shape[0], len(NVEC)), dtype=np.int64)
        if not greedy and not isinstance(rng, np.random.Generator):
            raise ValueError("sampling (greedy=False) needs rng, a numpy.random.Generator")
        for f in range(len(NVEC)):
            zf = z[:, _OFFSETS[f]:_OFFSETS[f + 1]]
            if greedy:
                parts[:, f] = np.argmax(zf, axis=1)
            else:
                p = np.exp(zf - zf.max(axis=1, keepdims=True))
                c = np.cumsum(p / p.sum(axis=1, keepdims=True), axis=1)
                u = rng.random((zf.shape[0], 1))
                parts[:, f] = np.minimum((u > c).sum(axis=1), zf.shape[1] - 1)
        return codes_from_parts(parts)


class PolicyBot:
    """A bot playing a policy file: ``act(obs)`` for the game's ``Observation``.

    It rebuilds the learning observation from the raw numbers the observation carries
    (``spacewar.game.features.learning_vector``), decides every ``frame_skip`` frames (the policy
    was trained holding each decision that long) and holds the action in between. The
    observation does not say how many rounds the match has, so the entries scaled by it are
    computed with the training value and are not read by the network anyway. ``greedy=False``
    samples actions from a generator seeded by ``seed``. In seat 1 it sees the game turned
    half way about the star, as seat 0 (``seat_signs``). A match under other rules than the
    policy's is refused (``strict_rules=False`` plays it when the observation length fits)."""

    def __init__(self, policy, seed=None, greedy=True, strict_rules=True):
        self.policy = policy if isinstance(policy, Policy) else Policy.load(policy)
        self.greedy = bool(greedy)
        self.seed = seed
        self.strict_rules = strict_rules
        self.reset()

    def reset(self):
        self._rng = np.random.default_rng(self.seed)
        self._held = None
        self._left = 0
        self._checked = False

    def _check_rules(self, rules):
        check_rules(self.policy, rules, self.strict_rules)
        self._checked = True

    def act(self, obs):
        from spacewar.game.features import learning_vector
        from spacewar.protocol import Action

        if not self._checked:
            self._check_rules(obs.rules)
        if self._left == 0:
            raw = object.__getattribute__(obs, "_raw")
            if raw is None:
                raise ValueError("the observation carries no raw numbers to compute a learning "
                                 "observation from")
            x = learning_vector(raw, obs.rules, self.policy.rounds)[None]
            self._held = Action.from_code(int(self.policy.act_batch(
                x, greedy=self.greedy, rng=self._rng, seat=1 if obs.seat == 1 else 0)[0]))
            self._left = self.policy.frame_skip
        self._left -= 1
        return self._held


def check_rules(policy, rules, strict=True):
    """Raise ValueError naming the fields unless ``policy`` may play under ``rules``: the
    rules it was trained under (or, not ``strict``, any with the same observation length)."""
    mine, theirs = policy.rules.to_dict(), rules.to_dict()
    if mine != theirs:
        diff = {k: (mine.get(k), theirs.get(k)) for k in sorted(set(mine) | set(theirs))
                if mine.get(k) != theirs.get(k)}
        from spacewar.game.features import learning_length

        if strict or learning_length(rules) != policy.observation_length:
            raise ValueError(f"the policy was trained under other rules (field: "
                             f"(policy's, match's) = {diff})")


class PolicyBatch:
    """A policy as a batch bot (``spacewar.bots.batch``) for rows whose seats are known: each
    row decides every ``frame_skip`` frames and holds its action in between, seat 1's rows
    seen turned half way (``seat_signs``), greedily: row by row what ``PolicyBot`` plays in
    that row's match, however many rows are decided together. ``restart(mask)``: those rows'
    matches start again (their next call decides). Under other rules than the policy's every
    call raises, as ``PolicyBot.act`` does."""

    def __init__(self, policy, rules, seats, strict_rules=True):
        self.policy = policy if isinstance(policy, Policy) else Policy.load(policy)
        self.rules = rules
        self.seats = np.asarray(seats, dtype=np.int64)
        if self.seats.ndim != 1 or not np.isin(self.seats, (0, 1)).all():
            raise ValueError(f"seats must be a list of 0 and 1, got {seats!r}")
        self.strict_rules = strict_rules
        self._held = np.zeros(len(self.seats), dtype=np.int64)
        self._left = np.zeros(len(self.seats), dtype=np.int64)

    def reset(self):
        self._left[:] = 0

    def restart(self, mask):
        self._left[np.asarray(mask, dtype=bool)] = 0

    def act_batch(self, obs):
        check_rules(self.policy, self.rules, self.strict_rules)
        due = self._left == 0
        for seat in (0, 1):
            rows = np.flatnonzero(due & (self.seats == seat))
            if rows.size:
                self._held[rows] = self.policy.act_batch(obs[rows], seat=seat)
        self._left[due] = self.policy.frame_skip
        self._left -= 1
        return self._held.copy()


def load_policy(path):
    """``Policy.load(path)``: a validated policy file (the vector env's ``.npz`` opponents)."""
    return Policy.load(path)


__all__ = ["Policy", "PolicyBot", "PolicyBatch", "check_rules", "PolicyError", "load_policy", "save_policy", "check_policy_path",
           "default_inputs", "layout_sha256", "codes_from_parts", "seat_signs", "FORMAT", "FORMAT_VERSION",
           "NVEC"]
