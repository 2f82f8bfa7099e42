"""Pairwise Newtonian gravity with Plummer softening.

a_i = sum_j G m_j (p_j - p_i) / (|p_j - p_i|^2 + eps^2)^(3/2)      (lecture, "gravity in open
space", with Plummer's softening length eps; Aarseth, Gravitational N-Body Simulations, 2003)

U = - sum_{i<j} G m_i m_j / sqrt(|p_j - p_i|^2 + eps^2)

Each pair is visited once and both bodies get equal and opposite forces, so total momentum is
conserved to round-off. Test particles feel the field but are not sources (so a pair of test
particles costs nothing: O(N_massive x N) for test particles around a few bodies). From
``pairwise.PARALLEL_MIN`` particles on, given a workspace, the vectorised multi-core kernel of
``pairwise`` runs instead (each pair visited from both ends; momentum to round-off per visit).
"""
import math
import warnings

from ..cache import jit

from . import pairwise, tree_terms
from ._kernels import delta_periodic, nearest_image, pair_box
from .base import Force, floats, EMPTY_INTS
from .._validate import nonnegative_float, one_of, optional, positive_float

KIND = 0


@jit(error_model="numpy", _nrt=False, inline="always")
def _all_massive_and_active(active, test, n):
    for i in range(n):
        if test[i] or not active[i]:
            return False
    return True


@jit(error_model="numpy", _nrt=False, inline="always")
def _open_space_3d(pos, mass, n, G, eps2, acc):
    """The common case without flags or periodic images: no branch in the pair loop (a small
    system's step is then as fast as a hand-written loop)."""
    for i in range(n):
        xi = pos[0, i]
        yi = pos[1, i]
        zi = pos[2, i]
        gi = G * mass[i]
        axi = 0.0
        ayi = 0.0
        azi = 0.0
        for j in range(i + 1, n):
            dx = pos[0, j] - xi
            dy = pos[1, j] - yi
            dz = pos[2, j] - zi
            r2 = dx * dx + dy * dy + dz * dz + eps2
            inv_r3 = 1.0 / (r2 * math.sqrt(r2))
            si = G * mass[j] * inv_r3
            sj = gi * inv_r3
            axi += si * dx
            ayi += si * dy
            azi += si * dz
            acc[0, j] -= sj * dx
            acc[1, j] -= sj * dy
            acc[2, j] -= sj * dz
        acc[0, i] += axi
        acc[1, i] += ayi
        acc[2, i] += azi


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    pos = state.pos
    mass = state.mass
    active = state.active
    test = state.test
    n = state.n
    G = params[f0]
    eps2 = params[f0 + 1]
    box = pair_box(params, f0, state)
    if pairwise.usable(n, work):
        single = params[f0 + 3] != 0.0
        pairwise.gravity(pos, mass, active, test, n, G, eps2, box, single, acc, work)
        return
    three = pos.shape[0] == 3
    if box == 0.0 and three and _all_massive_and_active(active, test, n):
        _open_space_3d(pos, mass, n, G, eps2, acc)
        return
    for i in range(n):
        if not active[i]:
            continue
        ti = test[i]
        gi = 0.0 if ti else G * mass[i]
        xi = pos[0, i]
        yi = pos[1, i]
        zi = pos[2, i] if three else 0.0
        axi = 0.0
        ayi = 0.0
        azi = 0.0
        for j in range(i + 1, n):
            if not active[j] or (ti and test[j]):
                continue
            gj = 0.0 if test[j] else G * mass[j]
            dx = nearest_image(pos[0, j] - xi, box)
            dy = nearest_image(pos[1, j] - yi, box)
            dz = nearest_image(pos[2, j] - zi, box) if three else 0.0
            r2 = dx * dx + dy * dy + dz * dz + eps2
            inv_r3 = 1.0 / (r2 * math.sqrt(r2))
            # Coincident bodies without softening give 0 * inf = nan: the step then fails loudly.
            si = gj * inv_r3
            sj = gi * inv_r3
            axi += si * dx
            ayi += si * dy
            acc[0, j] -= sj * dx
            acc[1, j] -= sj * dy
            if three:
                azi += si * dz
                acc[2, j] -= sj * dz
        acc[0, i] += axi
        acc[1, i] += ayi
        if three:
            acc[2, i] += azi


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    pos = state.pos
    mass = state.mass
    active = state.active
    test = state.test
    n = state.n
    G = params[f0]
    eps2 = params[f0 + 1]
    box = pair_box(params, f0, state)
    dim = pos.shape[0]
    u = 0.0
    for i in range(n):
        if not active[i] or test[i]:
            continue
        for j in range(i + 1, n):
            if not active[j] or test[j]:
                continue
            dx, dy, dz = delta_periodic(pos, i, j, dim, box)
            u -= G * mass[i] * mass[j] / math.sqrt(dx * dx + dy * dy + dz * dz + eps2)
    return u


