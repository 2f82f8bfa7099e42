"""Wisdom-Holman splitting (``whfast``): Kepler drifts about the dominant body, interaction kicks.

The Hamiltonian is split as H = H_Kepler + H_interaction, and a step is the symmetric
composition drift(h/2) kick(h) drift(h/2), where the drift moves every body exactly on its own
Kepler orbit (``kepler_drift.drift_columns``: universal variables, every body of the step
solved in lockstep, whole periods removed first from long arcs, ``engine.analytic.kepler_step``
where the fast iteration does not meet round-off) and the kick adds h times the acceleration of
everything the Kepler part leaves out
(Wisdom & Holman 1991, AJ 102, 1528; Rein & Tamayo 2015, MNRAS 452, 376). Inside one call the
half drifts of consecutive steps are merged into one drift, so a step costs one force
evaluation and one Kepler solve per body (``kepler_drift``); the state is synchronised (the
last half drift, the corrector's inverse, inertial coordinates) when the call ends.

Two kinds of scene:

``JACOBI`` (``NBodyGravity`` with a dominant mass)
    Jacobi coordinates about the heaviest body, the others in index order, test particles last
    (they feel gravity, exert none: they take no part in the interior masses). With interior
    masses eta_j = sum_{k<=j} m_k, body j's Jacobi position r'_j = r_j - R_{j-1} (R the centre
    of mass of the bodies before it) drifts on a Kepler orbit of mu_j = G eta_j, and the kick
    is a'_j = (J a)_j + G eta_j r'_j / |r'_j|^3: the Jacobi transform of the inertial
    accelerations of every declared term, plus the Kepler attraction the drift already took
    (Wisdom & Holman 1991, eqs. 10-13; the transform of the accelerations is the transform of
    the positions, since r' = J r is linear). The centre of mass drifts in a straight line.
``ATTRACTOR`` (a fixed ``PointMass``)
    every particle the attractor acts on drifts on its own Kepler orbit about it (mu and the
    attractor's position from the term), the others in straight lines; the kick is the
    acceleration of every other declared term. Exact for test particles about a fixed star:
    the whole of Spacewar's star is in the drift.

Kernels (``KERNEL_*``): the standard kick, and the lazy implementer's modified kick (Wisdom,
Holman & Touma 1996, Fields Inst. Commun. 10, 217, sec. 4; Rein, Tamayo & Brown 2019, MNRAS
489, 4632, sec. 2.3): the interaction evaluated at positions moved by h^2/12 times the
interaction acceleration, which removes the h^3 error term {{A,B},B}.

Symplectic correctors of order 3, 5, 7, 11 and 17 (Wisdom, Holman & Touma 1996; the order-17
set from Rein, Tamayo & Brown 2019, table 1): the corrector C is applied when a call starts and
its inverse when it ends, each a product of Z(a, b) = D(a) K(-b) D(-2a) K(b) D(a) operators,
with a_k = k sqrt(7/40) h (coefficients as published in those papers).

Other declared terms (drag, thrust, Coulomb, springs) enter through the kick; the method is
then of second order in h for them (its high order in the mass ratio holds only for gravity).
"""
import collections
import functools
import math

import numpy as np
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from ..cache import jit

from ..forces.dispatch import EMPTY_MODEL, accelerations_inline
from ..forces.gravity import NBodyGravity
from ..forces.point_mass import PointMass
from ..space import wrap_scalar
from . import direct as _direct
from .common import OK, all_finite
from ..address_calls import call_at, check_call, entry_address
from .kepler_drift import (INV_R0_ROW, R0_ROW, SCRATCH_ROWS, drift_columns_at,
                           fallback_address)

NAME = "whfast"
ORDER = 2

JACOBI = 0
ATTRACTOR = 1
#: JACOBI with gravity the only declared term: the interaction computed in place, fused
JACOBI_GRAVITY = 2
#: democratic heliocentric coordinates (Duncan, Levison & Lee 1998): heliocentric positions,
#: barycentric velocities, every body drifting about the central mass alone; the kick is
#: jump(h/2) interaction(h) jump(h/2), the jump moving every heliocentric position by
#: h sum_k m_k v_k / m_0
DEMOCRATIC = 3
#: the names of Simulation's ``coordinates``
COORDINATES = ("jacobi", "democratic_heliocentric")

KERNEL_STANDARD = 0
KERNEL_LAZY = 1
KERNELS = {"standard": KERNEL_STANDARD, "lazy": KERNEL_LAZY}

_A1 = math.sqrt(7.0 / 40.0)  # 0.41833001326703777...
# b coefficients of the correctors (Wisdom, Holman & Touma 1996; order 17: Rein, Tamayo &
# Brown 2019), listed from the largest a multiple down to a_1
_B = {
    3: (-0.024900596027799867499350357910273437184309981229127,),
    5: (-0.0083001986759332891664501193034244790614366604097090,
        0.041500993379666445832250596517122395307183302048545),
    7: (0.0024926811426922105779030593952776964450539008582219,
        -0.018270923246702131478062356884535264841652263842597,
        0.053964399093127498721765893493510877532452806339655),
    11: (0.00020361579647854651301632818774633716473696537436847,
         -0.0023487215292295354188307328851055489876255097419754,
         0.012309078592019946317544564763237909911330686448336,
         -0.038121613681288650508647613260247372125243616270670,
         0.072593394748842738674253180742744961827622366521517),
    17: (-0.0000043347415473373580190650223498124944896789841432241,
         0.000076436355227935738363241846979413475106795392377415,
         -0.00063599983075817658983166881625078545864140848560259,
         0.0033132577069380655655490196833451994080066801611459,
         -0.012071760822342291062449751726959664253913904872527,
         0.032422198864713580293681523029577130832258806467604,
         -0.065192863576377893658290760803725762027864651086787,
         0.093056103771425958591541059067553547100903397724386),
}
#: the corrector orders one can ask for (0: none)
CORRECTORS = (0,) + tuple(sorted(_B))


@functools.lru_cache(maxsize=None)
def corrector_table(order):
    """The corrector of ``order`` as rows (a / h, b / h) of its Z operators, in the order they
    are applied (the inverse applies the same rows with b negated). Order 3 is the pair
    Z(a1, -b), Z(-a1, b); the higher orders are Z(-a_k, -b_k) for k from the largest down,
    then Z(a_k, b_k) back up (Wisdom, Holman & Touma 1996, sec. 5)."""
    if order == 0:
        return np.zeros((0, 2))
    bs = _B[order]
    if order == 3:
        return np.array([[_A1, -bs[0]], [-_A1, bs[0]]])
    m = len(bs)
    rows = [[-(m - k) * _A1, -bs[k]] for k in range(m)]
    rows += [[(m - k) * _A1, bs[k]] for k in reversed(range(m))]
    return np.array(rows)


#: the options of the compiled functions only compiled code calls (directly or through their
#: addresses): no wrappers for calls from Python or C, which numba would otherwise build and
#: compile with each (unboxing a ``State`` and a ``Model`` is more code than a drift)
_CALLED = {"no_cpython_wrapper": True, "no_cfunc_wrapper": True}


# -- coordinates ------------------------------------------------------------------------------
@jit(error_model="numpy", inline="always")
def _to_jacobi(pos, vel, m, order, count, jp, jv, eta):
    """Jacobi positions and velocities of the bodies ``order[:count]`` (the first is the
    centre) into ``jp``, ``jv`` (column j for order[j]; column 0 the centre of mass), and the
    interior masses eta_j."""
    dim = pos.shape[0]
    c = order[0]
    e = m[c]
    eta[0] = e
    for k in range(dim):
        jp[k, 0] = m[c] * pos[k, c]  # running mass-weighted sums
        jv[k, 0] = m[c] * vel[k, c]
    for j in range(1, count):
        i = order[j]
        for k in range(dim):
            sx = jp[k, 0]
            sv = jv[k, 0]
            jp[k, j] = pos[k, i] - sx / e
            jv[k, j] = vel[k, i] - sv / e
            jp[k, 0] = sx + m[i] * pos[k, i]
            jv[k, 0] = sv + m[i] * vel[k, i]
        e += m[i]
        eta[j] = e
    for k in range(dim):
        jp[k, 0] /= e
        jv[k, 0] /= e


@jit(error_model="numpy", inline="always")
def _from_jacobi(jp, jv, m, order, count, eta, pos, vel, with_vel):
    """Inertial positions (and velocities) from Jacobi ones (the inverse of ``_to_jacobi``):
    with S_j the mass-weighted sum of the first j + 1 bodies, S_{j-1} = (S_j - m r'_j)
    eta_{j-1} / eta_j and r = r'_j + S_{j-1} / eta_{j-1}."""
    dim = jp.shape[0]
    for k in range(dim):
        s = jp[k, 0] * eta[count - 1]
        sv = jv[k, 0] * eta[count - 1]
        for j in range(count - 1, 0, -1):
            i = order[j]
            s = (s - m[i] * jp[k, j]) / eta[j]
            pos[k, i] = jp[k, j] + s
            s *= eta[j - 1]
            if with_vel:
                sv = (sv - m[i] * jv[k, j]) / eta[j]
                vel[k, i] = jv[k, j] + sv
                sv *= eta[j - 1]
        c = order[0]
        pos[k, c] = s / m[c]
        if with_vel:
            vel[k, c] = sv / m[c]


