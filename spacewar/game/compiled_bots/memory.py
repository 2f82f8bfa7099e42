"""What a compiled bot keeps between frames: ``MEMORY`` floats per seat (the layout in the
package's text), the random bot's splitmix64 streams, and a seat's reset."""
import numpy as np

from spacewar.game import core

jit = core.jit

# memory per seat (see the package's text)
(ESCAPING, THRUST_X, THRUST_Y, HAS_LAST, LAST_ROUND, LAST_ROUND_FRAME, LAST_X, LAST_Y, LAST_VX,
 LAST_VY, MEMORY) = range(11)


def new_memory(matches):
    """Fresh memory for ``matches`` matches: float64 (M, 2, MEMORY), zeros = a fresh bot."""
    return np.zeros((int(matches), 2, MEMORY))


def new_streams(matches, seed=0):
    """The random bot's per-seat splitmix64 states, (M, 2) uint64, from an int seed
    (numpy's SeedSequence, as ``game.seed_state``)."""
    return np.random.SeedSequence(int(seed)).generate_state(2 * int(matches), np.uint64) \
        .reshape(int(matches), 2)


@jit()
def reset_memory(m, seat, memory):
    """Seat ``seat``'s bot of match ``m`` as new (the Python bots' ``reset()``). Its random
    stream ``bot_rng[m, seat]`` is the caller's to set."""
    for k in range(memory.shape[2]):
        memory[m, seat, k] = 0.0