class NBodyGravity(Force):
    """Mutual gravity of all active, non-test particles (test particles only feel it).

    ``G=None`` uses the simulation's ``G`` (1.0 without units). ``softening`` is the Plummer
    length eps >= 0; with eps = 0 two coincident bodies make the step raise SimulationError.
    ``box`` (deprecated): side of a periodic domain for this term alone; declare the space
    once instead (``Simulation(box=L)``), and pairs interact through their nearest image.
    ``precision="float32"``: the vectorised kernel (from ``pairwise.PARALLEL_MIN`` bodies on)
    sums the pairs in single precision, in a frame centred on the bodies' mean position and
    scaled by their extent (so any units work): about 2 times faster per step. Forces come out
    good to about 1e-6 of their size for one compact system; separations under about 1e-7 of
    the system's extent are not resolved (such bodies coincide, and without softening the step
    raises SimulationError), and a scene of distant clumps loses accuracy in proportion.
    Positions, velocities, the small-N loop and the potential energy stay in float64.

    ``method``: ``"direct"`` (the default) sums every pair, exactly; ``"fmm"`` takes the
    field from the tree's fast multipole walk, in O(N), and ``"tree"`` from its Barnes-Hut
    walk, in O(N log N), both with opening angle ``theta`` (in [0, 2); 0 sums every pair) and
    multipoles to ``order`` (2: quadrupole) about each cell's centre; ``"auto"`` sums
    directly below ``tree_terms.DIRECT_BELOW`` particles and uses the fast multipole walk
    above (``engine.forces.tree_terms``, ``engine.forces.gravity_tree``: what it costs and
    where it cannot act). The tree computes in float64 (``precision="float32"`` is the
    direct sum's).
    """

    KIND = KIND
    LAYOUT = (("G", ()), ("softening_squared", ()), ("box", ()), ("float32", ()), ("theta", ()),
              ("order", ()), ("method", ()))
    BOUNDS = {"G": (0.0, False), "softening_squared": (0.0, False), "box": (0.0, False)}
    conservative = True

    PRECISIONS = ("float64", "float32")
    _settable = {"G": optional(nonnegative_float), "softening": nonnegative_float,
                 "box": optional(positive_float), "precision": one_of(*PRECISIONS),
                 "method": tree_terms.check_method, "theta": tree_terms.check_theta,
                 "order": tree_terms.check_order}

    def __init__(self, G=None, softening=0.0, box=None, precision="float64", method="direct",
                 theta=0.5, order=2):
        super().__init__()
        self.method = method
        self.theta = theta
        self.order = order
        self.G = G
        self.softening = softening
        if box is not None:
            warnings.warn(f"{type(self).__name__}(box=...) is deprecated: declare the periodic space once, "
                          "Simulation(box=L) or Batch(box=L), and every pair force, the drift "
                          "and collisions use it", DeprecationWarning, stacklevel=3)
        self.box = box
        self.precision = precision

    def _pack(self, sim):
        G = sim.G if self.G is None else self.G
        single = 1.0 if self.precision == "float32" else 0.0
        return (floats(G, self.softening ** 2, self.box or 0.0, single, *tree_terms.packed(self)),
                EMPTY_INTS)

    def _check(self, sim):
        tree_terms.check_owner(self, sim)
        if self.method != "direct" and self.precision == "float32":
            raise ValueError(f"NBodyGravity(method={self.method!r}) computes in float64: "
                             "precision='float32' is the direct sum's; use one or the other")

    def _kind(self, sim):
        return gravity_tree_kind() if tree_terms.uses_tree(self, sim.n) else KIND

    def __repr__(self):
        return (f"NBodyGravity(G={self.G!r}, softening={self.softening!r}, box={self.box!r}, "
                f"precision={self.precision!r}, {tree_terms.describe(self)})")


def gravity_tree_kind():
    """The kind of the tree's gravity kernels (``engine.forces.gravity_tree``; imported on
    first use, so that a scene without a tree term loads none of the tree's code)."""
    from . import gravity_tree
    return gravity_tree.KIND


#: the term this module implements (for ``engine.forces.registry``)
TERM = NBodyGravity
