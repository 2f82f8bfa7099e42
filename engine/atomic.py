"""Writing output files safely: atomically, and to a path checked before the work starts.

``atomic_write(path, data)`` writes to a temporary file in the same directory, flushes and
fsyncs it, then moves it over ``path`` with ``os.replace``: a crash, an exception or an
interrupt mid-write leaves the old file (or no file) at ``path``, never a truncated one, and
removes the temporary file. The new file gets the user's normal permissions,
``0o666 & ~umask`` (the temporary is created with ``os.open(..., 0o666)``, so the kernel applies
the umask; ``tempfile.mkstemp`` would give 0600).

``check_output_path(path, kind)`` is called before a long job (a benchmark, a report, a match
whose replay or GIF is to be written) so that a bad path fails at once instead of after the
work: the directory must exist and be writable, the path must not be a directory, and an
existing file there must be of the ``kind`` about to be written (a GIF written over a JSON
replay is refused). Both live in the engine so the game and the validation suite share them.
"""
import json
import os
import secrets

__all__ = ["atomic_write", "check_output_path", "check_output_dir", "file_kind",
           "OutputPathError", "KINDS"]

#: output kinds ``check_output_path`` knows, and the existing-file kinds each may replace
#: ("empty" files may always be replaced: there is nothing in them to lose)
KINDS = {
    "json": ("json",),
    "replay": ("replay",),
    "gif": ("gif",),
    "png": ("png",),
    "markdown": ("text",),
    "text": ("text",),
    "html": ("html",),
}

_GIF = (b"GIF87a", b"GIF89a")
_PNG = b"\x89PNG\r\n\x1a\n"
_SNIFF_LIMIT = 64 * 1024 * 1024  # files larger than this are classed by their first bytes


class OutputPathError(ValueError):
    """An output path that cannot (or must not) be written; raised before any work is done."""


def _replace_mode(mode):
    if mode not in ("w", "wb"):
        raise ValueError(f"mode must be 'w' (text) or 'wb' (bytes), got {mode!r}")
    return mode


def atomic_write(path, data, mode="w", *, encoding="utf-8"):
    """Write ``data`` to ``path`` atomically; return ``path``.

    ``data`` is a ``str`` (``mode="w"``), ``bytes`` (``mode="wb"``), or a callable taking the
    open temporary file object and writing into it (``writer(f)``), for content produced
    incrementally (a GIF encoder, ``fig.savefig(f, format="png")``). Whatever fails in between
    (the writer raising, a full disk, Ctrl-C) the old file at ``path`` is left untouched and the
    temporary file is removed. The written file has mode ``0o666 & ~umask``.
    """
    mode = _replace_mode(mode)
    path = os.fspath(path)
    if isinstance(path, bytes):
        path = os.fsdecode(path)
    if not callable(data):
        want = str if mode == "w" else (bytes, bytearray, memoryview)
        if not isinstance(data, want):
            raise TypeError(f"atomic_write of {path!r} with mode {mode!r} takes "
                            f"{'str' if mode == 'w' else 'bytes'} or a writer callable, "
                            f"got {type(data).__name__}")
    directory = os.path.dirname(os.path.abspath(path))
    base = os.path.basename(path)[:180]
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0)
    while True:
        tmp = os.path.join(directory, f".{base}.{secrets.token_hex(6)}.tmp")
        try:
            fd = os.open(tmp, flags, 0o666)  # the umask applies: the user's usual file mode
            break
        except FileExistsError:
            continue
    try:
        kwargs = {"encoding": encoding} if mode == "w" else {}
        with os.fdopen(fd, mode, **kwargs) as f:
            if callable(data):
                data(f)
            else:
                f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    _fsync_directory(directory)
    return path


