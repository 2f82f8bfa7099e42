"""A bot's budgets: ``Limits`` (every allowance of a seat: per action, the overage bank, start-up,
memory, output, CPU time) and ``TimeBank``, the overage bank an answer's lateness is paid from."""
import dataclasses
import math

MAX_SECONDS = 3600.0  # no budget of a bot's is longer than an hour
#: rounds a batch bot's learning observations are scaled by when the caller does not say
DEFAULT_ROUNDS = 3
MAX_CPU_SECONDS = 1 << 30


@dataclasses.dataclass(frozen=True)
class Limits:
    """What a bot may spend. Times in seconds, sizes in MiB.

    ``budget`` per action; ``overage``: a bank for the whole match that pays for answers over
    the budget until it is spent (as Kaggle's environments do); ``startup``: import,
    construction and ``reset``; ``stop_after``: a bot silent this long past its deadline is
    stopped and forfeits. ``cpu_seconds``: CPU time for the bot's whole process (None: derived
    from the match length); ``output_bytes``: stdout and stderr the bot may write.
    """

    budget: float = 0.05
    overage: float = 1.0
    startup: float = 10.0
    stop_after: float = 2.0
    memory_mb: int = 1024
    cpu_seconds: int = None
    scratch_mb: int = 64
    file_mb: int = 1
    max_files: int = 64
    output_bytes: int = 1 << 16

    def __post_init__(self):
        for name in ("budget", "overage", "startup", "stop_after"):
            value = getattr(self, name)
            low = "0 <=" if name == "overage" else "0 <"
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not math.isfinite(value) or value < 0 or (value == 0 and name != "overage") \
                    or value > MAX_SECONDS:
                raise ValueError(f"{name} must be a number of seconds with {low} {name} <= "
                                 f"{MAX_SECONDS}, got {value!r}")
        for name, high in (("memory_mb", 1 << 20), ("scratch_mb", 1 << 14), ("file_mb", 1 << 14),
                           ("max_files", 1 << 16), ("output_bytes", 1 << 30)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= high:
                raise ValueError(f"{name} must be an int in [1, {high}], got {value!r}")
        if self.cpu_seconds is not None and (isinstance(self.cpu_seconds, bool) or not isinstance(
                self.cpu_seconds, int) or not 1 <= self.cpu_seconds <= MAX_CPU_SECONDS):
            raise ValueError(f"cpu_seconds must be None or an int in [1, {MAX_CPU_SECONDS}], "
                             f"got {self.cpu_seconds!r}")


class TimeBank:
    """The overage bank: time over the budget is paid from it while it lasts."""

    def __init__(self, limits):
        self.budget, self.left = limits.budget, limits.overage

    def allowance(self):
        return self.budget + self.left

    def charge(self, elapsed):
        """Pay for an answer that took ``elapsed`` s; False if it came too late."""
        over = elapsed - self.budget
        if over <= 0:
            return True
        if over <= self.left:
            self.left -= over
            return True
        self.left = 0.0
        return False

    def late(self, elapsed):
        return (f"answered after {elapsed * 1e3:.1f} ms (budget {self.budget * 1e3:.1f} ms, "
                "overage bank spent)")
