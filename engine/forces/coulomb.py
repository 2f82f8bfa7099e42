"""Electric force between charged particles (Coulomb's law, Plummer-softened).

f_a = -k q_a q_b (p_b - p_a) / (|p_b - p_a|^2 + eps^2)^(3/2)     (lecture, "electric forces":
like charges repel)     U = sum_{a<b} k q_a q_b / sqrt(|p_b - p_a|^2 + eps^2)

Pairs act equally and oppositely (momentum conserved to round-off); the acceleration is f / m.
Uncharged and inactive particles are skipped; test particles do take part (the test flag is
about gravity only).
"""
import math
import warnings

from ..cache import jit

from . import pairwise, tree_terms
from ._kernels import add_force, delta_periodic, pair_box
from .base import Force, floats, EMPTY_INTS
from .._validate import nonnegative_float, finite_float, optional, positive_float

KIND = 3


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    pos = state.pos
    mass = state.mass
    charge = state.charge
    active = state.active
    n = state.n
    k = params[f0]
    eps2 = params[f0 + 1]
    box = pair_box(params, f0, state)
    dim = pos.shape[0]
    if pairwise.usable(n, work):
        pairwise.coulomb(pos, mass, charge, active, n, k, eps2, box, acc, work)
        return
    for i in range(n):
        if not active[i] or charge[i] == 0.0:
            continue
        for j in range(i + 1, n):
            if not active[j] or charge[j] == 0.0:
                continue
            dx, dy, dz = delta_periodic(pos, i, j, dim, box)
            r2 = dx * dx + dy * dy + dz * dz + eps2
            s = k * charge[i] * charge[j] / (r2 * math.sqrt(r2))
            # force on i is -s d (repulsion for s > 0); on j it is +s d
            add_force(acc, i, dim, -s * dx, -s * dy, -s * dz, mass[i])
            add_force(acc, j, dim, s * dx, s * dy, s * dz, mass[j])


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    pos = state.pos
    charge = state.charge
    active = state.active
    n = state.n
    k = params[f0]
    eps2 = params[f0 + 1]
    box = pair_box(params, f0, state)
    dim = pos.shape[0]
    u = 0.0
    for i in range(n):
        if not active[i] or charge[i] == 0.0:
            continue
        for j in range(i + 1, n):
            if not active[j] or charge[j] == 0.0:
                continue
            dx, dy, dz = delta_periodic(pos, i, j, dim, box)
            u += k * charge[i] * charge[j] / math.sqrt(dx * dx + dy * dy + dz * dz + eps2)
    return u


class Coulomb(Force):
    """Coulomb forces between all charged active particles; ``k`` is the Coulomb constant.

    ``box`` (deprecated): side of a periodic domain for this term alone; declare the space
    once instead (``Simulation(box=L)``), and pairs interact through their nearest image.

    ``method``, ``theta``, ``order``: as ``NBodyGravity``'s (``"fmm"`` and ``"tree"``: the
    tree's two walks, ``engine.forces.coulomb_tree``; charges of both signs, so the quadrupole
    ``order=2``, the default, is what keeps a neutral plasma's error small).
    """

    KIND = KIND
    LAYOUT = (("k", ()), ("softening_squared", ()), ("box", ()), ("theta", ()), ("order", ()),
              ("method", ()))
    BOUNDS = {"softening_squared": (0.0, False), "box": (0.0, False)}
    conservative = True
    _settable = {"k": finite_float, "softening": nonnegative_float,
                 "box": optional(positive_float), "method": tree_terms.check_method,
                 "theta": tree_terms.check_theta, "order": tree_terms.check_order}

    def __init__(self, k=1.0, softening=0.0, box=None, method="direct", theta=0.5, order=2):
        super().__init__()
        self.method = method
        self.theta = theta
        self.order = order
        self.k = k
        self.softening = softening
        if box is not None:
            warnings.warn(f"{type(self).__name__}(box=...) is deprecated: declare the periodic space once, "
                          "Simulation(box=L) or Batch(box=L), and every pair force, the drift "
                          "and collisions use it", DeprecationWarning, stacklevel=3)
        self.box = box

    def _pack(self, sim):
        return floats(self.k, self.softening ** 2, self.box or 0.0, *tree_terms.packed(self)), EMPTY_INTS

    def _check(self, sim):
        tree_terms.check_owner(self, sim)

    def _kind(self, sim):
        if tree_terms.uses_tree(self, sim.n):
            from . import coulomb_tree
            return coulomb_tree.KIND
        return KIND

    def __repr__(self):
        return (f"Coulomb(k={self.k!r}, softening={self.softening!r}, "
                f"{tree_terms.describe(self)})")


#: the term this module implements (for ``engine.forces.registry``)
TERM = Coulomb
