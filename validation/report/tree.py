"""Section 6: the engine's tree gravity (FMM and Barnes-Hut) against pytreegrav's and
REBOUND's trees, its error and its speed (the measurements: ``validation.tree_bench``)."""
import os
import sys

from .. import plots as draw
from .. import tree_bench
from .text import f

NAME = "tree"
CONTENTS = "6. Tree gravity (FMM and Barnes-Hut)"
PHASE = "alone"  # timed: alone in this process, after everything else
FIGURES = {"error": "tree_error.png", "time": "tree_time.png"}


def jobs(level):
    return []


def gather(level, results, progress):
    say = (lambda text: print(f"tree: {text}", file=sys.stderr)) if progress else None
    return tree_bench.measure(tree_bench.SIZES[level.name], progress=say,
                              energy_spec=tree_bench.ENERGY[level.name])


def plots(sec, level, out_dir):
    draw.tree_error(sec, os.path.join(out_dir, FIGURES["error"]))
    draw.tree_time(sec, os.path.join(out_dir, FIGURES["time"]))
    return dict(FIGURES)


def markdown(sec, level, figs):
    return section_tree(sec, figs["error"], figs["time"])


def section_tree(sec, fig_error, fig_time):
    """Section 6: the engine's tree gravity (FMM and Barnes-Hut) against pytreegrav's and
    REBOUND's trees."""
    lines = ["## 6. Tree gravity: error and speed against pytreegrav and REBOUND", ""]
    lines.append(
        "`NBodyGravity(method=\"tree\", theta, order=2)` sums near pairs directly and far "
        "cells by their multipoles to the quadrupole (Barnes & Hut 1986), walking the tree "
        "from its root for every group of targets; `method=\"fmm\"` (what `\"auto\"` uses) "
        "walks the same tree once, cells acting on cells through local expansions passed "
        "down to the groups (a fast multipole method: Greengard & Rokhlin 1987, Dehnen "
        "2002), so that its cost grows as N rather than N log N; pytreegrav and "
        "REBOUND are the references (pytreegrav with its monopole and with its quadrupole "
        "walk; REBOUND's pip build has the monopole tree on one core). The error of a body "
        "is |a - a_exact| / |a_exact|, a_exact summing every other body exactly. The opening "
        "angles of the three codes mean different things (the engine takes a cell whole when "
        "its size is below theta times its distance from a leaf's group of targets; REBOUND "
        "when its width is below theta times the distance from one target to the cell's "
        "centre of mass; pytreegrav has a criterion of its own), so the codes are compared at "
        "equal error, each at the theta its curve gives for a median error of "
        f"{sec['target_error']:g}, not at equal theta.")
    lines.append("")
    lines.append(f"![relative force error against theta]({fig_error})")
    lines.append("")
    lines.append(f"![time of one force evaluation against N]({fig_time})")
    lines.append("")
    lines += tree_bench.markdown_tree(sec)
    lines.append("")
    if "energy" in sec:
        lines += tree_bench.markdown_energy(sec["energy"])
        lines.append("")
    lines.append(findings(sec))
    lines.append("")
    return "\n".join(lines)


def findings(sec):
    """The section's findings, from its figures (and its targets, met or not)."""
    parts = []
    curves = sec["error"]["curves"]
    for code, curve in curves.items():
        at = {round(r["theta"], 6): r for r in curve["rows"]}
        if 0.5 in at:
            parts.append(f"At theta = 0.5 the median error of {sec['labels'][code]} is "
                         f"{f(at[0.5]['median'])} (99th percentile {f(at[0.5]['p99'])}).")
    rows = [r for r in sec["compare"] if r.get("speedup")]
    if rows:
        big = rows[-1]
        cells = ", ".join(f"{big['speedup'][c]:.1f}x against {sec['labels'][c]}"
                          for c in big["speedup"])
        parts.append(f"At N = {big['n']:.0e} and equal median error, the engine FMM's "
                     f"speed-up (the other code's time over the engine's; below 1x the engine "
                     f"is slower): {cells}.")
    e = sec.get("energy")
    if e:
        fmm, direct = e["fmm"], e["direct"]
        parts.append(
            f"Over {fmm['steps']} leapfrog steps of a {e['n']}-body Plummer sphere the FMM's "
            f"largest energy error is {f(max(abs(x) for x in fmm['dE']))} against the direct "
            f"sum's {f(max(abs(x) for x in direct['dE']))} over its {direct['steps']}; the "
            f"FMM's momentum drifts to {f(max(fmm['dP']))} of sum m|v| (its forces are not "
            f"antisymmetric pair by pair), the direct sum's to {f(max(direct['dP']))}.")
    for name, measured, met in tree_bench.targets(sec):
        parts.append(f"Target: {name}: {measured}, {'met' if met else 'not met'}.")
    return "**Findings.** " + " ".join(parts)


def glance(sec, level):
    return [], []
