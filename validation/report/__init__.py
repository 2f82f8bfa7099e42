"""``python -m validation report --out DIR [--quick]``: run every comparison, write the report.

Writes ``DIR/report.md`` (tables, embedded plots, findings), the PNG plots and
``DIR/results.json`` (every figure in the report; deterministic except the keys named
``time_s``, ``wall_s``, the wall-time-based "fastest" entries, and the tree section's times
and speed-ups: its keys ending in ``_s``, ``speedup`` and ``repeats``).

The untimed work (errors, energies, stability) runs on ``--workers`` processes; the timed
work-precision sweeps then run one at a time in this process, and last the Barnes-Hut tree
section (``tree_bench``: errors and times of the engine's tree, pytreegrav's and REBOUND's).

Each section is a module of this package, declared once in ``registry.SECTIONS`` (what a
section module declares: ``registry``); ``run`` runs them, ``document`` assembles
``report.md``, ``text`` formats numbers and tables.
"""
import argparse
import json
import os
import sys

from engine.atomic import OutputPathError, atomic_write, check_output_dir, check_output_path

from ..settings import LEVELS
from .document import markdown, section_glance
from .registry import MODULES, PHASES, SECTIONS, chosen
from .run import collect, jsonable, meta, warm_up
from .text import expo, f, g, label_of, seconds, table
from .tree import section_tree
from .work_precision import ratio_cell, skipped_text, versus_rows, versus_why


def write(out_dir, res, level):
    os.makedirs(out_dir, exist_ok=True)
    figs = {module.NAME: module.plots(res[module.NAME], level, out_dir)
            for module in chosen(res)}
    atomic_write(os.path.join(out_dir, "results.json"), json.dumps(jsonable(res), indent=1) + "\n")
    atomic_write(os.path.join(out_dir, "report.md"), markdown(res, level, figs))


def output_files(sections=SECTIONS):
    """The files ``write`` produces in the output directory, with their kinds."""
    files = {"report.md": "markdown", "results.json": "json"}
    for module in chosen(sections):
        files.update(dict.fromkeys(module.FIGURES.values(), "png"))
    return files


def check_outputs(out_dir, sections=SECTIONS):
    """Raise OutputPathError now if the report could not be written to ``out_dir`` later."""
    check_output_dir(out_dir)
    if os.path.isdir(out_dir):
        for name, kind in output_files(sections=sections).items():
            check_output_path(os.path.join(out_dir, name), kind)


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m validation report",
        description="Validate the engine against REBOUND and closed forms; write DIR/report.md, "
                    "its PNG plots and DIR/results.json.")
    parser.add_argument("--out", required=True, metavar="DIR", help="output directory")
    parser.add_argument("--quick", action="store_true",
                        help="shorter runs and sweeps: one to two minutes on 2 cores, and "
                             "a few more for the tree section (--only to leave it out)")
    parser.add_argument("--smoke", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--workers", type=int, default=2,
                        help="processes for the untimed runs (default 2)")
    parser.add_argument("--scheduler", default=None, metavar="ADDRESS",
                        help="run the untimed runs on a Dask cluster: its scheduler's address, or "
                             "'local' for a LocalCluster of this machine (default: "
                             "$DASK_SCHEDULER_ADDRESS, else --workers local processes); the "
                             "timed sweeps run here; needs the [cluster] extra")
    parser.add_argument("--only", default=",".join(SECTIONS),
                        help=f"comma-separated sections to run (default all: {','.join(SECTIONS)})")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    args = parser.parse_args(argv)
    level = LEVELS["smoke" if args.smoke else "quick" if args.quick else "full"]
    sections = tuple(s.strip() for s in args.only.split(",") if s.strip())
    unknown = set(sections) - set(SECTIONS)
    if unknown:
        parser.error(f"unknown section(s) {', '.join(sorted(unknown))}; "
                     f"choose from {', '.join(SECTIONS)}")
    try:
        check_outputs(args.out, sections)  # fail now, not after the runs
    except (OutputPathError, TypeError) as exc:
        parser.error(str(exc))
    from engine.cluster import CodeMismatch, SchedulerUnreachable

    try:
        res = collect(level, workers=max(1, args.workers), progress=not args.no_progress,
                      sections=sections, scheduler=args.scheduler)
    except (CodeMismatch, SchedulerUnreachable, ImportError) as exc:
        parser.exit(2, f"python -m validation report: error: {exc}\n")
    write(args.out, res, level)
    print(f"wrote {os.path.join(args.out, 'report.md')} ({seconds(res['timings']['wall_s'])})",
          file=sys.stderr)
    return 0


__all__ = ["LEVELS", "MODULES", "PHASES", "SECTIONS", "check_outputs", "collect", "expo", "f",
           "g", "jsonable", "label_of", "main", "markdown", "meta", "output_files", "ratio_cell",
           "section_glance", "section_tree", "seconds", "skipped_text", "table", "versus_rows",
           "versus_why", "warm_up", "write"]
