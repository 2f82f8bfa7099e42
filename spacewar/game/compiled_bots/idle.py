"""``spacewar.bots.idle.Idle`` compiled: it does nothing, every frame."""
from spacewar.game import core

jit = core.jit


@jit(inline="always")
def idle_code():
    """The idle bot's action code: no turn, no thrust, no fire, no jump (``core.NOOP``)."""
    return core.NOOP
