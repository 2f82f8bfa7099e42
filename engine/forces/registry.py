"""Every force term, declared once.

Each force module declares, in one place: its ``KIND`` (the number the compiled dispatcher
branches on), its kernels ``accumulate`` and ``potential``, and its ``TERM`` class, which carries
the documentation (its docstring and the module's), whether it is ``conservative`` and its
parameter ``LAYOUT`` by name. ``TERMS`` lists the modules; ``entries()`` reads the declarations
back as one table. The dispatcher (``engine.forces.dispatch``) has a branch per module in both
the force and the potential switch, and ``tests/engine/test_force_registry.py`` proves every kind
unique and reaching both, against the module's own kernels.
"""
from collections import namedtuple

import importlib

from . import (blast, buoyancy, coulomb, drag, gravity, point_mass, springs, thrust,
               uniform_gravity, wind)

#: the force modules, in the order of the documentation
TERMS = (gravity, point_mass, uniform_gravity, coulomb, springs, drag, thrust, wind, buoyancy,
         blast)

Entry = namedtuple("Entry", "kind name term module conservative layout accumulate potential doc")


def entries():
    """One ``Entry`` per force module: what it declares, read from the module and its class."""
    out = []
    for module in TERMS:
        term = module.TERM
        out.append(Entry(module.KIND, term.__name__, term, module, term.conservative,
                         term.LAYOUT, module.accumulate, module.potential,
                         (module.__doc__ or "").strip()))
    return tuple(out)


#: modules that give a term of ``TERMS`` the kernels of another method, by kind: imported on
#: first use, so that a scene without them loads none of their code (``NBodyGravity`` and
#: ``Coulomb`` with ``method="tree"``: ``engine.tree``)
METHODS = {10: "gravity_tree", 11: "coulomb_tree"}


def method_entry(kind):
    """The entry of a method's kind (``METHODS``): its module imported now."""
    module = importlib.import_module(f"{__package__}.{METHODS[kind]}")
    term = module.TERM
    return Entry(module.KIND, f"{term.__name__}(method={module.METHOD!r})", term, module,
                 term.conservative, term.LAYOUT, module.accumulate, module.potential,
                 (module.__doc__ or "").strip())


def by_kind(kind):
    """The entry of a kind number (KeyError naming it if none has it)."""
    for entry in entries():
        if entry.kind == kind:
            return entry
    if kind in METHODS:
        return method_entry(kind)
    raise KeyError(f"no force term has kind {kind!r}")


__all__ = ["TERMS", "METHODS", "Entry", "entries", "method_entry", "by_kind"]