@jit(error_model="numpy", inline="always")
def _jacobi_accelerations(acc, m, order, count, eta, ja):
    """The Jacobi transform of inertial accelerations (the same map as the positions')."""
    dim = acc.shape[0]
    c = order[0]
    for k in range(dim):
        s = m[c] * acc[k, c]
        for j in range(1, count):
            i = order[j]
            ja[k, j] = acc[k, i] - s / eta[j - 1]
            s += m[i] * acc[k, i]
        ja[k, 0] = s / eta[count - 1]


@jit(error_model="numpy", inline="always")
def _to_democratic(pos, vel, m, order, count, jp, jv, eta):
    """Democratic heliocentric coordinates of the bodies ``order[:count]`` (the first is the
    centre): column 0 the centre of mass and its velocity, column j the position relative to
    the centre and the velocity relative to the centre of mass. ``eta[0]`` is the central
    mass, the other entries the total mass."""
    dim = pos.shape[0]
    c = order[0]
    total = 0.0
    for j in range(count):
        total += m[order[j]]
    for k in range(dim):
        sx = 0.0
        sv = 0.0
        for j in range(count):
            i = order[j]
            sx += m[i] * pos[k, i]
            sv += m[i] * vel[k, i]
        jp[k, 0] = sx / total
        jv[k, 0] = sv / total
        for j in range(1, count):
            i = order[j]
            jp[k, j] = pos[k, i] - pos[k, c]
            jv[k, j] = vel[k, i] - jv[k, 0]
    eta[0] = m[c]
    for j in range(1, count):
        eta[j] = total


@jit(error_model="numpy", inline="always")
def _from_democratic(jp, jv, m, order, count, eta, pos, vel, with_vel):
    """Inertial positions (and velocities) from democratic heliocentric ones: the centre at
    R - sum_j m_j Q_j / M, each body at Q_j from it; the bodies' velocities V + v_j and the
    centre's V - sum_j m_j v_j / m_0 (so the total momentum is M V)."""
    dim = jp.shape[0]
    c = order[0]
    total = eta[count - 1] if count > 1 else eta[0]
    for k in range(dim):
        sx = 0.0
        sv = 0.0
        for j in range(1, count):
            i = order[j]
            sx += m[i] * jp[k, j]
            sv += m[i] * jv[k, j]
        centre = jp[k, 0] - sx / total
        pos[k, c] = centre
        for j in range(1, count):
            pos[k, order[j]] = jp[k, j] + centre
        if with_vel:
            vel[k, c] = jv[k, 0] - sv / eta[0]
            for j in range(1, count):
                vel[k, order[j]] = jv[k, j] + jv[k, 0]


@jit(error_model="numpy", inline="always")
def _jump(jp, jv, mo, count, massive, m0, h):
    """The democratic heliocentric jump: every heliocentric position moves by
    h sum_k m_k v_k / m_0 (the centre's kinetic term, Duncan, Levison & Lee 1998)."""
    dim = jp.shape[0]
    for k in range(dim):
        p = 0.0
        for j in range(1, massive):
            p += mo[0, j] * jv[k, j]
        shift = h * (p / m0)
        for j in range(1, count):
            jp[k, j] += shift


@jit(error_model="numpy", _nrt=False, **_CALLED)
def _democratic_interaction(t, jp, jv, state, kick_model, work, m, order, count, eta, mu, center,
                            acc, ja, kick_com, mo, massive, G, with_vel):
    """The interaction acceleration in democratic heliocentric coordinates: with gravity the
    only term, the pulls among the bodies other than the centre, from the heliocentric
    positions (test particles pulled by the massive ones); otherwise every term at the
    inertial positions, less the centre's pull G m_0 Q_j / |Q_j|^3 (in the Kepler part) and
    less the acceleration of the centre of mass, which moves column 0."""
    dim = jp.shape[0]
    if not kick_com:
        for j in range(count):
            for k in range(dim):
                ja[k, j] = 0.0
        for j in range(1, massive):
            for i in range(j + 1, massive):
                dx = jp[0, i] - jp[0, j]
                dy = jp[1, i] - jp[1, j]
                dz = jp[2, i] - jp[2, j] if dim == 3 else 0.0
                r2 = dx * dx + dy * dy + dz * dz
                f = G / (r2 * math.sqrt(r2))
                fj = f * mo[0, i]
                fi = f * mo[0, j]
                ja[0, j] += fj * dx
                ja[1, j] += fj * dy
                ja[0, i] -= fi * dx
                ja[1, i] -= fi * dy
                if dim == 3:
                    ja[2, j] += fj * dz
                    ja[2, i] -= fi * dz
        for j in range(massive, count):
            for i in range(1, massive):
                dx = jp[0, i] - jp[0, j]
                dy = jp[1, i] - jp[1, j]
                dz = jp[2, i] - jp[2, j] if dim == 3 else 0.0
                r2 = dx * dx + dy * dy + dz * dz
                f = G * mo[0, i] / (r2 * math.sqrt(r2))
                ja[0, j] += f * dx
                ja[1, j] += f * dy
                if dim == 3:
                    ja[2, j] += f * dz
        return
    _from_democratic(jp, jv, m, order, count, eta, state.pos, state.vel, with_vel)
    accelerations_inline(t, state, kick_model, acc, work)
    total = eta[count - 1] if count > 1 else eta[0]
    for k in range(dim):
        s = 0.0
        for j in range(count):
            s += mo[0, j] * acc[k, order[j]]
        ja[k, 0] = s / total
    for j in range(1, count):
        i = order[j]
        r2 = 0.0
        for k in range(dim):
            r2 += jp[k, j] * jp[k, j]
        f = mu[j] / (r2 * math.sqrt(r2))
        for k in range(dim):
            ja[k, j] = acc[k, i] + f * jp[k, j] - ja[k, 0]


# -- calls through addresses ----------------------------------------------------------------------
# A compiled function carries the machine code of every compiled function it calls: numba links
# the callee in, and optimises and translates the whole again for each caller up the chain. The
# step loop, the kicks of each kind of scene, SABA's corrector and the fast loops are therefore
# called through their addresses, chosen in Python for the scene and the scheme (``_addresses``,
# part of ``Plan.kernel_tail``) and passed down in an int64 array: each is compiled once, and
# only when a scene needs it (``python -m engine``'s lone orbit compiles no kick at all; whfast on
# planets none of the general force table). Each slot takes one fixed signature
# (``_slot_types``); the scratch travels as the arrays it is cut from (``columns``, ``rows``),
# so that a call passes few arguments.

#: the slots of the ``addresses`` array: the step loop (``_steps``, in the version for the
#: scene), the fast loop of the common case (0: none), the kick (0: JACOBI_GRAVITY's own,
#: compiled in, or nothing to kick), SABA's corrector (0: none), the Kepler drift
#: (``kepler_drift.drift_columns_at``), the same with |r| known (``_gravity_steps``' drift,
#: 0: no such loop) and the drift's fallback
STEPS, LOOP, KICK, LAZY, DRIFT, DRIFT_KNOWN, FALLBACK = range(7)
_SLOT_NAMES = ("the step loop", "the fast loop", "the kick", "the lazy corrector",
               "the drift", "the drift", "the drift's fallback")


@functools.lru_cache(maxsize=None)
def _slot_types():
    """``(return type, argument types)`` of each slot's functions: the engine's named tuples
    as the force kernels take them (``engine.forces.calls.argument_types``), C-contiguous
    arrays, int64 and float64 numbers."""
    from numba import typeof

    from ..forces.calls import argument_types

    accumulate = argument_types()[0]
    state, work = accumulate[1], accumulate[9]
    model = typeof(EMPTY_MODEL)
    f8, i8, b1 = types.float64, types.int64, types.boolean
    f1, f2, f3 = (types.Array(f8, d, "C") for d in (1, 2, 3))
    i1, bools = types.Array(i8, 1, "C"), types.Array(b1, 1, "C")
    steps = (f8, f8, i8, state, model, work, b1, i8, i1, f1, f8, f8, f1, bools, b1, i8, f2, f1,
             f1, f8, i1, f3, f2, f2, f2, f2, f2)
    loop = (f8, f8, i8, f3, f2, f2, i8, i8, f8, f1, f1, b1, f8, i1)
    kick = (f8, f8, state, model, work, i8, f1, i1, i8, f1, f3, f2, f2, f2, b1, i8, b1, i8, f8)
    lazy = (f8, f8, f8, state, model, work, i8, f1, i1, i8, f1, f3, f2, f2, b1, b1)
    drift = (f2, f2, i8, i8, f1, f8, f2, i8)
    return {STEPS: (types.Tuple((f8, f8, i8, i8)), steps),
            LOOP: (types.Tuple((f8, i8, i8)), loop),
            KICK: (types.none, kick),
            LAZY: (types.none, lazy),
            DRIFT: (types.none, drift)}


