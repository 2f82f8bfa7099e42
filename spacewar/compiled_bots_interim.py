"""Interim stand-in for spacewar.compiled_bots (idle and random only), until it lands."""
import numpy as np

from . import core

jit = core.jit
KINDS = {"idle": 0, "random": 1}
MEMORY = 1


def new_memory(matches):
    return np.zeros((int(matches), 2, MEMORY))


@jit()
def reset_memory(m, seat, memory):
    for k in range(memory.shape[2]):
        memory[m, seat, k] = 0.0


@jit()
def decide(kind, m, seat, pos, vel, charge, active, ship_gauges, ship_counters, torp_life,
           match_state, rules, memory, bot_rng):
    if kind == 1:
        r0 = core.uniform(bot_rng[m], seat)
        return int(r0 * 3.0)
    return core.NOOP
