"""What a bot did wrong, in one vocabulary for every place a match is judged: the kinds of
fault, the code a replay stores for each, a seat's fault log, and how a bot's text is shown.

Kinds (``FAULT_KINDS``, in code order: code k = 1 + the kind's index, 0 = none):

- ``raised``: ``act`` raised; ``invalid``: not a valid action, or a broken wire protocol;
- ``timeout``: no answer in time, or over its CPU time; ``crashed``: its process died;
- ``startup``: loading, constructing or resetting it failed or took too long;
- ``memory``: it ran out of its memory limit.

Pure Python (no numba, no engine): a bot's own process may load it.
"""
from spacewar import wire

FAULT_KINDS = ("raised", "invalid", "timeout", "crashed", "startup", "memory")

#: the fault kind of a bot process's answer status, for the statuses that are faults
KIND_BY_STATUS = {wire.RAISED: "raised", wire.INVALID: "invalid", wire.MEMORY: "memory"}

#: characters of a fault message kept in a result
MAX_MESSAGE = 300

#: messages a fault log keeps as examples (the first ones), besides the last
EXAMPLES = 5


def fault_code(kind):
    """The code a replay stores for a fault of ``kind``: 1 + its index in ``FAULT_KINDS``."""
    return 1 + FAULT_KINDS.index(kind)


def printable(text):
    """``text`` with every control character (terminal escapes, newlines) shown escaped, so a
    bot's message cannot redraw the terminal it is printed on."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


class FaultLog:
    """Counts of each kind of fault of one seat, the first few messages and the last one."""

    def __init__(self):
        self.counts = {kind: 0 for kind in FAULT_KINDS}
        self.examples = []
        self.last = None
        self.total = 0

    def add(self, frame, kind, message):
        """Record a fault of ``kind`` at ``frame``; its message kept escaped and cut short."""
        self.counts[kind] += 1
        self.total += 1
        self.last = {"frame": int(frame), "kind": kind,
                     "message": printable(str(message))[:MAX_MESSAGE]}
        if len(self.examples) < EXAMPLES:
            self.examples.append(self.last)

    def to_dict(self):
        return {"total": self.total, **self.counts, "examples": self.examples, "last": self.last}
