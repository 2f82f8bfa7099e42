"""The game's compiled step: Spacewar! rules over arrays with a leading match axis.

All state lives in a handful of numpy arrays whose first axis is the match, so one compiled
call advances many matches (training, fast tournaments). The only Python per frame is asking
the bots for actions. Motion goes through the engine: each match's bodies are advanced by the
engine's own ``symplectic_euler`` splitting kernel with the engine's force terms (the star is a
``PointMass``, the engines a ``Thrust``, plus ``NBodyGravity`` or ``Coulomb`` in the newer
modes), so there is one physics, not two.

Bodies per match: ships 0 and 1, then ``T`` torpedo slots for ship 0 and ``T`` for ship 1.
The matches are one ``engine.Batch`` (a system per match, the periodic space of side 1): the
engine's drift wraps positions onto the torus [-0.5, 0.5)^2 and its pair forces and the
collisions here take the nearest image, all with ``engine.space``'s one wrap. Randomness (fuel burn, hyperspace) comes from a per-match splitmix64
stream, so a match is bit-identical for a given seed whatever else runs beside it.
"""
import math

import numpy as np

from engine import space
from engine.batch import system_model
from engine.cache import compiler
from engine.forces import dispatch, point_mass, thrust
from engine.forces.calls import call_accumulate
from engine.integrators import splitting
from engine.state import Model, State, Workspace

# -- layout of the state arrays ---------------------------------------------------------
# ship gauges, floats (M, 2, SF): heading, turn rate, fuel
HEADING, OMEGA, FUEL, SF = 0, 1, 2, 3
# ship counters and flags, ints (M, 2, SI)
(TORPS, RELOAD, HYPER_LEFT, HYPER_TIMER, HYPER_RECHARGE, HYPER_JUMPS, FLIP_CD, ALIVE, IN_HYPER,
 FIRE_LATCH, THRUSTING, KILLED_AT, SI) = range(13)
# match state, ints (M, MI): frame counters, scores, end timer, flags
(FRAME, ROUND_FRAME, ROUNDS_PLAYED, END_TIMER, SCORE0, SCORE1, OVER, ERROR, ROUND_FRAMES_TOTAL,
 MI) = range(10)

# the rules as one float64 vector (``rules`` in the functions below): indices
(R_TURN, R_ANG_ACCEL, R_ANG_MOM, R_THRUST, R_BURN_MIN, R_BURN_MAX, R_FUEL, R_SHIP_MASS,
 R_START, R_NTORP, R_RELOAD, R_TLIFE, R_MUZZLE, R_OFFSET, R_TMASS, R_HJUMPS, R_HFRAMES,
 R_HRECHARGE, R_HRISK, R_REENTRY, R_HITBOX, R_DIAMOND, R_DELAY, R_MAXFRAMES, R_ROUNDS,
 R_MAXEXTRA, R_STAR, R_CAPTURE, R_STAR_KILLS, R_SINGLE, R_TORP_STAR, R_CHARGE, R_FLIP_CD,
 R_ELECTRIC, R_THRUST_OFF, RN) = range(36)

# action codes: turn index (0, 1, 2 for -1, 0, +1) + 3 thrust + 6 fire + 12 hyperspace + 24 flip
from spacewar.codes import N_ACTIONS, NOOP  # noqa: E402  (kept here: core.NOOP is used throughout)