def _slot_signature(slot, address, args):
    """The typing of a call of ``slot`` through ``address`` with the tuple ``args``."""
    restype, wanted = _slot_types()[slot]
    given = tuple(args)
    check_call(given, wanted, _SLOT_NAMES[slot])

    def codegen(context, builder, signature, values):
        parts = cgutils.unpack_tuple(builder, values[1], len(given))
        value = call_at(context, builder, values[0], restype, wanted, given, parts)
        return context.get_dummy_value() if restype == types.none else value
    return restype(address, args), codegen


@intrinsic
def _call_steps(typingctx, address, args):
    """``_steps(*args)`` through its address."""
    return _slot_signature(STEPS, address, args)


@intrinsic
def _call_loop(typingctx, address, args):
    """``_gravity_steps(*args)`` or ``_free_steps(*args)`` through its address."""
    return _slot_signature(LOOP, address, args)


@intrinsic
def _call_kick(typingctx, address, args):
    """The scene's kick (``_democratic_kick``, ``_kick``) through its address."""
    return _slot_signature(KICK, address, args)


@intrinsic
def _call_lazy(typingctx, address, args):
    """``_lazy_corrector(*args)`` through its address."""
    return _slot_signature(LAZY, address, args)


@intrinsic
def _call_drift(typingctx, address, args):
    """``drift_columns_at(*args)`` through its address."""
    return _slot_signature(DRIFT, address, args)


@functools.lru_cache(maxsize=None)
def _slot_address(slot, function, *defaults):
    """The address of ``function`` compiled for ``slot``'s signature (compiled on the first
    call in a process, or loaded from the compiled-code cache); ``defaults``: the values of
    its further parameters, compiled in as constants (numba's ``Omitted`` arguments, which
    take no part in a call: the slot's callers pass the slot's arguments alone). numba takes
    True and 1, False and 0, for the same constant (whichever it met first): the code only
    tests these for truth, or against None."""
    restype, wanted = _slot_types()[slot]
    return entry_address(function, restype(*wanted, *map(types.Omitted, defaults)))


@functools.lru_cache(maxsize=None)
def _addresses(free, mode, kernel, one_stage, lazy):
    """The ``addresses`` array of a scene and scheme: ``free`` nothing to kick (ATTRACTOR mode,
    the attractor the only term), ``mode``, the ``kernel`` code, ``one_stage`` one kick a
    step, ``lazy`` SABA's corrector. Made once per combination in a process (each function
    compiled, or loaded from the cache, when first needed); shared, read only."""
    loop = known = 0  # the common cases' own loops (see ``_gravity_steps``)
    if free:
        loop = _slot_address(LOOP, _free_steps)
    elif one_stage and not lazy and mode == JACOBI_GRAVITY and kernel == KERNEL_STANDARD:
        loop = _slot_address(LOOP, _gravity_steps)
        known = _slot_address(DRIFT, drift_columns_at, True)
    kick = 0
    if not free and mode != JACOBI_GRAVITY:
        kick = _slot_address(KICK, _democratic_kick if mode == DEMOCRATIC else _kick)
    corrector = _slot_address(LAZY, _lazy_corrector) if lazy and not free else 0
    # ``_steps``' version for the scene (see there)
    steps = _slot_address(STEPS, _steps, None if free else True)
    return np.array([steps, loop, kick, corrector,
                     _slot_address(DRIFT, drift_columns_at, False), known, fallback_address()],
                    dtype=np.int64)


# -- the two operators ------------------------------------------------------------------------
@jit(error_model="numpy", _nrt=False, **_CALLED)
def _democratic_kick(t, h, state, kick_model, work, mode, m, order, count, center, columns,
                     rows, acc, kw, kick_com, kernel, vdep, massive, G):
    """DEMOCRATIC mode's kick (slot ``KICK``): jump(h/2) interaction(h) jump(h/2);
    velocity-dependent terms at the midpoint velocity, as in the other modes."""
    jp, jv, shifted, ja = columns[0], columns[1], columns[4], columns[5]
    eta, mu = rows[0], rows[1]
    mo = rows[2:]
    dim = jp.shape[0]
    m0 = mo[0, 0]
    _jump(jp, jv, mo, count, massive, m0, 0.5 * h)
    _democratic_interaction(t, jp, jv, state, kick_model, work, m, order, count, eta, mu,
                            center, acc, ja, kick_com, mo, massive, G, vdep)
    if vdep:
        for j in range(count):
            for k in range(dim):
                shifted[k, j] = jv[k, j] + 0.5 * h * ja[k, j]
        _democratic_interaction(t, jp, shifted, state, kick_model, work, m, order, count, eta,
                                mu, center, acc, ja, kick_com, mo, massive, G, True)
    for j in range(count):
        for k in range(dim):
            jv[k, j] += h * ja[k, j]
    _jump(jp, jv, mo, count, massive, m0, 0.5 * h)


@jit(error_model="numpy", inline="always")
def _kepler_drift(mode, jp, jv, mu, count, h, kw, box, addresses):
    """Every moving body along its Kepler orbit for time h (mu[j] = 0: a straight line;
    ``kepler_drift.drift_columns_at`` at ``addresses[DRIFT]``, ``kw`` its scratch); in JACOBI
    mode column 0, the centre of mass, always moves in a straight line. In a periodic space
    (ATTRACTOR mode only) each position relative to the attractor is taken back to its nearest
    image afterwards, the image the attractor's force acts from."""
    dim = jp.shape[0]
    first = 1 if mode != ATTRACTOR else 0
    if mode != ATTRACTOR:
        for k in range(dim):
            jp[k, 0] += h * jv[k, 0]
    _call_drift(addresses[DRIFT], (jp, jv, first, count, mu, h, kw, addresses[FALLBACK]))
    if box > 0.0:
        _wrap_columns(jp, first, count, box)


@jit(error_model="numpy", _nrt=False, **_CALLED)
def _wrap_columns(jp, first, count, box):
    """Columns ``first`` to ``count`` of ``jp`` to their nearest images in a periodic space of
    side ``box`` (called, not inlined into each drift: only a periodic scene takes it)."""
    for j in range(first, count):
        for k in range(jp.shape[0]):
            jp[k, j] = wrap_scalar(jp[k, j], box)


@jit(error_model="numpy", _nrt=False, **_CALLED)  # one copy of the inlined force table
def _interaction(mode, t, jp, state, kick_model, work, m, order, count, eta, mu, center, acc,
                 ja, kick_com):
    """The acceleration of the interaction part at the current positions, per coordinate
    column, into ``ja``: ATTRACTOR mode, every other term's acceleration; JACOBI mode, the
    Jacobi transform of every term's plus G eta_j r'_j / |r'_j|^3 (the Kepler part's own
    attraction, taken out). ``state.pos`` must hold the inertial positions."""
    accelerations_inline(t, state, kick_model, acc, work)
    dim = jp.shape[0]
    if mode == ATTRACTOR:
        for j in range(count):
            i = order[j]
            for k in range(dim):
                ja[k, j] = acc[k, i]
        return
    _jacobi_accelerations(acc, m, order, count, eta, ja)
    if not kick_com:
        for k in range(dim):
            ja[k, 0] = 0.0
    for j in range(1, count):
        if mu[j] > 0.0:
            r2 = 0.0
            for k in range(dim):
                r2 += jp[k, j] * jp[k, j]
            s = mu[j] / (r2 * math.sqrt(r2))
            for k in range(dim):
                ja[k, j] += s * jp[k, j]


