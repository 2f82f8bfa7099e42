"""Reading a file that may come from a stranger, bounded before anything is read.

Policy files, replays, league results files and the bot files a cluster run ships are all
read by the organizer's own process, so each is read the same way: opened without blocking (a
FIFO would block ``open`` for ever), checked by ``fstat`` on the descriptor it is then read
from (a device never ends; a path swapped after the check is not read), refused when larger
than its cap, and read no further than the cap, in one read when the file does not grow.
Each caller words the refusal for its own kind of file (``FileRefused.reason``).
"""
import os
import stat


class FileRefused(ValueError):
    """A file not read: ``reason`` is ``"not regular"``, ``"too large"`` (its size said so:
    ``size``) or ``"grew"`` (it grew past the cap while it was read)."""

    def __init__(self, reason, size=None):
        super().__init__(reason)
        self.reason, self.size = reason, size


def read_bounded(path, limit):
    """The bytes of the regular file at ``path``, at most ``limit`` of them; ``FileRefused``
    otherwise, ``OSError`` (``FileNotFoundError`` included) when it cannot be opened or read.
    The bytes are held once: a file read in one piece is returned as that piece."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise FileRefused("not regular")
        if info.st_size > limit:
            raise FileRefused("too large", info.st_size)
        chunks, left, size = [], limit + 1, info.st_size + 1
        while left > 0:
            chunk = os.read(fd, min(left, size))
            size = 1 << 20  # more reads only if it grows meanwhile
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
        if left <= 0:
            raise FileRefused("grew")
        return b"".join(chunks)
    finally:
        os.close(fd)
