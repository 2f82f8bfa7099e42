"""Asking a bot object for its action, whatever it does: the one place a bot's ``act`` is
called, on both sides of the wire (a confined bot's own process, ``spacewar.sandbox.bothost``, and
a built-in bot in the match's process, ``spacewar.arena.seats.InlineSeat``)."""
from spacewar.bots.batch import SingleFromBatch
from spacewar.protocol import action_code, short_repr
from spacewar.wire import INVALID, MEMORY, OK, RAISED, exception_text


def ask(bot, obs):
    """Ask ``bot`` for its action on ``obs``: ``(status, code, text)``, whatever it does.

    Used on both sides of the wire: by a bot's process (``spacewar.sandbox.bothost``) and by the
    match for a bot it calls directly (``spacewar.arena.seats.InlineSeat``). The code comes from the
    answer's fields (``spacewar.protocol.action_code``), never from what its class says.
    """
    if type(bot) is SingleFromBatch:  # a batch bot playing one match: K = 1 (ours, exactly)
        return bot.answer(obs)
    try:
        result = bot.act(obs)
    except MemoryError:
        return MEMORY, 0, "MemoryError in act"
    except BaseException as exc:  # SystemExit and KeyboardInterrupt from a bot are its faults
        return RAISED, 0, exception_text(exc)
    try:
        return OK, action_code(result), ""
    except ValueError as exc:
        return INVALID, 0, f"returned {short_repr(result)}: {exc}"
    except BaseException as exc:
        return INVALID, 0, exception_text(exc)
