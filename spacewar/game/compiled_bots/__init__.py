"""The built-in bots compiled: they decide inside the game's compiled call, for learning.

The Python bots in ``spacewar.bots`` (with ``spacewar.bots.geometry``) are the readable
reference; this module computes the same decisions from the game's arrays (``core``'s layout,
leading match axis) with no Python per frame, so that the opponents a learner trains against
can play thousands of matches per call (``spacewar.learn.batch.step_learning``)::

    memory = new_memory(M)                 # (M, 2, MEMORY) float64, zeros = a fresh bot
    bot_rng = new_streams(M, seed)         # (M, 2) uint64, the random bot's own streams
    code = decide(KINDS["chaser"], m, seat, pos, vel, charge, active, ship_gauges,
                  ship_counters, torp_life, match_state, rules, memory, bot_rng)
    decide_all(kind, seat, ..., memory, bot_rng, codes)    # every match, codes[:, seat]
    reset_memory(m, seat, memory)          # a match restarted: the bot's reset()

**What a bot sees.** ``Game.observe`` gives a Python bot the raw arrays' own float64 values
(``core.write_observation``): positions, velocities, heading and turn rate, fuel, counters,
``star_mu = rules[R_STAR]`` (the *effective* mu: the heavy / light / none switch applied),
``star_capture = rules[R_CAPTURE]``, the round and round frame, the torpedoes present (own
slots first, in slot order, each with its frames to live) and ``obs.rules``, the game's
``Rules``. The compiled bots read exactly these from the arrays: the rules they use are the
rules vector's turn rate, angular acceleration and switch, thrust, launch offset, muzzle
speed, torpedo life, hit box and diamond, the star's capture radius, whether torpedoes feel
the star (``R_TORP_STAR``, the newtonian mode) and the electric mode.

**Memory** (``MEMORY`` floats per seat): ``[ESCAPING]`` the chaser's and sniper's star-escape
flag; the sniper's and dodger's enemy-thrust estimate ``[THRUST_X, THRUST_Y]`` and the enemy
seen last frame ``[HAS_LAST, LAST_ROUND, LAST_ROUND_FRAME, LAST_X, LAST_Y, LAST_VX, LAST_VY]``
(``Sniper.track``). Zeros are a fresh bot, as after ``reset()``.

**Same numbers, same decisions.** Every formula is the reference's, in the reference's order
of operations, so that a decision is the same bit for bit where the reference's arithmetic
can be reproduced:

* ``math.hypot`` in Python 3.8+ is not the C library's ``hypot``: it is CPython's own
  correctly-rounded-in-practice algorithm (``vector_norm`` in ``Modules/mathmodule.c``:
  scaling by a power of two, exact squares, a compensated sum and one differential
  correction of the square root). It differs from the C ``hypot`` (what numba's
  ``math.hypot`` and numpy's ``np.hypot`` call) in the last bit about 4 times in 10^5.
  :func:`py_hypot` re-implements CPython's algorithm; ``np.hypot`` in the reference
  (``lead_intercept``, the dodger's star pull) stays ``math.hypot`` here.
* numpy's ``a @ b`` of two 2-vectors goes to OpenBLAS's ``ddot``, whose kernel is chosen
  by CPU: on some (SkylakeX kernels) it computes ``fma(a1, b1, a0 b0)``, which a quarter of
  the time differs from ``a0 b0 + a1 b1`` in the last bit; on others (its Haswell kernel on
  an AMD EPYC) it computes the plain sum. ``engine.cache.numpy_dot_kind`` measures which at
  import, and :func:`dot_blas` is compiled to match (the fused form with LLVM's
  ``llvm.fma.f64``, correctly rounded everywhere); the game's compiled-code directory is
  named by the kind. On a machine with a third rounding, the plain sum is used and this
  mirror is off by one rounding there.
  Sums written with ``(a * b).sum(axis=1)`` or ``x * x + y * y`` stay plain.
* ``np.cos`` / ``np.sin`` of float64 agree with ``math.cos`` / ``math.sin`` (the C library)
  on this machine (checked on 2e5 angles); Python's ``%`` on floats and numpy's remainder
  agree with numba's ``%`` (all take the sign of the divisor); ``x ** 2`` of a Python float
  is ``pow(x, 2)``, taken here as ``x * x`` (the same value unless the C library's pow
  misrounds a square, not seen).
* The Kepler prediction calls the engine's compiled ``engine.analytic.kepler_step``, the very
  kernel ``geometry.predict_path`` reaches through ``engine.analytic.kepler``, time by time
  from the same start; its results are identical.
* ``argmin`` / ``argmax`` take the first of equal values, as numpy's; the dodger's
  ``sort`` of two escape directions is stable.

What is left: a ``NaN`` reaching a comparison (numpy's ``maximum`` keeps it where Python's
``max(0.0, nan)`` drops it); a Kepler point that is not finite (the reference then predicts
the whole path straight; here only the points computed are checked, see :func:`enemy_point`;
never seen); and the random bot, whose draws come from ``bot_rng`` (splitmix64,
``core.next_u64``), not numpy's PCG64: it has the reference's probabilities, not its exact
sequence. The agreement test (``tests/spacewar/test_compiled_bots.py``) measured 100% of
frames for the chaser, sniper and dodger.

**Cost.** idle, random and chaser allocate nothing (chaser: about 0.7-1 us a decision on one
thread here). The sniper and dodger need the enemy's predicted path, one Kepler solve
(about 1.7 us) per frame of a torpedo's life: its points are computed lazily and the scans
(lead, first hit, pending hit) skip the frames where a speed bound proves nothing can happen
(:func:`lead_intercept`), which leaves the decisions exactly the reference's and cuts the cost
about eightfold (to about 7-10 us a decision). :func:`decide` allocates one small scratch array
per call for them (``new_scratch``), :func:`decide_all` one per chunk of matches.

**Where each part is.** One module per bot, as in ``spacewar.bots``: ``idle``,
``random_bot``, ``chaser``, ``sniper``, ``dodger`` (each holds its reference's parameters, a
test holds them equal to the constructors' defaults); what they share: ``geometry`` (as
``spacewar.bots.geometry``), ``numerics`` (the reference's arithmetic) and ``memory``. This
module holds the entry points and re-exports the names callers use.
"""
from numba import prange