@jit(error_model="numpy", _nrt=False, fastmath={"contract"}, **_CALLED)
def _gravity_interaction(jp, mo, count, massive, eta, mu, G, xs, ad, ja, kw):
    """JACOBI_GRAVITY mode's interaction acceleration (``_interaction``'s, for mutual
    gravity alone), on the coordinates' own columns: the inertial positions from the Jacobi
    ones, every body's pull by the first ``massive`` (the massive bodies; ``mo[0]`` the
    masses in column order, ``mo[1]`` the reciprocals of eta), the Jacobi transform, and the
    Kepler part's attraction taken out. Compiled with contracted multiply-adds: each rounds
    once, and the chains of the transforms are shorter. The pair of the centre and the first
    body is left out on both sides, and so is that body's Kepler term: they cancel exactly
    (WH91), and leaving both out keeps the round-off of the largest terms out of the
    interaction (as REBOUND's WHFast does).

    The inertial positions are r_j = r'_j + R_{j-1}, R_j the centre of mass of the first j + 1
    bodies. The Kepler terms take mu / r'^3 as mu (1/r')^3, and leave |r'| and 1/|r'| of
    every column in rows ``R0_ROW``, ``INV_R0_ROW`` of ``kw``, the Kepler drift's scratch,
    for a drift that follows at these positions (``_gravity_step``). Measured on the outer
    solar system (separate processes alternating, this function's changes with the checkpoints
    of ``_gravity_steps`` and the short Stumpff series): a step 319 -> 258 ns; final states
    differ from the previous forms' by round-off (at most 2e-13 of the largest coordinate
    after 3000 steps)."""
    dim = jp.shape[0]
    for k in range(dim):
        # R_{j-1} = R_j - (m_j / eta_j) r'_j, from the centre of mass R_{N-1} (column 0):
        # one multiply-add a body on the chain each step waits for (``_from_jacobi``'s form
        # takes two multiplications and a multiply-add a body, and a division at the end)
        s = jp[k, 0]
        for j in range(count - 1, 0, -1):
            s -= (mo[0, j] * mo[1, j]) * jp[k, j]
            xs[k, j] = jp[k, j] + s
        xs[k, 0] = s
    for j in range(count):
        for k in range(dim):
            ad[k, j] = 0.0
    for j in range(massive):  # pairs of massive bodies, each once (Newton's third law)
        # body j's coordinates and sums held in registers along its row of pairs (the
        # compiler cannot tell ad[:, j] from ad[:, i], and would store and reload them at
        # every pair); the same sums in the same order
        xj = xs[0, j]
        yj = xs[1, j]
        zj = xs[2, j] if dim == 3 else 0.0
        mj = mo[0, j]
        axj = ad[0, j]
        ayj = ad[1, j]
        azj = ad[2, j] if dim == 3 else 0.0
        for i in range(j + 1, massive):
            if i + j == 1:  # the centre and the first body
                continue
            dx = xs[0, i] - xj
            dy = xs[1, i] - yj
            dz = xs[2, i] - zj if dim == 3 else 0.0
            r2 = dx * dx + dy * dy + dz * dz
            f = G / (r2 * math.sqrt(r2))
            fj = f * mo[0, i]
            fi = f * mj
            axj += fj * dx
            ayj += fj * dy
            ad[0, i] -= fi * dx
            ad[1, i] -= fi * dy
            if dim == 3:
                azj += fj * dz
                ad[2, i] -= fi * dz
        ad[0, j] = axj
        ad[1, j] = ayj
        if dim == 3:
            ad[2, j] = azj
    for j in range(massive, count):  # test particles: pulled by the massive bodies alone
        for i in range(massive):
            if i + j == 1:
                continue
            dx = xs[0, i] - xs[0, j]
            dy = xs[1, i] - xs[1, j]
            dz = xs[2, i] - xs[2, j] if dim == 3 else 0.0
            r2 = dx * dx + dy * dy + dz * dz
            f = G * mo[0, i] / (r2 * math.sqrt(r2))
            ad[0, j] += f * dx
            ad[1, j] += f * dy
            if dim == 3:
                ad[2, j] += f * dz
    for k in range(dim):
        s = mo[0, 0] * ad[k, 0]
        for j in range(1, count):
            ja[k, j] = ad[k, j] - s * mo[1, j - 1]
            s += mo[0, j] * ad[k, j]
        ja[k, 0] = 0.0  # mutual gravity does not move the centre of mass
    for j in range(1, count):
        # |r'_j| and its reciprocal, left in the Kepler drift's scratch: a drift that follows
        # with these very positions takes them from there (``drift_columns``' ``known``)
        x = jp[0, j]
        y = jp[1, j]
        z = jp[2, j] if dim == 3 else 0.0
        r0 = math.sqrt(x * x + y * y + z * z)
        inv = 1.0 / r0
        kw[R0_ROW, j] = r0
        kw[INV_R0_ROW, j] = inv
        if j >= 2:
            f = mu[j] * (inv * inv) * inv
            for k in range(dim):
                ja[k, j] += f * jp[k, j]


@jit(error_model="numpy", inline="always")
def _from_attractor(jp, jv, order, count, center, pos, vel, with_vel, box):
    """ATTRACTOR mode's inertial positions (and velocities): the attractor's position added,
    in a periodic space the nearest image taken."""
    for j in range(count):
        i = order[j]
        for k in range(jp.shape[0]):
            pos[k, i] = wrap_scalar(jp[k, j] + center[k], box)
            if with_vel:
                vel[k, i] = jv[k, j]


@jit(error_model="numpy", _nrt=False, **_CALLED)
def _sync_positions(mode, jp, jv, m, order, count, eta, center, pos, vel, with_vel, box):
    """Inertial positions (and velocities) in ``pos``, ``vel`` from the coordinates."""
    if mode == DEMOCRATIC:
        _from_democratic(jp, jv, m, order, count, eta, pos, vel, with_vel)
        return
    if mode != ATTRACTOR:
        _from_jacobi(jp, jv, m, order, count, eta, pos, vel, with_vel)
        return
    _from_attractor(jp, jv, order, count, center, pos, vel, with_vel, box)


@jit(error_model="numpy", inline="always")
def _sync_kicked(mode, jp, jv, m, order, count, eta, center, pos, vel, with_vel, box):
    """``_sync_positions`` for the modes ``_kick`` and ``_lazy_corrector`` take (ATTRACTOR,
    JACOBI, JACOBI_GRAVITY), inlined: a call to it in each kick cost 10 ns, measured (3% of a
    step of two particles with drag about a star)."""
    if mode != ATTRACTOR:
        _from_jacobi(jp, jv, m, order, count, eta, pos, vel, with_vel)
    else:
        _from_attractor(jp, jv, order, count, center, pos, vel, with_vel, box)


@jit(error_model="numpy", inline="always")
def _sync(kicking, mode, jp, jv, m, order, count, eta, center, pos, vel, with_vel, box):
    """``_sync_positions``; ``kicking`` None (see ``_steps``): ATTRACTOR mode's alone."""
    if kicking is not None:
        _sync_positions(mode, jp, jv, m, order, count, eta, center, pos, vel, with_vel, box)
    else:
        _from_attractor(jp, jv, order, count, center, pos, vel, with_vel, box)


@jit(error_model="numpy", inline="always")
def _gravity_kick(h, kernel, count, massive, G, columns, rows, kw):
    """JACOBI_GRAVITY mode's kick: v' += h a'_interaction, a' by ``_gravity_interaction``;
    the lazy kernel evaluates a' at positions moved by h^2/12 a' first. Inlined into the
    step loop (a kick in a function of its own, called, cost 19 ns more, measured: 4% of a
    SABA step of three planets)."""
    jp, jv, shifted, ja = columns[0], columns[1], columns[4], columns[5]
    xs, ad = columns[7], columns[8]
    eta, mu = rows[0], rows[1]
    mo = rows[2:]
    dim = jp.shape[0]
    _gravity_interaction(jp, mo, count, massive, eta, mu, G, xs, ad, ja, kw)
    if kernel == KERNEL_LAZY:
        eps = h * h / 12.0
        for j in range(count):
            for k in range(dim):
                shifted[k, j] = jp[k, j] + (eps * ja[k, j] if j >= 1 else 0.0)
        _gravity_interaction(shifted, mo, count, massive, eta, mu, G, xs, ad, ja, kw)
    for j in range(count):
        for k in range(dim):
            jv[k, j] += h * ja[k, j]


@jit(error_model="numpy", _nrt=False, **_CALLED)
def _kick(t, h, state, kick_model, work, mode, m, order, count, center, columns, rows, acc, kw,
          kick_com, kernel, vdep, massive, G):
    """The kick of ATTRACTOR mode (with terms besides the attractor) and JACOBI mode (slot
    ``KICK``): v' += h a'_interaction; the lazy kernel evaluates a' at positions moved by
    h^2/12 a' first. With velocity-dependent terms the acceleration is taken at the
    velocities half way through the kick (explicit midpoint; the lazy kernel then does not
    apply)."""
    jp, jv, shifted, ja = columns[0], columns[1], columns[4], columns[5]
    eta, mu = rows[0], rows[1]
    dim = jp.shape[0]
    pos = state.pos
    vel = state.vel
    _sync_kicked(mode, jp, jv, m, order, count, eta, center, pos, vel, vdep, state.box)
    _interaction(mode, t, jp, state, kick_model, work, m, order, count, eta, mu, center, acc,
                 ja, kick_com)
    if vdep:
        # a velocity-dependent term: the kick's acceleration taken at the velocity half way
        # through it (the explicit midpoint rule), so that the kick stays second order
        for j in range(count):
            for k in range(dim):
                shifted[k, j] = jv[k, j] + 0.5 * h * ja[k, j]
        _sync_kicked(mode, jp, shifted, m, order, count, eta, center, pos, vel, True, state.box)
        _interaction(mode, t, jp, state, kick_model, work, m, order, count, eta, mu, center,
                     acc, ja, kick_com)
    elif kernel == KERNEL_LAZY:
        eps = h * h / 12.0
        first = 1 if mode != ATTRACTOR else 0
        for j in range(count):
            for k in range(dim):
                shifted[k, j] = jp[k, j] + (eps * ja[k, j] if j >= first else 0.0)
        _sync_kicked(mode, shifted, jv, m, order, count, eta, center, pos, vel, False,
                     state.box)
        _interaction(mode, t, shifted, state, kick_model, work, m, order, count, eta, mu,
                     center, acc, ja, kick_com)
    for j in range(count):
        for k in range(dim):
            jv[k, j] += h * ja[k, j]


@jit(error_model="numpy", inline="always")
def _kick_at(addresses, t, h, state, kick_model, work, mode, m, order, count, center, columns,
             rows, acc, kw, kick_com, kernel, vdep, massive, G):
    """The scene's kick: the one at ``addresses[KICK]``, or (0) JACOBI_GRAVITY's, compiled
    in."""
    if addresses[KICK] == 0:
        _gravity_kick(h, kernel, count, massive, G, columns, rows, kw)
    else:
        _call_kick(addresses[KICK], (t, h, state, kick_model, work, mode, m, order, count, center,
                                     columns, rows, acc, kw, kick_com, kernel, vdep, massive, G))


