"""The bench's sections, declared once.

Each section is a module of this package that declares, in one place:

- ``NAME``: its word in ``--only``;
- ``KEYS``: the entries of the results that ``run`` fills (the section is shown when the
  results hold any of them);
- ``NEEDS``: the modules beyond the core install it cannot run without (``python -m
  validation`` names the extra that has them before starting);
- ``run(quick)``: its measurements, ``{key: results}``;
- ``text(r)``: its lines of the printed report, from the whole results ``r``;
- ``markdown(r)``: its lines of ``docs/performance.md``;
- ``targets(r)``: its performance targets against these figures, ``(target, measured, met)``.

``MODULES`` lists them in the order of their numbers; adding a section is adding its module
and its name there.
"""
import importlib

#: the section modules, in the order of their numbers in the report
MODULES = tuple(importlib.import_module(f"{__package__}.{name}") for name in (
    "direct_sum", "small_n", "scaling", "terms", "startup", "spacewar", "batch", "learning",
    "planets", "cluster", "tree", "contact"))
#: their words in ``--only``, in the same order
SECTIONS = tuple(module.NAME for module in MODULES)

#: where the targets table departs from the sections' order, to stay as it has always been:
#: the section (its ``NAME``) whose targets come just before those of the section named
TARGETS_BEFORE = {"learning": "spacewar"}


def chosen(results):
    """The modules of the sections that have entries in ``results``, in their order."""
    return [module for module in MODULES if any(key in results for key in module.KEYS)]


def named(names):
    """The modules of the sections ``names`` lists (words of ``--only``), in their order."""
    return [module for module in MODULES if module.NAME in names]
