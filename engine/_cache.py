"""Where numba keeps this project's compiled code, so that it is never stale.

numba's on-disk cache (``cache=True``) is keyed on the source file of each function only: a
kernel inlined into a caller from another module (every force kernel is, in the dispatcher)
would keep its old machine code after an edit or an upgrade. So the project's compiled code
lives in a directory named after a hash of all the project's sources: any change to any source
file selects a fresh directory. Only functions defined by this project's modules use it:
numba's setting is switched while they are imported and restored afterwards.
"""
import contextlib
import hashlib
import os
import shutil
import time
from pathlib import Path

_ROOT = Path(__file__).resolve().parent.parent
_PACKAGES = ("engine", "spacewar", "validation")


def _source_hash():
    digest = hashlib.sha1()
    for package in _PACKAGES:
        for path in sorted((_ROOT / package).rglob("*.py")):
            digest.update(str(path.relative_to(_ROOT)).encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


KEEP = 6  # compiled-code directories kept (for the sources seen most recently) ...
MIN_AGE = 24 * 3600  # ... and none younger than a day is removed (a long run may be using it)


def cache_dir():
    """The directory of this project's compiled code for the current sources."""
    base = os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
        "nbody-spacewar")
    return os.path.join(base, "numba-" + _source_hash())


def prune(current):
    """Remove all but the most recently used compiled-code directories beside ``current``."""
    parent = os.path.dirname(current)
    try:
        entries = [os.path.join(parent, d) for d in os.listdir(parent) if d.startswith("numba-")]
        entries.sort(key=os.path.getmtime, reverse=True)
    except OSError:
        return
    now = time.time()
    for old in entries[KEEP:]:
        try:
            stale = now - os.path.getmtime(old) > MIN_AGE
        except OSError:
            continue
        if old != current and stale:
            shutil.rmtree(old, ignore_errors=True)


@contextlib.contextmanager
def project_cache():
    """Import the project's compiled modules inside this block."""
    from numba.core import config

    previous = config.CACHE_DIR
    current = cache_dir()
    if os.path.isdir(current):
        try:
            os.utime(current)  # mark it recently used, so pruning keeps it
        except OSError:
            pass  # a cache we may read but not touch (a bot's sandbox): use it as it is
    else:
        prune(current)
    config.CACHE_DIR = current
    try:
        yield
    finally:
        config.CACHE_DIR = previous