@jit(error_model="numpy", _nrt=False, **_CALLED)
def _corrector(table, sign, h, t, state, kick_model, work, mode, m, order, count, center,
               columns, rows, acc, kw, kick_com, vdep, massive, G, addresses):
    """The corrector (sign 1) or its inverse (sign -1): Z(a, b) = D(a) K(-b) D(-2a) K(b) D(a)
    for each row (a / h, b / h) of ``table``; the kicks with the standard kernel. A scene
    with nothing to kick has none (each Z(a, b) would be the identity): ``_steps`` does not
    call it then."""
    jp, jv = columns[0], columns[1]
    mu = rows[1]
    for row in range(table.shape[0]):
        a = table[row, 0] * h
        b = sign * table[row, 1] * h
        _kepler_drift(mode, jp, jv, mu, count, a, kw, state.box, addresses)
        _kick_at(addresses, t, -b, state, kick_model, work, mode, m, order, count, center,
                 columns, rows, acc, kw, kick_com, KERNEL_STANDARD, vdep, massive, G)
        _kepler_drift(mode, jp, jv, mu, count, -2.0 * a, kw, state.box, addresses)
        _kick_at(addresses, t, b, state, kick_model, work, mode, m, order, count, center,
                 columns, rows, acc, kw, kick_com, KERNEL_STANDARD, vdep, massive, G)
        _kepler_drift(mode, jp, jv, mu, count, a, kw, state.box, addresses)


@jit(error_model="numpy", inline="always")
def _first_bad_column(jp, jv, count):
    for j in range(count):
        for k in range(jp.shape[0]):
            if not (math.isfinite(jp[k, j]) and math.isfinite(jv[k, j])):
                return j
    return 0


@jit(error_model="numpy", inline="always")
def _coordinates(kicking, mode, pos, vel, m, order, count, center, jp, jv, eta, box):
    """The coordinates of the inertial state; ``kicking`` None (see ``_steps``): ATTRACTOR
    mode's, relative to the attractor, alone."""
    dim = pos.shape[0]
    if kicking is not None:
        if mode == DEMOCRATIC:
            _to_democratic(pos, vel, m, order, count, jp, jv, eta)
            return
        if mode != ATTRACTOR:
            _to_jacobi(pos, vel, m, order, count, jp, jv, eta)
            return
    for j in range(count):
        i = order[j]
        for k in range(dim):
            jp[k, j] = wrap_scalar(pos[k, i] - center[k], box)
            jv[k, j] = vel[k, i]


@jit(error_model="numpy", inline="always")
def kepler_parameters(mode, m, order, count, eta, G, mu_attractor, attracted, mu):
    """mu per coordinate column: G eta_j in JACOBI mode (0 for the centre of mass), the
    attractor's mu for the particles it acts on in ATTRACTOR mode (else 0)."""
    for j in range(count):
        if mode == DEMOCRATIC:
            mu[j] = 0.0 if j == 0 else G * eta[0]
        elif mode != ATTRACTOR:
            mu[j] = 0.0 if j == 0 else G * eta[j]
        else:
            mu[j] = mu_attractor if attracted[order[j]] else 0.0


@jit(error_model="numpy", _nrt=False, **_CALLED)
def _lazy_corrector(cc, h, t, state, kick_model, work, mode, m, order, count, center, columns,
                    rows, acc, kick_com, vdep):
    """SABA's corrector exp(cc h^3 L_{{A,B},B}) by the lazy implementer's difference
    (Wisdom, Holman & Touma 1996, eq. 10.6; Rein, Tamayo & Brown 2019, sec. 2.3):
    v' += 12 cc h (a'(r' + h^2/12 a') - a'(r')), the positions left where they were (slot
    ``LAZY``; a scene with no interaction has none: zero)."""
    jp, jv, shifted, ja, ja0 = columns[0], columns[1], columns[4], columns[5], columns[6]
    eta, mu = rows[0], rows[1]
    dim = jp.shape[0]
    pos = state.pos
    vel = state.vel
    _sync_kicked(mode, jp, jv, m, order, count, eta, center, pos, vel, vdep, state.box)
    _interaction(mode, t, jp, state, kick_model, work, m, order, count, eta, mu, center, acc,
                 ja0, kick_com)
    eps = h * h / 12.0
    first = 1 if mode != ATTRACTOR else 0
    for j in range(count):
        for k in range(dim):
            shifted[k, j] = jp[k, j] + (eps * ja0[k, j] if j >= first else 0.0)
    _sync_kicked(mode, shifted, jv, m, order, count, eta, center, pos, vel, False, state.box)
    _interaction(mode, t, shifted, state, kick_model, work, m, order, count, eta, mu, center,
                 acc, ja, kick_com)
    f = 12.0 * cc * h
    for j in range(first, count):
        for k in range(dim):
            jv[k, j] += f * (ja[k, j] - ja0[k, j])


@jit(error_model="numpy", inline="always")
def _lazy(kicking, lazy, cc, h, t, state, kick_model, work, mode, m, order, count, center,
          columns, rows, acc, kick_com, vdep):
    """SABA's corrector with coefficient ``cc``, when the scene has one (``lazy`` its address,
    0: none; ``kicking`` None: nothing to kick, so zero, see ``_steps``)."""
    if kicking is not None:
        if lazy != 0:
            _call_lazy(lazy, (cc, h, t, state, kick_model, work, mode, m, order, count, center,
                              columns, rows, acc, kick_com, vdep))


@jit(error_model="numpy")
def advance(t, h, steps, state, kick_model, work, vdep, t_end, mode, order, m, G, mu_attractor,
            center, attracted, kick_com, kernel, corrector, drifts, kicks, cc, addresses):
    """``steps`` steps of ``h`` of the splitting ``drifts[0] kicks[0] drifts[1] ... kicks[S-1]
    drifts[S]`` (fractions of h; Kepler drifts, interaction kicks; see the module).

    ``order`` lists the particles that move, the centre first in JACOBI mode; ``m`` the
    masses the coordinates use (test particles 0); ``attracted[i]`` whether the attractor acts
    on particle i (ATTRACTOR mode); ``corrector`` the symplectic corrector's table
    (``corrector_table``), applied when the call starts and undone when it ends; ``cc`` the
    coefficient of SABA's lazy corrector applied at both ends of every step (0: none);
    ``addresses`` the compiled functions the scene and scheme use (``_addresses``). The
    last drift of a step and the first of the next are merged when no corrector stands
    between them. Returns ``(t, h, done, status)`` as every integrator does; on a non-finite
    state the last finite one is restored, synchronised."""
    pos = state.pos
    vel = state.vel
    dim = pos.shape[0]
    count = order.shape[0]
    if count == 0 or steps == 0:
        return t, h, 0, OK
    # every scratch array made here, once: the loop runs without reference counting (the
    # columns' arrays cut from one allocation: a fresh call allocates little)
    columns = np.empty((9, dim, count))
    rows = np.empty((4, count))
    acc = np.empty((dim, state.n))
    kw = np.empty((SCRATCH_ROWS, max(count, dim)))  # the Kepler drift's
    first_p = pos.copy()  # the call's starting state: kept bit for bit if its first step fails
    first_v = vel.copy()
    return _call_steps(addresses[STEPS], (
        t, h, steps, state, kick_model, work, vdep, mode, order, m, G, mu_attractor, center,
        attracted, kick_com, kernel, corrector, drifts, kicks, cc, addresses, columns, rows,
        acc, kw, first_p, first_v))


@jit(error_model="numpy", inline="always")
def _save_columns(jp, jv, save_p, save_v, count):
    """The coordinates a step starts from, kept: a step that fails is undone from them."""
    for j in range(count):
        for k in range(jp.shape[0]):
            save_p[k, j] = jp[k, j]
            save_v[k, j] = jv[k, j]


#: steps between the saved states of ``_gravity_steps`` and ``_free_steps``: a step that fails
#: is found again from the last saved state (see ``_gravity_steps``)
CHECKPOINT_STEPS = 64


@jit(error_model="numpy", inline="always")
def _gravity_step(jp, jv, mo, count, massive, eta, mu, G, xs, ad, ja, kw, kick, d, addresses):
    """One step of ``_gravity_steps``: the interaction's kick, then the drift ``d`` (the one
    compiled with ``known`` True, a constant; ``_addresses``)."""
    dim = jp.shape[0]
    _gravity_interaction(jp, mo, count, massive, eta, mu, G, xs, ad, ja, kw)
    for k in range(dim):  # by rows: 258-263 -> 247-254 ns a step, against by columns
        for j in range(count):
            jv[k, j] += kick * ja[k, j]
    for k in range(dim):
        jp[k, 0] += d * jv[k, 0]
    _call_drift(addresses[DRIFT_KNOWN], (jp, jv, 1, count, mu, d, kw, addresses[FALLBACK]))


