"""Coulomb's law by the tree: ``Coulomb(method="fmm")`` (and "auto" above its threshold), by
its fast multipole walk, and ``method="tree"``, by its Barnes-Hut walk.

The field of every active charged particle is taken from ``engine.tree`` (uncharged and
inactive particles take no part, as in the direct sum), with alpha_i = -k q_i / m_i and
beta_j = q_j:

    a_i = -(k q_i / m_i) sum_j q_j (p_j - p_i) / (|p_j - p_i|^2 + eps^2)^(3/2)

Charges of both signs cancel in a cell's total: a neutral cell acts through its dipole and
quadrupole, which is why ``order=2`` (the default) is needed for a plasma (the error of a
neutral plasma against theta is in docs/engine.md). Near pairs are summed directly, far cells
by their multipoles about their centres (Barnes & Hut 1986, Nature 324, 446; Barnes 1990), at
each target or through local expansions passed down the tree (``engine.tree.fmm``). The error
falls with ``theta`` and is 0 to round-off
at theta = 0 (every pair summed). Forces are not antisymmetric pair by pair, so total momentum
drifts at the level of the force error (the direct sum keeps it to round-off).

The potential energy of a simulation's tree term is summed by the same tree with the same
theta: U = 1/2 sum_i k q_i sum_j q_j / r_ij (``Simulation.potential_energy``); the
``potential`` kernel here, which has no workspace for a tree, sums every pair exactly.
"""
import math

from ..cache import jit

from ..tree import field, layout
from . import coulomb, tree_terms

KIND = 11


@jit(error_model="numpy", inline="always")
def _members(state, part, slots, k):
    """List the active charged particles in ``slots`` with beta (q) in block 5 and alpha
    (-k q / m) in block 6, by slot; how many."""
    m = 0
    if k == 0.0:
        return 0  # no force at all: the direct sum's loop adds nothing (alpha would be 0 / 0)
    for i in range(state.n):
        q = state.charge[i]
        if state.active[i] and q != 0.0:
            slots[m] = i
            m += 1
            part[5, i] = q
            part[6, i] = -k * q / state.mass[i]
    return m


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    """acc += the tree's field; the direct sum without a tree workspace (a caller's own
    ``pairwise.workspace``). ("auto" below its threshold packs the direct sum's kind.)"""
    n = state.n
    if layout.usable(n, work):
        m = _members(state, field.blocks(work.floats, n), field.slots_of(work.ints, n),
                     params[f0])
        if field.add_field(state.pos, n, m, work.floats, work.ints, params[f0 + 3],
                           params[f0 + 1], int(params[f0 + 4]), work.threads,
                           tree_terms.multipole(params[f0 + 5]), acc):
            return
    coulomb.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    """Every pair, exactly (the tree's potential needs a workspace: ``tree_potential``)."""
    return coulomb.potential(t, state, params, f0, f1, indices, i0, i1)


@jit(error_model="numpy")
def tree_potential(state, params, f0, work):
    """U = 1/2 sum_i k q_i phi_i, phi_i = sum_j q_j / r_ij from the tree (same theta)."""
    n = state.n
    if not layout.usable(n, work):
        return math.nan  # a tree workspace is needed (``engine.tree.layout.workspace(n)``)
    part = field.blocks(work.floats, n)
    slots = field.slots_of(work.ints, n)
    m = _members(state, part, slots, params[f0])
    if m == 0:
        return 0.0
    field.solve(state.pos, n, m, work.floats, work.ints, params[f0 + 3], params[f0 + 1],
                int(params[f0 + 4]), True, work.threads,
                tree_terms.multipole(params[f0 + 5]))
    u = 0.0
    for k in range(m):
        u += 0.5 * params[f0] * state.charge[slots[k]] * part[8, k]
    return u


#: the term whose method this module gives
TERM = coulomb.Coulomb
METHOD = "tree"
