"""``python -m validation bench``: the engine's speed, measured side by side with references.

Machines are noisy, so every claim is a ratio measured in one run: each repetition times the
engine and its reference back to back, the ratio of that repetition is kept, and the median
of the ratios is reported (with the median times). Sections:

1. direct-sum gravity (leapfrog + NBodyGravity) against REBOUND's leapfrog, N = 256, 1024, 4096,
   with pair interactions per second, and the pair kernel alone against the loop that visits
   each pair from both ends (the engine's former kernel);
2. the Benchmarks Game n-body workload (Sun and four giant planets, symplectic Euler,
   dt = 0.01) through ``sim.step(n)``, against a plain hand-written numba loop and REBOUND;
3. scaling of the time per step with N (direct sum) and with N_test (test particles around
   four massive bodies), with fitted log-log slopes;
4. the cost of the force terms declared (1, 2 and 4 terms on the same particles);
5. start-up: ``import engine`` plus a first step, with a warm and with a cold numba cache;
6. headless Spacewar: frames per second of one match with built-in bots, and of many
   matches advanced together;
7. ``engine.Batch``: 4096 systems of the game's size advanced by one call, against one
   ``Simulation.step`` call per system, at 1 thread and at every thread;
8. ``spacewar.learn.batch.LearningBatch``: 4096 matches stepped with observations and rewards,
   at 1 thread and at every thread;
9. the planetary integrators on the outer solar system (Sun, four giants and Pluto): time per
   step of the engine's ``whfast`` with corrector 11 and of ``ias15`` (epsilon 1e-9) against
   REBOUND's, side by side;
10. tournaments and sweeps on Dask (``cluster``);
11. the tree's gravity, by its fast multipole walk (``NBodyGravity(method="fmm")``) and its
    Barnes-Hut walk (``method="tree"``), on a Plummer sphere against pytreegrav's and
    REBOUND's trees at equal median force error, its scaling with N, its crossover with the
    direct sum and its memory (``validation.tree_bench``);
12. contact: a hard-sphere gas's collisions found and resolved, against REBOUND's tree
    collision search on the same scene (``contact``).

Each section is a module of this package, declared once in ``registry.MODULES`` (what a
section module declares: ``registry``); ``run`` runs them, ``document`` writes the text and
the Markdown, ``timing`` holds the side-by-side timers and ``host`` describes the machine.
"""
import argparse
import json
import os

from engine.atomic import OutputPathError, atomic_write, check_output_path

from .batch import bench_batch
from .direct_sum import bench_direct_sum, kernel_against_both_ends
from .document import HOW_THE_TARGETS_ARE_MET, format_markdown, format_report, targets
from .host import machine
from .learning import bench_harness, bench_learning
from .planets import PLANETS_DT, PLANETS_EPSILON, bench_planets
from .registry import MODULES, SECTIONS, named
from .scaling import bench_scaling
from .small_n import DAYS_PER_YEAR, NBODY_BODIES, SOLAR_MASS, bench_small_n, nbody_state
from .spacewar import bench_spacewar
from .startup import (COMPILE_TIMES_DIR, STARTUP_COMMANDS, bench_startup, compile_time_markdown,
                      stored_compile_times)
from .terms import bench_terms
from .timing import side_by_side


def run(quick=False, sections=None):
    """Every section ``sections`` names (words of ``--only``; default all), in their order."""
    report = {"machine": machine(), "quick": quick}
    for module in named(sections or SECTIONS):
        report.update(module.run(quick))
    return report


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m validation bench",
                                     description="Measure the engine's speed against references.")
    parser.add_argument("--quick", action="store_true", help="smaller sizes, fewer repetitions")
    parser.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    parser.add_argument("--markdown", metavar="FILE", help="also write the results as Markdown")
    parser.add_argument("--only", metavar="SECTIONS",
                        help="comma-separated sections (default: every one): "
                             + ",".join(SECTIONS))
    args = parser.parse_args(argv)
    # a bad output path fails now, not after minutes of benchmarks
    try:
        for path, kind in ((args.json, "json"), (args.markdown, "markdown")):
            if path is not None:
                check_output_path(path, kind)
    except OutputPathError as exc:
        parser.error(str(exc))
    if args.json is not None and args.markdown is not None and \
            os.path.abspath(args.json) == os.path.abspath(args.markdown):
        parser.error(f"--json and --markdown name the same file {args.json!r}")
    sections = args.only.split(",") if args.only else None
    report = run(quick=args.quick, sections=sections)
    print(format_report(report))
    if args.json:
        atomic_write(args.json, json.dumps(report, indent=2, sort_keys=True))
    if args.markdown:
        command = "python -m validation bench" + (" --quick" if args.quick else "")
        atomic_write(args.markdown, format_markdown(report, command))
    return 0


__all__ = ["COMPILE_TIMES_DIR", "DAYS_PER_YEAR", "HOW_THE_TARGETS_ARE_MET", "MODULES",
           "NBODY_BODIES", "PLANETS_DT", "PLANETS_EPSILON", "SECTIONS", "SOLAR_MASS",
           "STARTUP_COMMANDS", "bench_batch", "bench_direct_sum", "bench_harness", "bench_learning",
           "bench_planets", "bench_scaling", "bench_small_n", "bench_spacewar", "bench_startup",
           "bench_terms", "compile_time_markdown", "format_markdown", "format_report",
           "kernel_against_both_ends", "machine", "main", "nbody_state", "run", "side_by_side",
           "stored_compile_times", "targets"]