#: numba's njit with this module's compiled code in the game's cache directory
jit = compiler("spacewar")
# The frame's helpers are compiled without numba's reference counting (``_nrt=False``: they
# allocate nothing), as the engine's force kernels are: with it, each call pays two atomic
# updates per array argument, which for a dozen arrays was most of a match-frame's fixed cost.
# The ones called every frame are also inlined (``inline="always"``): a call passes each
# array as ten words, and one with a dozen arrays measured 25 to 165 ns, against about
# 300 ns for a whole idle match-frame once inlined.
#
# The frame itself (``step_match``) is compiled once, on its own, and inlined into its three
# callers (``step_all``, ``step_one_and_observe``, ``learning.step_learning``) by LLVM
# (``forceinline``: the same machine code as numba's inlining, no call per match): numba's
# inlining re-derives and deep-copies a callee's IR at every call site, in time that grows
# with the square of its size, and compiled each caller's copy of the frame in full. The
# helpers that only compiled code calls have no Python entry points
# (``no_cpython_wrapper``, ``no_cfunc_wrapper``; calling one from Python would crash), which
# numba would otherwise generate and optimise for each; ``forceinline=False`` keeps the cold
# ones called even when compiled from within the frame (numba passes a caller's
# ``forceinline`` on to the callees it compiles).
_CALLED = dict(_nrt=False, forceinline=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)


@jit(**_CALLED)
def next_u64(rng, m):
    """splitmix64 (Steele, Lea & Flood 2014): the next 64 random bits of match m's stream."""
    z = rng[m] + _GOLDEN
    rng[m] = z
    z = (z ^ (z >> np.uint64(30))) * _MIX1
    z = (z ^ (z >> np.uint64(27))) * _MIX2
    return z ^ (z >> np.uint64(31))