def _fsync_directory(directory):
    """Make the rename durable (best effort: not every platform can open a directory)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def file_kind(path):
    """What an existing file holds: "empty", "gif", "png", "replay", "json", "html", "text",
    "binary".

    Only reads the file; "replay" is a JSON object whose ``format`` is ``"spacewar-replay"``;
    "html" is text that starts (after white space) with ``<!DOCTYPE html`` or ``<html``.
    """
    with open(path, "rb") as f:
        head = f.read(_SNIFF_LIMIT + 1)
    if not head.strip():
        return "empty" if not head else "text"
    if head.startswith(_GIF):
        return "gif"
    if head.startswith(_PNG):
        return "png"
    if len(head) > _SNIFF_LIMIT:
        head = head[:_SNIFF_LIMIT]
        return "text" if _is_text(head[:4096], partial=True) else "binary"
    if not _is_text(head):
        return "binary"
    first = head.lstrip()[:1]
    if first in (b"{", b"["):
        try:
            value = json.loads(head)
        except (ValueError, RecursionError):
            return "text"
        if isinstance(value, dict) and value.get("format") == "spacewar-replay":
            return "replay"
        return "json"
    if head.lstrip()[:14].lower().startswith((b"<!doctype html", b"<html")):
        return "html"
    return "text"


def _is_text(raw, partial=False):
    if b"\x00" in raw:
        return False
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        return partial and exc.start >= len(raw) - 4  # a character cut at the end
    return True


def _writable_dir(directory, what, path):
    if not os.path.exists(directory):
        raise OutputPathError(f"cannot write {what} {path!r}: the directory {directory!r} "
                              "does not exist")
    if not os.path.isdir(directory):
        raise OutputPathError(f"cannot write {what} {path!r}: {directory!r} is not a directory")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise OutputPathError(f"cannot write {what} {path!r}: the directory {directory!r} is "
                              "not writable")


def check_output_path(path, kind=None):
    """Raise OutputPathError unless ``path`` can receive a new file of ``kind``; return it.

    Checked, without writing anything: ``path`` is a str or path-like naming a file (not an
    existing directory, not ending in a separator); its directory exists and is writable; an
    existing file there is writable and, when ``kind`` is given (one of ``KINDS``: "json",
    "replay", "gif", "png", "markdown", "text"), already holds that kind of content or is
    empty, so that e.g. ``spacewar replay game.json --gif game.json`` cannot replace the replay
    with a GIF. Call it before the work whose result will be written.
    """
    if kind is not None and kind not in KINDS:
        raise ValueError(f"kind must be None or one of {', '.join(KINDS)}, got {kind!r}")
    what = f"the {kind} output" if kind else "the output"
    if isinstance(path, bool) or not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"{what} path must be a str or path-like, got {path!r}")
    path = os.fspath(path)
    if isinstance(path, bytes):
        path = os.fsdecode(path)
    if not path:
        raise OutputPathError(f"{what} path is empty")
    if "\x00" in path:
        raise OutputPathError(f"{what} path {path!r} contains a NUL character")
    if os.path.isdir(path):
        raise OutputPathError(f"cannot write {what} {path!r}: it is an existing directory")
    if path.endswith((os.sep, os.altsep or os.sep)):
        raise OutputPathError(f"cannot write {what} {path!r}: the path names a directory, "
                              "not a file")
    directory = os.path.dirname(os.path.abspath(path))
    _writable_dir(directory, what, path)
    if os.path.lexists(path):
        if not os.path.exists(path):
            raise OutputPathError(f"cannot write {what} {path!r}: it is a broken symbolic link")
        if not os.path.isfile(path):
            raise OutputPathError(f"cannot write {what} {path!r}: it exists and is not a "
                                  "regular file")
        if not os.access(path, os.W_OK):
            raise OutputPathError(f"cannot write {what} {path!r}: the existing file is "
                                  "read-only")
        if kind is not None:
            try:
                found = file_kind(path)
            except OSError as exc:
                raise OutputPathError(f"cannot write {what} {path!r}: the existing file "
                                      f"cannot be read ({exc})") from None
            if found != "empty" and found not in KINDS[kind]:
                raise OutputPathError(
                    f"refusing to write {what} {path!r}: the file exists and holds "
                    f"{_DESCRIBE.get(found, found)}, not {_DESCRIBE[KINDS[kind][0]]}; "
                    "choose another path or remove the file first")
    return path


_DESCRIBE = {"gif": "a GIF image", "png": "a PNG image", "replay": "a spacewar replay",
             "json": "JSON", "html": "an HTML page", "text": "text", "binary": "binary data", "empty": "nothing"}


def check_output_dir(path):
    """Raise OutputPathError unless ``path`` is (or can be made as) a writable directory.

    An existing path must be a writable directory; a missing one is created later with
    ``os.makedirs``, so its nearest existing ancestor must be a writable directory.
    """
    if isinstance(path, bool) or not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"the output directory must be a str or path-like, got {path!r}")
    path = os.fspath(path)
    if isinstance(path, bytes):
        path = os.fsdecode(path)
    if not path:
        raise OutputPathError("the output directory path is empty")
    what = "into the output directory"
    if os.path.exists(path):
        if not os.path.isdir(path):
            raise OutputPathError(f"cannot write {what} {path!r}: it exists and is not a "
                                  "directory")
        if not os.access(path, os.W_OK | os.X_OK):
            raise OutputPathError(f"cannot write {what} {path!r}: it is not writable")
        return path
    ancestor = os.path.dirname(os.path.abspath(path))
    while not os.path.exists(ancestor):
        parent = os.path.dirname(ancestor)
        if parent == ancestor:
            break
        ancestor = parent
    if not os.path.isdir(ancestor):
        raise OutputPathError(f"cannot create the output directory {path!r}: {ancestor!r} is "
                              "not a directory")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise OutputPathError(f"cannot create the output directory {path!r}: {ancestor!r} is "
                              "not writable")
    return path
