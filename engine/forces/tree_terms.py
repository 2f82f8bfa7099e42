"""What the tree methods of ``NBodyGravity`` and ``Coulomb`` share: their parameters and rules.

``method="direct"`` (the default) sums every pair, exactly; ``"tree"`` evaluates the field
with the Barnes-Hut tree of ``engine.tree`` (``engine.tree.walk``: a walk from the root for
every group of targets) and its opening angle ``theta`` (0 sums every pair, through the tree;
larger is faster and less accurate; below 2) and multipole ``order`` (0, 1 or 2: monopole,
dipole, quadrupole about each cell's centre); ``"fmm"`` evaluates it with the same tree, cells
acting on cells through local expansions passed down the tree (``engine.tree.fmm``, a fast
multipole method: cost growing as N rather than N log N), with the same parameters (below
theta 0.2 it walks as ``"tree"`` does); ``"auto"`` sums directly in a simulation of fewer than
``DIRECT_BELOW`` particle slots (``sim.n``, inactive ones included: the count every rule here
is decided on) and uses ``"fmm"`` from there on. The threshold is a constant,
not measured on the machine that runs, so that a scene gives the same result everywhere.

A tree term runs in a ``Simulation`` in open space. ``engine.Batch`` refuses it (its systems
are small, where the direct sum is faster), as do a periodic space (the tree has no periodic
images) and the whfast, saba and ias15 integrators (see ``check_integrator``).
"""
from .._validate import finite_float, int_in_range, one_of
from ..cache import jit

METHODS = ("direct", "tree", "fmm", "auto")
#: the packed code of each method
METHOD_CODES = {"direct": 0.0, "tree": 1.0, "auto": 2.0, "fmm": 3.0}
#: the multipole orders the tree offers (``engine.tree.multipoles``)
ORDERS = (0, 1, 2)
#: ``method="auto"`` sums directly below this many interacting particles: about where the
#: fast multipole walk at median force error 1e-3 overtakes the direct sum (3632 and 3703
#: bodies in two runs on the 2-core AMD EPYC (znver4) of docs/performance.md, Plummer sphere,
#: both cores, since the direct sum takes each pair once; 1744 before, when it visited each
#: pair twice; ``python -m validation bench``, section "tree"). A constant, the same on every
#: machine, so that results do not depend on where they run
DIRECT_BELOW = 3600
#: integrators that refuse tree terms, and why
REFUSING_INTEGRATORS = {
    "whfast": "its Kepler splitting is made for a few bodies around a dominant mass",
    "saba": "its Kepler splitting is made for a few bodies around a dominant mass",
    "ias15": ("it controls its error to machine precision, and a tree's forces are good to "
              "theta's accuracy only and jump where a cell's opening decision flips between "
              "its substeps"),
}


def check_method(name, value):
    return one_of(*METHODS)(name, value)


def check_theta(name, value):
    """theta in [0, 2): 0 opens every cell; from 2 on a cell could be taken by its multipoles
    from inside its own bounding sphere."""
    value = finite_float(name, value)
    if not 0.0 <= value < 2.0:
        raise ValueError(f"{name} must be in [0, 2) (0 sums every pair directly), got {value!r}")
    return value


def check_order(name, value):
    """0, 1 or 2: a bool, float, text or array is a TypeError, another int a ValueError."""
    return int_in_range(name, value, min(ORDERS), max(ORDERS))


def uses_tree(term, n):
    """Does ``term`` evaluate by the tree in a system of n particle slots?"""
    method = getattr(term, "method", "direct")
    return method in ("tree", "fmm") or (method == "auto" and n >= DIRECT_BELOW)


#: the packed code of the Barnes-Hut walk, read by compiled code
BARNES_HUT = METHOD_CODES["tree"]


@jit(error_model="numpy", inline="always")
def multipole(code):
    """Does a tree term of packed method ``code`` walk by the fast multipole method ("fmm",
    and "auto" above its threshold) rather than Barnes-Hut's ("tree")?"""
    return code != BARNES_HUT


def check_owner(term, sim):
    """Refuse a tree term where it cannot act: a Batch or a periodic space (ValueError)."""
    if term.method == "direct":
        return
    name = type(term).__name__
    if sim._owner == "batch":
        raise ValueError(f"{name}(method={term.method!r}) cannot act in a Batch: its systems are "
                         "small, where the direct sum is faster; use method='direct'")
    box = term.box or sim.box
    if box:
        raise ValueError(f"{name}(method={term.method!r}) cannot act in a periodic space "
                         f"(box={box!r}): the tree has "
                         "no periodic images; use method='direct'")


def check_integrator(terms, n, integrator):
    """ValueError if ``integrator`` refuses a tree term among ``terms`` (module doc)."""
    reason = REFUSING_INTEGRATORS.get(integrator)
    if reason is None:
        return
    for term in terms:
        if uses_tree(term, n):
            raise ValueError(f"{integrator} cannot step {type(term).__name__}(method="
                             f"{term.method!r}): {reason}; use a fixed-step integrator "
                             "(leapfrog, yoshida4, ...) or method='direct'; nothing was changed")


def packed(term):
    """theta, order and the method's code, as the term's last packed floats."""
    return (term.theta, float(term.order), METHOD_CODES[term.method])


def describe(term):
    return f"method={term.method!r}, theta={term.theta!r}, order={term.order!r}"


__all__ = ["METHODS", "ORDERS", "DIRECT_BELOW", "check_method", "check_theta", "check_order",
           "uses_tree", "check_owner", "check_integrator"]