@jit(error_model="numpy", _nrt=False, **_CALLED)
def _gravity_steps(t, h, steps, columns, rows, kw, count, massive, G, kicks, drifts, split, box,
                   addresses):
    """``_steps``' loop for its most common case (mutual gravity alone, the standard kernel,
    one kick a step and no corrector between steps: ``whfast`` on planets; slot ``LOOP``),
    the same operations in the same order, so the same bits. Returns ``(t, done, bad)``,
    ``bad`` the first column that is not finite after the step that failed (-1: none), and
    then the state that step started from in ``save_p``, ``save_v``, as ``_steps`` keeps it.

    Why a loop of its own: inside ``_steps``, which takes every mode, scheme and corrector, the
    same step of the outer solar system ran slower than in this small function (642 against
    510 ns in a quiet stretch, 3-13% more in seven slow ones, one pair the other way; separate
    processes, alternating): the large function's loop pays for its generality on every step.

    The state is saved every ``CHECKPOINT_STEPS`` steps, not every step: when a step fails,
    the steps from the last save to it are taken again, the same operations on the same
    numbers, so the state the failing step started from is found bit for bit at a cost paid
    only on failure."""
    jp, jv, save_p, save_v = columns[0], columns[1], columns[2], columns[3]
    ja, xs, ad = columns[5], columns[7], columns[8]
    eta, mu = rows[0], rows[1]
    mo = rows[2:]
    kick = kicks[0] * h
    merged = (drifts[1] + drifts[0]) * h  # the last drift of a step and the first of the next
    last = drifts[1] * h
    done = 0
    since = CHECKPOINT_STEPS
    for step in range(steps):
        if since == CHECKPOINT_STEPS:
            _save_columns(jp, jv, save_p, save_v, count)
            since = 0
        d = last if step == steps - 1 else merged
        _gravity_step(jp, jv, mo, count, massive, eta, mu, G, xs, ad, ja, kw, kick, d,
                      addresses)
        since += 1
        if not all_finite(jp, jv, count):
            bad = _first_bad_column(jp, jv, count)
            _save_columns(save_p, save_v, jp, jv, count)
            for _ in range(since - 1):  # the steps before the failing one: none was the last
                _gravity_step(jp, jv, mo, count, massive, eta, mu, G, xs, ad, ja, kw, kick,
                              merged, addresses)
            _save_columns(jp, jv, save_p, save_v, count)
            return t, done, bad
        t = t + h
        done += 1
    return t, done, -1


@jit(error_model="numpy", inline="always")
def _free_step(jp, jv, mu, count, h, drifts, final, split, kw, box, addresses):
    """One step of ``_free_steps``: its drifts, the last merged with the next step's first
    unless the step is the call's ``final`` one or SABA's corrector stands between them
    (``split``), as ``_steps`` takes them."""
    stages = drifts.shape[0] - 1
    for s in range(1, stages):
        _kepler_drift(ATTRACTOR, jp, jv, mu, count, drifts[s] * h, kw, box, addresses)
    last = drifts[stages]
    d = last * h if final or split else (last + drifts[0]) * h
    _kepler_drift(ATTRACTOR, jp, jv, mu, count, d, kw, box, addresses)
    if split and not final:
        _kepler_drift(ATTRACTOR, jp, jv, mu, count, drifts[0] * h, kw, box, addresses)


@jit(error_model="numpy", _nrt=False, **_CALLED)
def _free_steps(t, h, steps, columns, rows, kw, count, massive, G, kicks, drifts, split, box,
                addresses):
    """``_steps``' loop when nothing is kicked (ATTRACTOR mode, the attractor the only term:
    test particles about a star, a lone Kepler orbit; slot ``LOOP``): each step its Kepler
    drifts per column (SABA's corrector, ``split``, and the symplectic correctors are zero
    without an interaction, but SABA's keeps a step's last drift apart from the next one's
    first), as ``_gravity_steps`` for its case, with its saved states every
    ``CHECKPOINT_STEPS`` steps."""
    jp, jv, save_p, save_v = columns[0], columns[1], columns[2], columns[3]
    mu = rows[1]
    done = 0
    since = CHECKPOINT_STEPS
    for step in range(steps):
        if since == CHECKPOINT_STEPS:
            _save_columns(jp, jv, save_p, save_v, count)
            since = 0
        _free_step(jp, jv, mu, count, h, drifts, step == steps - 1, split, kw, box, addresses)
        since += 1
        if not all_finite(jp, jv, count):
            bad = _first_bad_column(jp, jv, count)
            _save_columns(save_p, save_v, jp, jv, count)
            for _ in range(since - 1):
                _free_step(jp, jv, mu, count, h, drifts, False, split, kw, box, addresses)
            _save_columns(jp, jv, save_p, save_v, count)
            return t, done, bad
        t = t + h
        done += 1
    return t, done, -1


@jit(error_model="numpy", _nrt=False, **_CALLED)
def _steps(t, h, steps, state, kick_model, work, vdep, mode, order, m, G, mu_attractor, center,
           attracted, kick_com, kernel, corrector, drifts, kicks, cc, addresses, columns, rows,
           acc, kw, first_p, first_v, kicking=None):
    """``advance``'s work in the scratch it made (slot ``STEPS``), compiled without reference
    counting (it allocates nothing), as are the operators it calls: a call passing a dozen
    arrays would otherwise pay two atomic updates per array, more than a small system's
    physics. ``columns`` holds the coordinates' arrays (positions, velocities, their saved
    copies, shifted positions, two interaction accelerations, and JACOBI_GRAVITY's inertial
    positions and accelerations), ``rows`` eta, mu, and the masses and 1 / eta by column.

    ``kicking`` is None or True, a constant compiled in (``_slot_address``'s ``defaults``):
    None for a scene with nothing to kick (ATTRACTOR mode, the attractor the only term), whose
    version has no kicks or correctors, the branches on it taken out before the code is typed
    (numba prunes a test of an argument against None, not against another constant). So the
    lone orbit of ``python -m engine`` compiles no kick, corrector or force table; the other
    scenes share one version (one for each mode compiled 8 s more for a process with
    several, to save 2 s for one with a single mode, measured)."""
    pos = state.pos
    vel = state.vel
    dim = pos.shape[0]
    count = order.shape[0]
    stages = kicks.shape[0]
    jp, jv, save_p, save_v = columns[0], columns[1], columns[2], columns[3]
    eta, mu = rows[0], rows[1]
    mo = rows[2:]
    lazy = addresses[LAZY]
    massive = 0
    for j in range(count):
        mo[0, j] = m[order[j]] if mode != ATTRACTOR else 0.0
        if mo[0, j] > 0.0:
            massive = j + 1  # the massive bodies come first
    t0 = t
    _coordinates(kicking, mode, pos, vel, m, order, count, center, jp, jv, eta, state.box)
    kepler_parameters(mode, m, order, count, eta, G, mu_attractor, attracted, mu)
    for j in range(count):
        mo[1, j] = 1.0 / eta[j] if mode != ATTRACTOR else 0.0
    if kicking is not None:
        _corrector(corrector, 1.0, h, t, state, kick_model, work, mode, m, order, count, center,
                   columns, rows, acc, kw, kick_com, vdep, massive, G, addresses)
    if cc != 0.0:
        _lazy(kicking, lazy, cc, h, t, state, kick_model, work, mode, m, order, count, center,
              columns, rows, acc, kick_com, vdep)
    _kepler_drift(mode, jp, jv, mu, count, drifts[0] * h, kw, state.box, addresses)
    done = 0
    status = OK
    if not all_finite(jp, jv, count):  # after this, each step's end is checked
        status = order[_first_bad_column(jp, jv, count)]
        steps = 0
    # the two common cases take their own loops (see there; ``_addresses`` gives
    # ``_gravity_steps`` only with no SABA corrector and one kick a step, ``_free_steps`` to
    # every scene with nothing to kick); the loop below takes the rest
    loop = addresses[LOOP]
    bad = -1
    if loop != 0 and status == OK:
        t, done, bad = _call_loop(loop, (t, h, steps, columns, rows, kw, count, massive, G,
                                         kicks, drifts, cc != 0.0, state.box, addresses))
        steps = 0
    if bad >= 0:
        status = order[bad]
    # a scene with nothing to kick has had all its steps in ``_free_steps``: its version of this
    # function has no loop here
    if kicking is not None:
        for step in range(steps):
            _save_columns(jp, jv, save_p, save_v, count)
            elapsed = drifts[0]
            for s in range(stages):
                _kick_at(addresses, t + elapsed * h, kicks[s] * h, state, kick_model, work,
                         mode, m, order, count, center, columns, rows, acc, kw, kick_com, kernel,
                         vdep, massive, G)
                if s < stages - 1:
                    _kepler_drift(mode, jp, jv, mu, count, drifts[s + 1] * h, kw, state.box,
                                  addresses)
                    elapsed += drifts[s + 1]
            last = drifts[stages]
            if step == steps - 1 or cc != 0.0:
                _kepler_drift(mode, jp, jv, mu, count, last * h, kw, state.box, addresses)
                if cc != 0.0:
                    _lazy(kicking, lazy, cc if step == steps - 1 else 2.0 * cc, h, t + h, state,
                          kick_model, work, mode, m, order, count, center, columns, rows, acc,
                          kick_com, vdep)
                    if step < steps - 1:
                        _kepler_drift(mode, jp, jv, mu, count, drifts[0] * h, kw, state.box,
                                      addresses)
            else:
                _kepler_drift(mode, jp, jv, mu, count, (last + drifts[0]) * h, kw, state.box,
                              addresses)
            if not all_finite(jp, jv, count):
                status = order[_first_bad_column(jp, jv, count)]
                break
            t = t + h
            done += 1
    if status == OK:
        if kicking is not None:
            _corrector(corrector, -1.0, h, t, state, kick_model, work, mode, m, order, count,
                       center, columns, rows, acc, kw, kick_com, vdep, massive, G, addresses)
        _sync(kicking, mode, jp, jv, m, order, count, eta, center, pos, vel, True, state.box)
        if all_finite(pos, vel, state.n):
            return t, h, done, OK
        status = order[0]
        done -= 1  # the inverse corrector failed: back to the last step's start
        t = t - h
    if done > 0:
        # the last finite state: the step that failed began one first drift (and, with SABA's
        # corrector, one corrector) after it
        for j in range(count):
            for k in range(dim):
                jp[k, j] = save_p[k, j]
                jv[k, j] = save_v[k, j]
        _kepler_drift(mode, jp, jv, mu, count, -drifts[0] * h, kw, state.box, addresses)
        if cc != 0.0:
            _lazy(kicking, lazy, -cc, h, t, state, kick_model, work, mode, m, order, count,
                  center, columns, rows, acc, kick_com, vdep)
        if kicking is not None:
            _corrector(corrector, -1.0, h, t, state, kick_model, work, mode, m, order, count,
                       center, columns, rows, acc, kw, kick_com, vdep, massive, G, addresses)
        _sync(kicking, mode, jp, jv, m, order, count, eta, center, pos, vel, True, state.box)
        if all_finite(pos, vel, state.n):
            return t, h, done, status
    for k in range(dim):  # nothing finite to stop at after the start: the start, unchanged
        for i in range(pos.shape[1]):
            pos[k, i] = first_p[k, i]
            vel[k, i] = first_v[k, i]
    return t0, h, 0, status


