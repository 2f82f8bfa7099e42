"""A seat for a bot at a match's table: ``open_seat`` picks it (a built-in bot or the caller's bot
object called here, ``InlineSeat``; any other bot in its own confined process,
``spacewar.sandbox.process``), and ``bot_name`` names the bot in results. What a seat
promises, whichever it is, is in ``spacewar.sandbox.process``'s text: an action code or a
fault, every wait with a deadline."""
import array
import time


from spacewar import codes, wire
from spacewar.bots.ask import ask
from spacewar.bots.batch import is_batch_bot, one_match_bot
from spacewar.bots import BotLoadError, is_builtin, locate, make_bot
from spacewar.faults import KIND_BY_STATUS
from spacewar.protocol import observation_of_copy
from spacewar.sandbox.limits import DEFAULT_ROUNDS, Limits, TimeBank
from spacewar.sandbox.process import ProcessSeat

class InlineSeat:
    """A built-in bot, or a bot object the caller made in its own process, called directly
    here (trusted code, fast). Its faults, ``SystemExit`` and ``KeyboardInterrupt`` included,
    cost it its turn; it sees a read-only observation and its own copy of the rules."""

    def __init__(self, spec, seed, limits, rules, bot=None, rounds=None):
        if bot is None and not is_builtin(spec):
            raise ValueError(f"inline seats are for built-in bots only, got {spec!r}: "
                             "other bots run in their own process")
        self.spec = spec
        self.act_seconds = array.array("d")  # each action's time (see the module's text)
        self._rules = type(rules).from_dict(rules.to_dict())  # decodes; the bot never sees it
        self.rules = type(rules).from_dict(rules.to_dict())  # the bot may break only its own copy
        self.bank = TimeBank(limits)
        self.dead = None
        self.layers = ["in this process (built-in bot or the caller's bot object)"]
        try:
            self.bot = make_bot(spec, seed=seed) if bot is None else bot
        except BotLoadError as exc:  # a policy file that is not a valid policy
            self.bot, self.dead = None, ("startup", str(exc))
            return
        self.bot = one_match_bot(self.bot, self._rules,
                                 DEFAULT_ROUNDS if rounds is None else rounds)
        try:
            reset = getattr(self.bot, "reset", None)
            if callable(reset):
                reset()
        except BaseException as exc:  # SystemExit from a bot object's reset is its fault
            self.dead = ("startup", wire.exception_text(exc))

    def wait_ready(self):
        """None when the bot is ready, else its start-up fault (it starts in the constructor)."""
        return self.dead

    def act(self, raw):
        """``(code, fault)``: fault is None or ``(kind, message)``. ``raw`` is the match's
        (a float64 array of ``raw_length``); the bot gets its own copy."""
        obs = observation_of_copy(raw.copy(), self._rules, self.rules)
        start = time.perf_counter()
        status, code, text = ask(self.bot, obs)
        elapsed = time.perf_counter() - start
        self.act_seconds.append(elapsed)
        if status in (wire.RAISED, wire.MEMORY):  # no answer at all: its time is not charged
            return codes.NOOP, (KIND_BY_STATUS[status], text)
        if not self.bank.charge(elapsed):
            return codes.NOOP, ("timeout", self.bank.late(elapsed))
        if status == wire.INVALID:
            return codes.NOOP, ("invalid", text)
        return code, None

    def close(self):
        return {"text": "", "bytes": 0, "truncated": False}


def bot_name(spec):
    """The name a bot goes by in results: its specification, or for a bot object its class."""
    if isinstance(spec, str):
        return spec
    cls = type(spec)
    return f"{cls.__module__}.{cls.__qualname__}"


def open_seat(spec, seed, limits=None, rules=None, isolation="auto", cpu_seconds=None,
              rounds=None):
    """A seat for bot ``spec``: built-in bots inline (``auto``), every other bot named by a
    string in its own confined process. ``isolation="process"`` puts built-in bots in a process
    too; ``inline`` is refused for a named bot that is not built in. A bot *object* (anything
    with ``act``, or a batch bot with ``act_batch``: ``spacewar.bots.batch``) is the caller's
    own code and plays inline. ``rounds``: the match's, which a batch bot's learning
    observations are scaled by."""
    from spacewar.rules import Rules

    if isolation not in ("auto", "inline", "process"):
        raise ValueError(f"isolation must be auto, inline or process, got {isolation!r}")
    limits = Limits() if limits is None else limits
    if isinstance(limits, (int, float)):
        limits = Limits(budget=limits)  # the old call shape: a budget in seconds
    rules = Rules() if rules is None else rules
    if not isinstance(spec, str) and (callable(getattr(spec, "act", None)) or is_batch_bot(spec)):
        return InlineSeat(bot_name(spec), seed, limits, rules, bot=spec, rounds=rounds)
    if not is_builtin(spec):
        locate(spec)  # a bad specification is an error here, before any process starts
    if is_builtin(spec) and isolation != "process":
        return InlineSeat(spec, seed, limits, rules, rounds=rounds)
    if isolation == "inline":
        raise ValueError(f"inline isolation is for built-in bots only, got {spec!r}")
    return ProcessSeat(spec, seed, limits, rules, cpu_seconds=cpu_seconds, rounds=rounds)