from spacewar.builtin_bots import NAMES
from spacewar.game import core
from spacewar.game.compiled_bots import chaser, dodger, idle, random_bot, sniper
from spacewar.game.compiled_bots.chaser import CHASER_PARAMS
from spacewar.game.compiled_bots.dodger import DODGER_PARAMS
from spacewar.game.compiled_bots.memory import (ESCAPING, HAS_LAST, LAST_ROUND, LAST_ROUND_FRAME,
                                                LAST_VX, LAST_VY, LAST_X, LAST_Y, MEMORY,
                                                THRUST_X, THRUST_Y, new_memory, new_streams,
                                                reset_memory)
from spacewar.game.compiled_bots.numerics import DOT_FUSED, NUMERIC, dot_blas, py_hypot
from spacewar.game.compiled_bots.random_bot import RANDOM_PARAMS
from spacewar.game.compiled_bots.sniper import SNIPER_PARAMS, new_scratch

jit = core.jit

#: the compiled bots by name, as ``decide``'s ``kind`` (``spacewar.builtin_bots``' order)
KINDS = {name: k for k, name in enumerate(NAMES)}
IDLE, RANDOM, CHASER, SNIPER, DODGER = (KINDS[name] for name in
                                        ("idle", "random", "chaser", "sniper", "dodger"))


