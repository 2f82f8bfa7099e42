"""``spacewar.bots.random_bot.RandomBot`` compiled."""

from spacewar.game import core
from spacewar.game.compiled_bots.numerics import NUMERIC
from spacewar.game.compiled_bots.geometry import action

jit = core.jit

# -- the reference bots' parameters (their constructors' defaults; a test holds them equal) --
RANDOM_PARAMS = {"thrust": 0.5, "fire": 0.2, "hyperspace": 0.002}


# numba freezes module globals into the machine code: plain floats, read once here
_P_THRUST, _P_FIRE, _P_HYPER = (RANDOM_PARAMS[k] for k in ("thrust", "fire", "hyperspace"))


@jit(**NUMERIC)
def random_code(m, seat, bot_rng):
    """``RandomBot``: turn uniform in {-1, 0, 1} (``int(3 u) - 1``), thrust with p = 0.5, fire
    with p = 0.2, hyperspace with p = 0.002, from four draws of the seat's own stream."""
    row = bot_rng[m]
    turn = int(core.uniform(row, seat) * 3.0) - 1
    thrust = core.uniform(row, seat) < _P_THRUST
    fire = core.uniform(row, seat) < _P_FIRE
    hyper = core.uniform(row, seat) < _P_HYPER
    return action(turn, thrust, fire, hyper, False)