# -- the schemes: Wisdom-Holman and the SABA family -----------------------------------------------
#: drift and kick coefficients (fractions of h) of ``whfast``: drift-kick-drift
WH = ((0.5, 0.5), (1.0,))
_WH_DRIFTS = np.array(WH[0])
_WH_KICKS = np.array(WH[1])
_NO_CORRECTOR = corrector_table(0)


def _symmetric(half_drifts, half_kicks, stages):
    """The full drift (stages + 1) and kick (stages) sequences from their first halves."""
    drifts = [half_drifts[min(j, stages - j)] for j in range(stages + 1)]
    kicks = [half_kicks[min(j, stages - 1 - j)] for j in range(stages)]
    return tuple(drifts), tuple(kicks)


_S15 = math.sqrt(15.0)
_R30 = math.sqrt(30.0)
_P = math.sqrt(525.0 + 70.0 * _R30)
_M = math.sqrt(525.0 - 70.0 * _R30)
#: SABA(n) of Laskar & Robutel 2001 (Celest. Mech. Dyn. Astron. 80, 39), table 1: the kicks at
#: the Gauss-Legendre nodes with their weights; and the generalised-order methods SABA(10,4),
#: SABA(8,6,4), SABA(10,6,4) of Blanes, Casas, Farres, Laskar, Makazaga & Murua 2013 (Appl.
#: Numer. Math. 68, 58), table 3, as REBOUND lists them (Rein, Tamayo & Brown 2019): name ->
#: (first half of the drifts, first half of the kicks, stages, error orders in h)
_SABA_HALVES = {
    "SABA1": ((0.5,), (1.0,), 1, (2,)),
    "SABA2": ((0.5 - math.sqrt(3.0) / 6.0, math.sqrt(3.0) / 3.0), (0.5,), 2, (4, 2)),
    "SABA3": ((0.5 - _S15 / 10.0, _S15 / 10.0), (5.0 / 18.0, 4.0 / 9.0), 3, (6, 2)),
    "SABA4": ((0.5 - _P / 70.0, (_P - _M) / 70.0, _M / 35.0),
              (0.25 - _R30 / 72.0, 0.25 + _R30 / 72.0), 4, (8, 2)),
    "SABA(10,4)": ((0.04706710064597250612947887637243678556564,
                    0.1847569354170881069247376193702560968574,
                    0.2827060056798362053243616565541452479160,
                    -0.01453004174289681837857815229683813033908),
                   (0.1188819173681970199453503950853885936957,
                    0.2410504605515015657441667865901651105675,
                    -0.2732866667053238060543113981664559460630,
                    0.8267085775712504407295884329818044835997), 7, (10, 4)),
    "SABA(8,6,4)": ((0.0711334264982231177779387300061549964174,
                     0.241153427956640098736487795326289649618,
                     0.521411761772814789212136078067994229991,
                     -0.333698616227678005726562603400438876027),
                    (0.183083687472197221961703757166430291072,
                     0.310782859898574869507522291054262796375,
                     -0.0265646185119588006972121379164987592663,
                     0.0653961422823734184559721793911134363710), 7, (8, 6, 4)),
    "SABA(10,6,4)": ((0.03809449742241219545697532230863756534060,
                      0.1452987161169137492940200726606637497442,
                      0.2076276957255412507162056113249882065158,
                      0.4359097036515261592231548624010651844006,
                      -0.6538612258327867093807117373907094120024),
                     (0.09585888083707521061077150377145884776921,
                      0.2044461531429987806805077839164344779763,
                      0.2170703479789911017143385924306336714532,
                      -0.01737538195906509300561788011852699719871), 8, (10, 6, 4)),
}
#: the lazy corrector's coefficient of SABAC1-4 (Laskar & Robutel 2001, table 2: g/2 with
#: their g; the signs as REBOUND applies them)
_SABA_CORRECTOR = {"SABAC1": 1.0 / 12.0, "SABAC2": 0.01116454968463011276968973577058865137738,
                   "SABAC3": 0.005634593363122809402267823769797538671562,
                   "SABAC4": 0.003396775048208601331532157783492144}
#: every SABA method by name; ``Simulation(integrator="saba", saba="SABA(10,6,4)")``
SABA_METHODS = tuple(_SABA_HALVES) + tuple(_SABA_CORRECTOR)
DEFAULT_SABA = "SABA(10,6,4)"


@functools.lru_cache(maxsize=None)
def saba_scheme(name):
    """``(drifts, kicks, cc)`` of a SABA method: the drift and kick fractions of h and the
    lazy corrector's coefficient (0 without); the arrays are shared: read them only."""
    if name not in SABA_METHODS:
        raise ValueError(f"saba must be one of {', '.join(SABA_METHODS)}, got {name!r}")
    cc = _SABA_CORRECTOR.get(name, 0.0)
    base = "SABA" + name[5:] if cc else name
    half_drifts, half_kicks, stages, _ = _SABA_HALVES[base]
    drifts, kicks = _symmetric(half_drifts, half_kicks, stages)
    return np.array(drifts), np.array(kicks), cc


# -- the plan: which bodies, which coordinates (Python, once per call) ---------------------------
#: JACOBI mode needs the heaviest body to carry at least this many times the rest's mass
#: (more than two massive bodies; with two, the Kepler drift is the whole motion)
DOMINANCE = 10.0


_NO_MASSES = np.zeros(1)


@jit()
def _attractor_columns(active, pinned, indices, n):
    """ATTRACTOR mode's columns in one compiled pass (a plan is made on a simulation's first
    call, where a dozen small numpy calls would cost more than the steps): the moving
    particles (active, not pinned) in index order, and whether the attractor acts on each
    particle (``indices`` empty: on all)."""
    order = np.empty(n, dtype=np.int64)
    count = 0
    for i in range(n):
        if active[i] and not pinned[i]:
            order[count] = i
            count += 1
    attracted = np.empty(max(n, 1), dtype=np.bool_)
    attracted[:] = indices.shape[0] == 0
    for i in indices:
        attracted[i] = True
    return order[:count].copy(), attracted


@jit()
def _jacobi_columns(active, pinned, test, mass, n):
    """JACOBI mode's columns in one compiled pass: ``(order, masses, heaviest, rest, massive,
    pinned_active)``: the heaviest moving body first (ties: the lowest index), the other
    massive ones in index order, then the moving massless ones; the masses the coordinates
    use (test particles 0); the heaviest body's index (-1: none has mass), the other massive
    bodies' total and the number of massive moving bodies; the first active pinned particle
    (-1: none)."""
    masses = np.empty(n)
    heaviest = -1
    pinned_active = -1
    massive = 0
    total = 0.0
    for i in range(n):
        masses[i] = 0.0 if test[i] else mass[i]
        if active[i] and pinned[i] and pinned_active < 0:
            pinned_active = i
        if active[i] and not pinned[i] and masses[i] > 0.0:
            total += masses[i]
            massive += 1
            if heaviest < 0 or masses[i] > masses[heaviest]:
                heaviest = i
    order = np.empty(n, dtype=np.int64)
    count = 0
    if heaviest >= 0:
        order[0] = heaviest
        count = 1
    for weighs in (True, False):
        for i in range(n):
            if active[i] and not pinned[i] and i != heaviest and (masses[i] > 0.0) == weighs:
                order[count] = i
                count += 1
    rest = total - masses[heaviest] if heaviest >= 0 else 0.0
    return order[:count].copy(), masses, heaviest, rest, massive, pinned_active


