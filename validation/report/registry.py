"""The report's sections, declared once.

Each section is a module of this package that declares, in one place:

- ``NAME``: its key in ``results.json``, its word in ``--only`` and its module's name;
- ``CONTENTS``: its entry in the report's list of contents;
- ``PHASE``: when its results are made (``PHASES``);
- ``FIGURES``: the PNG files its ``plots`` writes whatever the results, by role (checked
  before the runs start: ``output_files``);
- ``jobs(level)``: its untimed runs (``validation.jobs.Job``), run on the worker processes or
  the cluster with every other section's;
- ``gather(level, results, progress)``: its results, from the untimed runs' ``results`` (and,
  in a timed phase, from the timed work it does itself, in this process);
- ``plots(sec, level, out_dir)``: writes its figures into ``out_dir``; returns their file names
  by role;
- ``markdown(sec, level, figs)``: its part of ``report.md`` (``figs``: what ``plots`` returned);
- ``glance(sec, level)``: its lines of "At a glance": ``(lines, tables)``, every section's lines
  first, then every section's tables.

``SECTIONS`` lists them in the report's order; adding a section is adding its module and its
name there.
"""
import importlib

#: the sections, in the report's order (their modules' names)
SECTIONS = ("crosscheck", "two_body", "energy_drift", "work_precision", "hard_cases", "tree",
            "contact")
#: the section modules, in the same order
MODULES = tuple(importlib.import_module(f"{__package__}.{name}") for name in SECTIONS)

#: the phases of a run, in order, each with its key in ``results.json``'s ``timings``:
#: "untimed", the runs of every section's ``jobs`` on the worker processes (or the cluster);
#: "timed", the sections timed one at a time in this process; "alone", those timed alone at
#: the very end (the tree's, whence the key's name)
PHASES = {"untimed": "untimed_phase_wall_s", "timed": "timed_phase_wall_s",
          "alone": "tree_phase_wall_s"}


def chosen(names):
    """The modules of the sections ``names`` lists, in the report's order."""
    return [module for module in MODULES if module.NAME in names]