# -- the entry points -----------------------------------------------------------------------------
@jit(_nrt=False, inline="always", **NUMERIC)  # allocates nothing; inlined (core's note)
def decide_with(kind, m, seat, pos, vel, charge, active, ship_gauges, ship_counters, torp_life,
                match_state, rules, memory, bot_rng, scratch):
    """:func:`decide` with the sniper's and dodger's scratch given (``new_scratch``)."""
    if kind == RANDOM:
        return random_bot.random_code(m, seat, bot_rng)
    if kind == CHASER:
        return chaser.chaser(m, seat, pos, vel, ship_gauges, ship_counters, rules, memory)
    if kind == SNIPER or kind == DODGER:
        sniper.track(m, seat, pos, vel, ship_counters, match_state, rules, memory)
        if ship_counters[m, seat, core.ALIVE] == 0 or ship_counters[m, seat, core.IN_HYPER] == 1:
            return core.NOOP
        n = max(int(rules[core.R_TLIFE]) - 1, 1)
        if kind == DODGER:
            slot, t_c, cx, cy, t_hit = dodger.threat(m, seat, pos, vel, active, torp_life, rules, n,
                                              scratch)
            if slot >= 0:
                return dodger.dodge(m, seat, pos, vel, charge, active, ship_gauges, ship_counters,
                             torp_life, rules, memory, n, scratch, slot, t_c, cx, cy, t_hit)
        return sniper.sniper_decide(m, seat, pos, vel, active, ship_gauges, ship_counters, torp_life,
                             rules, memory, n, scratch)
    return idle.idle_code()


@jit(**NUMERIC)
def decide(kind, m, seat, pos, vel, charge, active, ship_gauges, ship_counters, torp_life,
           match_state, rules, memory, bot_rng):
    """The action code of bot ``kind`` (``KINDS``) in seat ``seat`` of match ``m`` this frame,
    from the state before the frame is stepped; updates its ``memory[m, seat]`` (and draws from
    ``bot_rng[m, seat]`` for the random bot). idle, random and chaser allocate nothing; the
    sniper and dodger allocate their scratch (``new_scratch``) per call."""
    if kind == SNIPER or kind == DODGER:
        scratch = new_scratch(rules)
        return decide_with(kind, m, seat, pos, vel, charge, active, ship_gauges, ship_counters,
                           torp_life, match_state, rules, memory, bot_rng, scratch)
    if kind == RANDOM:
        return random_bot.random_code(m, seat, bot_rng)
    if kind == CHASER:
        return chaser.chaser(m, seat, pos, vel, ship_gauges, ship_counters, rules, memory)
    return idle.idle_code()


CHUNK = 64  # matches per scratch in decide_all


@jit(parallel=True, **NUMERIC)
def decide_all(kind, seat, pos, vel, charge, active, ship_gauges, ship_counters, torp_life,
               match_state, rules, memory, bot_rng, codes):
    """:func:`decide` for every match, into ``codes[:, seat]`` (M, 2) int64; matches spread over
    the threads in chunks of ``CHUNK``, each chunk with one scratch. Each match touches only its
    own rows, so the result does not depend on the thread count."""
    matches = pos.shape[0]
    chunks = (matches + CHUNK - 1) // CHUNK
    for c in prange(chunks):
        scratch = new_scratch(rules)
        for m in range(c * CHUNK, min(matches, (c + 1) * CHUNK)):
            codes[m, seat] = decide_with(kind, m, seat, pos, vel, charge, active, ship_gauges,
                                         ship_counters, torp_life, match_state, rules, memory,
                                         bot_rng, scratch)


__all__ = ["KINDS", "IDLE", "RANDOM", "CHASER", "SNIPER", "DODGER", "decide", "decide_all",
           "decide_with", "new_scratch", "MEMORY", "ESCAPING", "THRUST_X", "THRUST_Y", "HAS_LAST",
           "LAST_ROUND", "LAST_ROUND_FRAME", "LAST_X", "LAST_Y", "LAST_VX", "LAST_VY",
           "new_memory", "new_streams", "reset_memory", "RANDOM_PARAMS", "CHASER_PARAMS",
           "SNIPER_PARAMS", "DODGER_PARAMS", "DOT_FUSED", "dot_blas", "py_hypot"]