class Plan:
    """What ``advance`` needs beyond the state: built by ``plan`` from a simulation's terms."""

    def __init__(self, mode, order, masses, G, mu, center, attracted, kick_model, kick_com):
        self.mode, self.order, self.masses, self.G = mode, order, masses, G
        self.mu, self.center, self.attracted = mu, center, attracted
        self.kick_model, self.kick_com = kick_model, kick_com
        self._tails = {}

    def kernel_tail(self, name, corrector, kernel, saba):
        """The arguments of ``advance`` after ``t_end`` for integrator ``name`` (``whfast``
        with ``corrector`` and ``kernel``, or ``saba`` with method ``saba``), converted to the
        types its compiled version takes, the last the addresses of the compiled functions the
        scene and scheme use (``_addresses``: compiled, or loaded, on their first use in the
        process); made once per plan and setting, since a simulation stepping in short calls
        would otherwise rebuild them every call."""
        key = (name, corrector, kernel, saba)
        tail = self._tails.get(key)
        if tail is None:
            if self.mode == DEMOCRATIC and (name == "saba" or corrector != 0
                                            or kernel != "standard"):
                raise ValueError(
                    "democratic heliocentric coordinates take whfast's standard kernel without "
                    f"corrector (got integrator={name!r}, corrector={corrector!r}, "
                    f"kernel={kernel!r}): the correctors, the lazy kernel and SABA are built for "
                    "Jacobi coordinates; nothing was changed")
            scheme = _scheme_tail(*key)
            kernel_code, _, _, kicks, cc = scheme
            free = self.mode == ATTRACTOR and self.kick_model.kinds.shape[0] == 0
            addresses = _addresses(free, int(self.mode), kernel_code, kicks.shape[0] == 1,
                                   cc != 0.0)
            tail = (int(self.mode), self.order, self.masses, float(self.G), float(self.mu),
                    self.center, self.attracted, bool(self.kick_com)) + scheme + (addresses,)
            self._tails[key] = tail
        return tail


@functools.lru_cache(maxsize=None)
def _scheme_tail(name, corrector, kernel, saba):
    """The scheme's part of ``Plan.kernel_tail`` (kernel code, corrector table, drift and kick
    coefficients, lazy corrector coefficient), the same for every plan: made once per setting
    in the process, since a fresh simulation's first call would otherwise build it (its
    arrays are shared; the kernels only read them)."""
    if name == "whfast":
        return int(KERNELS[kernel]), corrector_table(corrector), _WH_DRIFTS, _WH_KICKS, 0.0
    drifts, kicks, cc = saba_scheme(saba)
    return int(KERNEL_STANDARD), _NO_CORRECTOR, drifts, kicks, float(cc)


#: how many single-term scenes' plans a process keeps (``shared_plan``), and up to how many
#: particles a scene's plan is kept (beyond that, making one costs little next to a step)
SHARED_PLANS = 64
SHARED_MAX_PARTICLES = 1024
_SHARED = collections.OrderedDict()


def shared_plan(terms, state, model, pack_terms, name, coordinates, particles_key):
    """``plan(..., direct=True)`` for a ``Simulation``, shared with every simulation of the
    process whose scene has the same content, when the scene is a single term (a PointMass
    alone, or NBodyGravity alone) of at most ``SHARED_MAX_PARTICLES`` particles.

    A plan is a function of the scene alone (the term's packed parameters, the particles'
    count, masses and flags, the space, the coordinates), and nothing writes it, so equal
    scenes may hold the same one: many short runs of one scene (a sweep, the advisor's pilot
    runs, an ensemble) then make it once, where each fresh simulation's first call would
    otherwise spend more time on it than a hundred steps of a small system take.
    ``particles_key`` is the bytes of the masses and flags (the caller has them). The
    least recently used plan is dropped past ``SHARED_PLANS``; a scene with more terms
    (their parameters change from frame to frame: thrust) is planned as before."""
    if model.kinds.shape[0] != 1 or state.n > SHARED_MAX_PARTICLES:
        return plan(terms, state, model, pack_terms, name, coordinates, direct=True)
    key = (name, coordinates, state.n, state.box, state.pos.shape[0], particles_key,
           model.kinds.tobytes(), model.params.tobytes(), model.indices.tobytes())
    made = _SHARED.get(key)
    if made is None:
        made = plan(terms, state, model, pack_terms, name, coordinates, direct=True)
        _SHARED[key] = made
        while len(_SHARED) > SHARED_PLANS:
            _SHARED.popitem(last=False)
    else:
        _SHARED.move_to_end(key)
    return made


def plan(terms, state, model, pack_terms, name="whfast", coordinates="jacobi", direct=False):
    """The Wisdom-Holman plan for a scene, or ValueError naming why it has none.

    ``terms`` are the declared force terms (in model order), ``pack_terms(list)`` packs a
    subset into a ``Model``; ``name`` is the integrator the messages name. A single
    ``PointMass`` (without softening) makes ATTRACTOR mode; otherwise a single
    ``NBodyGravity`` (without softening, in open space) whose heaviest body dominates
    (``DOMINANCE``) makes JACOBI mode, or DEMOCRATIC mode with ``coordinates``
    ``"democratic_heliocentric"``. ``direct``: ``state`` and ``model`` are a ``Simulation``'s
    own (``engine.integrators.direct``), so the compiled helpers skip numba's type dispatch."""
    if coordinates not in COORDINATES:
        raise ValueError(f"coordinates must be one of {', '.join(map(repr, COORDINATES))}, "
                         f"got {coordinates!r}")
    n = state.n
    attractors, gravities = [], []
    for s, term in enumerate(terms):
        if isinstance(term, PointMass):
            attractors.append(s)
        elif isinstance(term, NBodyGravity):
            gravities.append(s)
    dim = state.pos.shape[0]
    if len(attractors) > 1:
        raise ValueError(f"{name} drifts about one attractor; this scene declares "
                         f"{len(attractors)} PointMass terms")
    if attractors:
        s = attractors[0]
        f0 = int(model.param_offsets[s])
        # read as Python floats in one conversion (this runs on a simulation's first call,
        # where each numpy scalar read adds to what a short run costs)
        mu, eps2, *center = model.params[f0:f0 + 2 + dim].tolist()
        if eps2 != 0.0:
            raise ValueError(f"{name} drifts on exact Kepler orbits about the PointMass: its "
                             f"softening must be 0, got {eps2 ** 0.5!r}")
        center = np.array(center)
        i0, i1 = model.index_offsets[s:s + 2].tolist()
        columns_args = (state.active, state.pinned, model.indices[i0:i1], int(n))
        order, attracted = (_direct.call(_attractor_columns, columns_args) if direct
                            else _attractor_columns(*columns_args))
        others = terms[:s] + terms[s + 1:]
        return Plan(ATTRACTOR, order, _NO_MASSES, 0.0, mu, center, attracted,
                    pack_terms(others) if others else EMPTY_MODEL, True)
    if len(gravities) != 1:
        raise ValueError(f"{name} needs a dominant mass to drift about: declare a PointMass "
                         "attractor, or NBodyGravity with one body much heavier than the rest"
                         + (f"; this scene declares {len(gravities)} NBodyGravity terms"
                            if gravities else "; this scene declares neither"))
    s = gravities[0]
    f0 = model.param_offsets[s]
    G, eps2 = float(model.params[f0]), float(model.params[f0 + 1])
    if eps2 != 0.0:
        raise ValueError(f"{name} drifts on exact Kepler orbits: NBodyGravity's softening must "
                         f"be 0, got {eps2 ** 0.5!r}")
    if state.box > 0.0:
        raise ValueError(f"{name} in {coordinates.replace('_', ' ')} coordinates needs open space, "
                         f"got box={state.box!r} "
                         "(a PointMass attractor may sit in a periodic space)")
    columns_args = (state.active, state.pinned, state.test, state.mass, int(n))
    order, masses, heaviest, rest, massive, pinned_active = (
        _direct.call(_jacobi_columns, columns_args) if direct
        else _jacobi_columns(*columns_args))
    if pinned_active >= 0:
        raise ValueError(f"{name} in {coordinates.replace('_', ' ')} coordinates moves every body: "
                         f"particle {pinned_active} is "
                         "pinned (make a fixed central body a PointMass attractor instead)")
    if heaviest < 0:
        raise ValueError(f"{name} needs a dominant mass to drift about: no active body has mass")
    if massive > 2 and masses[heaviest] < DOMINANCE * rest:
        raise ValueError(f"{name} needs a dominant mass: the heaviest body (particle {heaviest}, "
                         f"mass {float(masses[heaviest])!r}) carries less than {DOMINANCE:g} times "
                         f"the other bodies' {float(rest)!r}; use a method for any scene "
                         "(engine.integrators.GENERAL) instead")
    kick_com = any(not isinstance(term, NBodyGravity) for term in terms)
    if coordinates == "democratic_heliocentric":
        mode = DEMOCRATIC
    else:
        mode = JACOBI if kick_com else JACOBI_GRAVITY
    return Plan(mode, order, masses, G, 0.0, np.zeros(dim),
                np.zeros(1, dtype=np.bool_), model, kick_com)