@jit(**_CALLED)
def uniform(rng, m):
    """A float in [0, 1) with 53 random bits."""
    return float(next_u64(rng, m) >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@jit(inline="always")
def wrap(x):
    """Onto the torus coordinate range [-0.5, 0.5): the engine's one wrap, side 1."""
    return space.wrap_scalar(x, 1.0)


@jit(**_CALLED)
def ship_start(s, rules):
    """Start position and heading: opposite corners of the star, each facing the other's side."""
    d = rules[R_START] / math.sqrt(2.0)
    if s == 0:
        return -d, d, -0.5 * math.pi
    return d, -d, 0.5 * math.pi


@jit(**_CALLED)
def reset_round(m, pos, vel, mass, charge, active, ship_gauges, ship_counters, torp_life, match_state, rules):
    """Ships back to their start, full stores, torpedoes cleared."""
    ntorp = int(rules[R_NTORP])
    n = pos.shape[2]
    for b in range(n):
        active[m, b] = False
        vel[m, 0, b] = 0.0
        vel[m, 1, b] = 0.0
    for k in range(torp_life.shape[1]):
        torp_life[m, k] = 0
    for s in range(2):
        x, y, h = ship_start(s, rules)
        pos[m, 0, s] = x
        pos[m, 1, s] = y
        active[m, s] = True
        mass[m, s] = rules[R_SHIP_MASS]
        charge[m, s] = rules[R_CHARGE] * (1.0 if s == 0 else -1.0) if rules[R_ELECTRIC] > 0 else 0.0
        ship_gauges[m, s, HEADING] = h
        ship_gauges[m, s, OMEGA] = 0.0
        ship_gauges[m, s, FUEL] = rules[R_FUEL]
        ship_counters[m, s, TORPS] = ntorp
        ship_counters[m, s, RELOAD] = 0
        ship_counters[m, s, HYPER_LEFT] = int(rules[R_HJUMPS])
        ship_counters[m, s, HYPER_TIMER] = 0
        ship_counters[m, s, HYPER_RECHARGE] = 0
        ship_counters[m, s, HYPER_JUMPS] = 0
        ship_counters[m, s, FLIP_CD] = 0
        ship_counters[m, s, ALIVE] = 1
        ship_counters[m, s, IN_HYPER] = 0
        ship_counters[m, s, FIRE_LATCH] = 0
        ship_counters[m, s, THRUSTING] = 0
        ship_counters[m, s, KILLED_AT] = -1
    match_state[m, ROUND_FRAME] = 0
    match_state[m, END_TIMER] = -1


@jit(**_CALLED)
def _kill_ship(m, s, active, ship_counters, frame):
    if ship_counters[m, s, ALIVE] == 1:
        ship_counters[m, s, ALIVE] = 0
        ship_counters[m, s, KILLED_AT] = frame
        ship_counters[m, s, THRUSTING] = 0
        active[m, s] = False


@jit(**_CALLED)
def _fire(m, s, pos, vel, mass, charge, active, ship_gauges, ship_counters, torp_life, rules):
    ntorp = int(rules[R_NTORP])
    k = ntorp - ship_counters[m, s, TORPS]  # each torpedo of a round has its own slot
    b = 2 + s * ntorp + k
    h = ship_gauges[m, s, HEADING]
    c = math.cos(h)
    sn = math.sin(h)
    pos[m, 0, b] = wrap(pos[m, 0, s] + rules[R_OFFSET] * c)
    pos[m, 1, b] = wrap(pos[m, 1, s] + rules[R_OFFSET] * sn)
    vel[m, 0, b] = vel[m, 0, s] + rules[R_MUZZLE] * c
    vel[m, 1, b] = vel[m, 1, s] + rules[R_MUZZLE] * sn
    mass[m, b] = rules[R_TMASS]
    charge[m, b] = charge[m, s]
    active[m, b] = True
    torp_life[m, s * ntorp + k] = int(rules[R_TLIFE])
    ship_counters[m, s, TORPS] -= 1
    ship_counters[m, s, RELOAD] = int(rules[R_RELOAD])


@jit(**_CALLED)
def _reenter(m, s, pos, vel, active, ship_gauges, ship_counters, rng, rules):
    """Back from hyperspace at a random place, speed and heading; jump k breaks up with k/8."""
    ship_counters[m, s, IN_HYPER] = 0
    ship_counters[m, s, HYPER_RECHARGE] = int(rules[R_HRECHARGE])
    while True:  # not inside the star's reach
        x = uniform(rng, m) - 0.5
        y = uniform(rng, m) - 0.5
        if rules[R_STAR] == 0.0 or x * x + y * y > (6.0 * rules[R_CAPTURE]) ** 2:
            break
    speed = rules[R_REENTRY] * uniform(rng, m)
    direction = 2.0 * math.pi * uniform(rng, m)
    pos[m, 0, s] = x
    pos[m, 1, s] = y
    vel[m, 0, s] = speed * math.cos(direction)
    vel[m, 1, s] = speed * math.sin(direction)
    ship_gauges[m, s, HEADING] = 2.0 * math.pi * uniform(rng, m) - math.pi
    ship_gauges[m, s, OMEGA] = 0.0
    active[m, s] = True
    breakup = min(1.0, rules[R_HRISK] * ship_counters[m, s, HYPER_JUMPS])
    return uniform(rng, m) < breakup


@jit(_nrt=False, inline="always")
def _control(m, s, code, frame, pos, vel, mass, charge, active, ship_gauges, ship_counters, torp_life, force_params,
             rng, rules):
    """Apply one ship's action for this frame: turn, thrust, fire, hyperspace, polarity."""
    turn = code % 3 - 1
    thrust = (code // 3) % 2 == 1
    fire = (code // 6) % 2 == 1
    hyper = (code // 12) % 2 == 1
    flip = (code // 24) % 2 == 1
    off = int(rules[R_THRUST_OFF])
    force_params[m, off + 2 * s] = 0.0
    force_params[m, off + 2 * s + 1] = 0.0
    ship_counters[m, s, THRUSTING] = 0
    if ship_counters[m, s, RELOAD] > 0:
        ship_counters[m, s, RELOAD] -= 1
    if ship_counters[m, s, HYPER_RECHARGE] > 0:
        ship_counters[m, s, HYPER_RECHARGE] -= 1
    if ship_counters[m, s, FLIP_CD] > 0:
        ship_counters[m, s, FLIP_CD] -= 1
    if ship_counters[m, s, ALIVE] == 0:
        return
    if ship_counters[m, s, IN_HYPER] == 1:
        ship_counters[m, s, HYPER_TIMER] -= 1
        if ship_counters[m, s, HYPER_TIMER] <= 0:
            if _reenter(m, s, pos, vel, active, ship_gauges, ship_counters, rng, rules):
                _kill_ship(m, s, active, ship_counters, frame)  # broke up in hyperspace
        return
    if hyper and ship_counters[m, s, HYPER_LEFT] > 0 and ship_counters[m, s, HYPER_RECHARGE] == 0:
        ship_counters[m, s, HYPER_LEFT] -= 1
        ship_counters[m, s, HYPER_JUMPS] += 1
        ship_counters[m, s, IN_HYPER] = 1
        ship_counters[m, s, HYPER_TIMER] = int(rules[R_HFRAMES])
        active[m, s] = False
        return
    # turning
    if rules[R_ANG_MOM] > 0:
        w = ship_gauges[m, s, OMEGA] + turn * rules[R_ANG_ACCEL]
        limit = 4.0 * rules[R_TURN]
        ship_gauges[m, s, OMEGA] = min(limit, max(-limit, w))
        ship_gauges[m, s, HEADING] += ship_gauges[m, s, OMEGA]
    else:
        ship_gauges[m, s, HEADING] += turn * rules[R_TURN]
    h = ship_gauges[m, s, HEADING]
    if h > math.pi:
        ship_gauges[m, s, HEADING] = h - 2.0 * math.pi
    elif h <= -math.pi:
        ship_gauges[m, s, HEADING] = h + 2.0 * math.pi
    h = ship_gauges[m, s, HEADING]
    # thrust: a control force through the engine's Thrust term
    if thrust and ship_gauges[m, s, FUEL] > 0.0:
        burn = rules[R_BURN_MIN] + (rules[R_BURN_MAX] - rules[R_BURN_MIN]) * uniform(rng, m)
        ship_gauges[m, s, FUEL] = max(0.0, ship_gauges[m, s, FUEL] - burn)
        f = rules[R_THRUST] * mass[m, s]
        force_params[m, off + 2 * s] = f * math.cos(h)
        force_params[m, off + 2 * s + 1] = f * math.sin(h)
        ship_counters[m, s, THRUSTING] = 1
    # polarity flip (electric mode)
    if flip and rules[R_ELECTRIC] > 0 and ship_counters[m, s, FLIP_CD] == 0:
        charge[m, s] = -charge[m, s]
        ship_counters[m, s, FLIP_CD] = int(rules[R_FLIP_CD])
    # fire
    latched = rules[R_SINGLE] > 0 and ship_counters[m, s, FIRE_LATCH] == 1
    if fire and not latched and ship_counters[m, s, TORPS] > 0 and ship_counters[m, s, RELOAD] == 0:
        _fire(m, s, pos, vel, mass, charge, active, ship_gauges, ship_counters, torp_life, rules)
    ship_counters[m, s, FIRE_LATCH] = 1 if fire else 0


@jit(_nrt=False, inline="always")
def _hit(pos, m, a, b, box, diamond):
    """The original's diamond proximity test, by the nearest image on the torus."""
    dx = abs(space.wrap_scalar(pos[m, 0, b] - pos[m, 0, a], 1.0))  # the nearest image
    if dx >= box:  # most pairs are far apart in x: no need for y
        return False
    dy = abs(space.wrap_scalar(pos[m, 1, b] - pos[m, 1, a], 1.0))
    return dy < box and dx + dy < diamond


@jit(_nrt=False, inline="always")
def _collisions(m, pos, vel, active, ship_counters, torp_life, match_state, rules, marks):
    """Torpedoes and ships that touch, and what the star captures. ``marks`` (2, bodies)
    int64 is the thread's scratch, so a frame allocates nothing: row 0 lists the live bodies
    (the pair test then visits only those, a handful of a match's 66 slots), row 1 flags the
    doomed."""
    n = pos.shape[2]
    box = rules[R_HITBOX]
    diamond = rules[R_DIAMOND]
    live = _live_list(m, active, n, 0, marks[0])
    for i in range(live):
        marks[1, marks[0, i]] = 0
    for i in range(live):
        a = marks[0, i]
        for j in range(i + 1, live):
            b = marks[0, j]
            if _hit(pos, m, a, b, box, diamond):
                marks[1, a] = 1
                marks[1, b] = 1
    # the star: ships (and, where they feel it, torpedoes) within its capture radius
    if rules[R_STAR] > 0.0:
        r2 = rules[R_CAPTURE] ** 2
        for i in range(live):
            b = marks[0, i]
            if b >= 2 and rules[R_TORP_STAR] == 0.0:
                continue
            if pos[m, 0, b] ** 2 + pos[m, 1, b] ** 2 < r2:
                if b < 2 and rules[R_STAR_KILLS] == 0.0:
                    pos[m, 0, b] = -0.5  # moved to the corner, at rest
                    pos[m, 1, b] = -0.5
                    vel[m, 0, b] = 0.0
                    vel[m, 1, b] = 0.0
                else:
                    marks[1, b] = 1
    for i in range(live):
        b = marks[0, i]
        if marks[1, b]:
            if b < 2:
                _kill_ship(m, b, active, ship_counters, match_state[m, FRAME])
            else:
                active[m, b] = False
                torp_life[m, b - 2] = 0


@jit(_nrt=False, inline="always")
def _round_logic(m, pos, vel, mass, charge, active, ship_gauges, ship_counters, torp_life, match_state, rules):
    """End of round (a ship lost, both out of torpedoes, or the time limit), then scoring."""
    match_state[m, ROUND_FRAME] += 1
    if match_state[m, END_TIMER] < 0:
        lost = ship_counters[m, 0, ALIVE] == 0 or ship_counters[m, 1, ALIVE] == 0
        dry = ship_counters[m, 0, TORPS] == 0 and ship_counters[m, 1, TORPS] == 0
        if lost or dry:
            match_state[m, END_TIMER] = int(rules[R_DELAY])
        elif match_state[m, ROUND_FRAME] >= int(rules[R_MAXFRAMES]):
            match_state[m, END_TIMER] = 0
    if match_state[m, END_TIMER] < 0:
        return
    if match_state[m, END_TIMER] > 0:
        match_state[m, END_TIMER] -= 1
        return
    # the round is over: a point to each survivor
    match_state[m, SCORE0] += ship_counters[m, 0, ALIVE]
    match_state[m, SCORE1] += ship_counters[m, 1, ALIVE]
    match_state[m, ROUNDS_PLAYED] += 1
    match_state[m, ROUND_FRAMES_TOTAL] += match_state[m, ROUND_FRAME]
    played = match_state[m, ROUNDS_PLAYED]
    rounds = int(rules[R_ROUNDS])
    tied = match_state[m, SCORE0] == match_state[m, SCORE1]
    if played >= rounds and (not tied or played >= rounds + int(rules[R_MAXEXTRA])):
        match_state[m, OVER] = 1
        return
    reset_round(m, pos, vel, mass, charge, active, ship_gauges, ship_counters, torp_life, match_state, rules)


@jit(_nrt=False, inline="always")
def _gather(m, state, bodies, order):
    """Match m's two ships (always, so they keep the indices 0 and 1 the force terms name
    them by) and its live torpedoes, in slot order, into the front of ``bodies`` (a one-system
    ``State``); ``order[k]`` gets the slot of the k-th. Returns how many. The game's bodies
    all keep the batch's zero radius and none is pinned, as ``bodies`` is made
    (``new_scratch``): those two are not copied."""
    count = _live_list(m, state.active, state.n, 2, order)
    for j in range(count):
        b = order[j]
        for k in range(state.pos.shape[1]):
            bodies.pos[k, j] = state.pos[m, k, b]
            bodies.vel[k, j] = state.vel[m, k, b]
        bodies.mass[j] = state.mass[m, b]
        bodies.charge[j] = state.charge[m, b]
        bodies.active[j] = state.active[m, b]
        bodies.test[j] = state.test[m, b]  # the torpedoes feel gravity but exert none
    return count


@jit(_nrt=False, inline="always")
def _live_list(m, active, n, first, order):
    """The slots of match m's first ``first`` bodies and of its other live ones, in order,
    into ``order``; returns how many. Without a branch per slot: which slots are live is
    random from frame to frame, and a mispredicted branch for each of 66 slots cost more
    than the physics of the live bodies."""
    count = 0
    for b in range(n):
        order[count] = b
        count += 1 if b < first else int(active[m, b])
    return count


@jit(_nrt=False, inline="always")
def _scatter(m, state, bodies, order, count):
    """The gathered bodies' new positions and velocities back into match m's slots."""
    for j in range(count):
        b = order[j]
        for k in range(state.pos.shape[1]):
            state.pos[m, k, b] = bodies.pos[k, j]
            state.vel[m, k, b] = bodies.vel[k, j]


@jit(error_model="numpy", _nrt=False, inline="always")
def _forces(t, state, model, acc, work):
    """``engine.forces.dispatch.accelerations_inline`` with the two terms every mode declares
    named: the star's ``PointMass`` and the engines' ``Thrust`` are inlined into the frame,
    and only a mode's other terms (``NBodyGravity``, ``Coulomb``) are called through their
    addresses. The same terms in the same order, so the same bits; a call through an address
    passes the whole state (about sixty words), which cost about 5% of a learning step."""
    dispatch.clear(acc, state.n)
    for s in range(model.kinds.shape[0]):
        kind = model.kinds[s]
        f0, f1 = model.param_offsets[s], model.param_offsets[s + 1]
        i0, i1 = model.index_offsets[s], model.index_offsets[s + 1]
        if kind == point_mass.KIND:
            point_mass.accumulate(t, state, model.params, f0, f1, model.indices, i0, i1, acc,
                                  work)
        elif kind == thrust.KIND:
            thrust.accumulate(t, state, model.params, f0, f1, model.indices, i0, i1, acc, work)
        else:
            call_accumulate(model.accumulators[s], t, state, model.params, f0, f1,
                            model.indices, i0, i1, acc, work)


@jit(_nrt=False, inline="always")
def _move(m, state, model, work, drifts, kicks, scratch):
    """The engine's step of match m's bodies: its symplectic Euler kernel, dt = 1 frame, with
    the engine's forces; its drift wraps positions onto the torus (the batch's box = 1).

    Most of a match's 66 slots are empty torpedo slots, which the engine's loops would visit
    only to skip, so the live bodies are gathered into the thread's own small system first
    and their motion scattered back. The bits are those of a step over all the slots: an
    inactive body neither moves nor exerts or feels a force, and the live ones keep their
    order, so every sum adds the same terms in the same order."""
    engine_scratch, bodies, marks = scratch
    order = marks[0]  # the live bodies' slots (the collisions rebuild the list after the move)
    count = _gather(m, state, bodies, order)
    system = State(bodies.pos, bodies.vel, bodies.mass, bodies.charge, bodies.radius,
                   bodies.active, bodies.test, bodies.pinned, count, state.box)
    _, _, _, status = splitting.advance_general_in(0.0, 1.0, 1, system, system_model(model, m),
                                                   work, False, drifts, kicks, engine_scratch,
                                                   _forces)
    _scatter(m, state, bodies, order, count)
    return status, count


@jit(_nrt=False, forceinline=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def step_match(m, actions, state, model, work, ship_gauges, ship_counters, torp_life,
               match_state, rng, rules, drifts, kicks, scratch):
    """Advance match ``m`` by one frame with ``actions[m, 0]`` and ``actions[m, 1]``.

    ``state`` and ``model`` are the match batch's ``engine.Batch.kernel_arguments()``;
    ``scratch`` is the thread's (``new_scratch``), reused from match to match."""
    if match_state[m, OVER] == 1:
        return
    pos = state.pos
    vel = state.vel
    mass = state.mass
    charge = state.charge
    active = state.active
    force_params = model.params
    match_state[m, FRAME] += 1
    for s in range(2):
        _control(m, s, actions[m, s], match_state[m, FRAME], pos, vel, mass, charge, active,
                 ship_gauges, ship_counters, torp_life, force_params, rng, rules)
    status, count = _move(m, state, model, work, drifts, kicks, scratch)
    if status >= 0:
        match_state[m, ERROR] = 1
        match_state[m, OVER] = 1
        return
    marks = scratch[2]
    for j in range(2, count):  # the live torpedoes (a dead one's life is 0 already)
        k = marks[0, j] - 2
        if torp_life[m, k] > 0:
            torp_life[m, k] -= 1
            if torp_life[m, k] == 0:
                active[m, 2 + k] = False  # bursts harmlessly
    _collisions(m, pos, vel, active, ship_counters, torp_life, match_state, rules, marks)
    _round_logic(m, pos, vel, mass, charge, active, ship_gauges, ship_counters, torp_life,
                 match_state, rules)


@jit(inline="always")
def new_scratch(pos):
    """A thread's scratch for the frames of the batch's matches (``pos`` is (M, dim, n)),
    reused for every match it steps, so a frame allocates nothing per match: the engine
    step's rows, the one-system ``State`` the live bodies are gathered into, and the
    collisions' lists."""
    dim, n = pos.shape[1], pos.shape[2]
    rows = splitting.scratch_rows(dim)
    floats = np.zeros((rows + 2 * dim + 3, n))  # three allocations in all: a frame of one
    flags = np.zeros((3, n), dtype=np.bool_)    # match (the match loop's) makes its own
    o = rows + 2 * dim
    bodies = State(floats[rows:rows + dim], floats[rows + dim:o], floats[o], floats[o + 1],
                   floats[o + 2], flags[0], flags[1], flags[2], n, 0.0)
    marks = np.zeros((2, n), dtype=np.int64)  # the live bodies' slots, the doomed ones
    return floats[:rows], bodies, marks


@jit()
def step_all(actions, pos, vel, mass, charge, radius, active, test, pinned, n, box, kinds,
             params, param_offsets, indices, index_offsets, accumulators, potentials,
             ship_gauges, ship_counters, torp_life, match_state, rng, rules, drifts, kicks):
    """Advance every match by one frame (matches already over are left as they are).

    The batch's ``State`` and ``Model`` come in as their arrays (numba reads plain array
    arguments faster than named tuples of them at the call from Python) and are put together
    here once."""
    state = State(pos, vel, mass, charge, radius, active, test, pinned, n, box)
    model = Model(kinds, params, param_offsets, indices, index_offsets, accumulators,
                  potentials)
    # the game's pair forces run the engine's scalar pair loop (no large-N workspace), as the
    # recorded replays were played
    work = Workspace(np.empty(0), np.empty(0, dtype=np.int64), False)
    scratch = new_scratch(pos)
    for m in range(pos.shape[0]):
        step_match(m, actions, state, model, work, ship_gauges, ship_counters, torp_life,
                   match_state, rng, rules, drifts, kicks, scratch)


@jit()
def step_one_and_observe(actions, pos, vel, mass, charge, radius, active, test, pinned, n, box,
                         kinds, params, param_offsets, indices, index_offsets, accumulators,
                         potentials, ship_gauges,
                         ship_counters, torp_life, match_state, rng, rules, drifts, kicks, m,
                         raws):
    """Match ``m``'s frame (``step_match``), then what each seat sees next written into
    ``raws[seat]`` (``write_observation``): one call per frame for a match loop that asks
    its bots one observation at a time, whose cost is mostly the calls themselves."""
    state = State(pos, vel, mass, charge, radius, active, test, pinned, n, box)
    model = Model(kinds, params, param_offsets, indices, index_offsets, accumulators,
                  potentials)
    work = Workspace(np.empty(0), np.empty(0, dtype=np.int64), False)
    step_match(m, actions, state, model, work, ship_gauges, ship_counters, torp_life,
               match_state, rng, rules, drifts, kicks, new_scratch(pos))
    for seat in range(2):
        write_observation(m, seat, pos, vel, charge, active, ship_gauges, ship_counters,
                          torp_life, match_state, rules, raws[seat])


@jit(**_CALLED)
def reset_match(m, pos, vel, mass, charge, active, ship_gauges, ship_counters, torp_life,
                match_state, rules):
    """Match m back to its first frame (its random stream is the caller's to set)."""
    for k in range(match_state.shape[1]):
        match_state[m, k] = 0
    reset_round(m, pos, vel, mass, charge, active, ship_gauges, ship_counters, torp_life,
                match_state, rules)


@jit()
def reset_all(pos, vel, mass, charge, active, ship_gauges, ship_counters, torp_life, match_state, rules):
    for m in range(pos.shape[0]):
        reset_match(m, pos, vel, mass, charge, active, ship_gauges, ship_counters, torp_life,
                    match_state, rules)


@jit()
def write_observation(m, seat, pos, vel, charge, active, ship_gauges, ship_counters, torp_life, match_state, rules, raw):
    """Match ``m`` seen from ``seat`` as the flat array of ``spacewar.protocol.raw_layout``:
    10 header numbers, the own ship's 15, the enemy's 15, then 8 per torpedo slot (own slots
    first, each with a presence flag; an empty slot is all zeros)."""
    raw[0] = match_state[m, FRAME]
    raw[1] = match_state[m, ROUND_FRAME]
    raw[2] = match_state[m, ROUNDS_PLAYED]
    raw[3] = match_state[m, SCORE0 + seat]
    raw[4] = match_state[m, SCORE0 + 1 - seat]
    raw[5] = seat
    raw[6] = rules[R_STAR]
    raw[7] = rules[R_CAPTURE]
    raw[8] = 0.0
    raw[9] = 0.0
    for row in range(2):
        s = seat if row == 0 else 1 - seat
        o = 10 + 15 * row
        raw[o] = pos[m, 0, s]
        raw[o + 1] = pos[m, 1, s]
        raw[o + 2] = vel[m, 0, s]
        raw[o + 3] = vel[m, 1, s]
        raw[o + 4] = ship_gauges[m, s, HEADING]
        raw[o + 5] = ship_gauges[m, s, OMEGA]
        raw[o + 6] = ship_gauges[m, s, FUEL]
        raw[o + 7] = ship_counters[m, s, TORPS]
        raw[o + 8] = ship_counters[m, s, HYPER_LEFT]
        raw[o + 9] = ship_counters[m, s, ALIVE]
        raw[o + 10] = ship_counters[m, s, IN_HYPER]
        raw[o + 11] = ship_counters[m, s, RELOAD]
        raw[o + 12] = ship_counters[m, s, HYPER_RECHARGE]
        raw[o + 13] = charge[m, s]
        raw[o + 14] = ship_counters[m, s, FLIP_CD]
    t = torp_life.shape[1] // 2
    o = 40
    for row in range(2):
        owner = seat if row == 0 else 1 - seat
        for k in range(t):
            b = 2 + owner * t + k
            if active[m, b]:
                raw[o] = 1.0
                raw[o + 1] = pos[m, 0, b]
                raw[o + 2] = pos[m, 1, b]
                raw[o + 3] = vel[m, 0, b]
                raw[o + 4] = vel[m, 1, b]
                raw[o + 5] = 1.0 if row == 0 else 0.0
                raw[o + 6] = torp_life[m, owner * t + k]
                raw[o + 7] = charge[m, b]
            else:
                for j in range(8):
                    raw[o + j] = 0.0
            o += 8


def drift_kick():
    """The engine's symplectic Euler coefficients: kick then drift, as the 1962 game."""
    return splitting.coefficients("symplectic_euler")
