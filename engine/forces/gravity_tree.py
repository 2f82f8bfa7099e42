"""Gravity by the tree: ``NBodyGravity(method="fmm")`` (and "auto" above its threshold), by
its fast multipole walk, and ``method="tree"``, by its Barnes-Hut walk.

The field of every active particle is taken from ``engine.tree`` (sources: the active
particles that are not test particles and have mass; targets: every active particle), with
alpha = 1 and beta_j = G m_j:

    a_i = sum_j G m_j (p_j - p_i) / (|p_j - p_i|^2 + eps^2)^(3/2)

summed directly for near pairs and by each far cell's multipoles about its centre (Barnes &
Hut 1986, Nature 324, 446; Barnes 1990), at each target or through local expansions passed
down the tree (``engine.tree.fmm``). The error falls with ``theta`` and is 0 to round-off
at theta = 0 (every pair summed). Forces are not antisymmetric pair by pair, so total momentum
drifts at the level of the force error (the direct sum keeps it to round-off).

The potential energy of a simulation's tree term is summed by the same tree with the same
theta: U = -1/2 sum_i m_i sum_j G m_j / r_ij (``Simulation.potential_energy``); the
``potential`` kernel here, which has no workspace for a tree, sums every pair exactly.
"""
import math

from ..cache import jit

from ..tree import field, layout
from . import gravity, tree_terms

KIND = 10


@jit(error_model="numpy", inline="always")
def _members(state, part, slots, G):
    """List the active particles in ``slots`` with beta (G m, 0 for a test particle) in
    block 5 and alpha (1) in block 6, by slot; how many."""
    m = 0
    for i in range(state.n):
        if state.active[i]:
            slots[m] = i
            m += 1
            part[5, i] = 0.0 if state.test[i] else G * state.mass[i]
            part[6, i] = 1.0
    return m


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    """acc += the tree's field; the direct sum without a tree workspace (a caller's own
    ``pairwise.workspace``). ("auto" below its threshold packs the direct sum's kind.)"""
    n = state.n
    if layout.usable(n, work):
        m = _members(state, field.blocks(work.floats, n), field.slots_of(work.ints, n),
                     params[f0])
        if field.add_field(state.pos, n, m, work.floats, work.ints, params[f0 + 4],
                           params[f0 + 1], int(params[f0 + 5]), work.threads,
                           tree_terms.multipole(params[f0 + 6]), acc):
            return
    gravity.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    """Every pair, exactly (the tree's potential needs a workspace: ``tree_potential``)."""
    return gravity.potential(t, state, params, f0, f1, indices, i0, i1)


@jit(error_model="numpy")
def tree_potential(state, params, f0, work):
    """U = -1/2 sum_i m_i phi_i, phi_i = sum_j G m_j / r_ij from the tree (same theta)."""
    n = state.n
    if not layout.usable(n, work):
        return math.nan  # a tree workspace is needed (``engine.tree.layout.workspace(n)``)
    part = field.blocks(work.floats, n)
    slots = field.slots_of(work.ints, n)
    m = _members(state, part, slots, params[f0])
    if m == 0:
        return 0.0
    field.solve(state.pos, n, m, work.floats, work.ints, params[f0 + 4], params[f0 + 1],
                int(params[f0 + 5]), True, work.threads,
                tree_terms.multipole(params[f0 + 6]))
    u = 0.0
    for k in range(m):
        i = slots[k]
        if not state.test[i]:
            u -= 0.5 * state.mass[i] * part[8, k]
    return u


#: the term whose method this module gives
TERM = gravity.NBodyGravity
METHOD = "tree"
