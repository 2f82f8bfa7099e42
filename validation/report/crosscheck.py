"""Section 1: the same algorithm in two codes, the engine's ``leapfrog`` against REBOUND's
(the runs: ``validation.crosscheck``)."""
from ..jobs import Job
from .text import f, g, table

NAME = "crosscheck"
CONTENTS = "1. leapfrog cross-check with REBOUND"
PHASE = "untimed"
FIGURES = {}


def jobs(level):
    return [Job(("crosscheck",), "crosscheck:run", dict(orbits=level.cross_orbits),
                cost=level.cross_orbits * 2000)]


def gather(level, results, progress):
    return results[("crosscheck",)]


def plots(sec, level, out_dir):
    return {}


def worst_difference(sec):
    """The largest relative difference, of positions or velocities, over every case."""
    return max(max(c["max_rel_pos_difference"], c["max_rel_vel_difference"])
               for c in sec.values())


def markdown(sec, level, figs):
    lines = ["## 1. Same algorithm, two codes: engine `leapfrog` against REBOUND `leapfrog`", ""]
    lines.append(
        "Both are drift-kick-drift with one force evaluation per step. Each case is set up "
        "identically in both codes (G = 1, same masses, positions and velocities; neither code "
        "moves anything to the centre of mass, and the two massive bodies' centre of mass is "
        "off the origin and moving) and stepped with the same dt; the states are compared about "
        "six times per orbit, at every phase. *Relative difference* = max over samples and "
        "components of |x_engine - x_REBOUND| / (size of the configuration: the largest distance "
        "from the centre of mass, or from the fixed centre), the same for velocities with the "
        "largest velocity relative to the centre of mass. The last two columns compare each "
        "code with the same "
        "algorithm run in 80-bit extended precision (numpy `longdouble`), which shows each "
        "code's own rounding error.")
    lines.append("")
    rows = []
    for key, c in sec.items():
        rows.append([c["problem"], c["steps"], g(c["orbits"]), g(c["dt"], 6),
                     f(c["max_rel_pos_difference"]), f(c["max_rel_vel_difference"]),
                     f(c.get("max_rel_pos_engine_vs_extended")),
                     f(c.get("max_rel_pos_rebound_vs_extended"))])
    lines.append(table(["case", "steps", "orbits", "dt", "max rel. position difference",
                        "max rel. velocity difference", "engine vs 80-bit", "REBOUND vs 80-bit"],
                       rows))
    lines.append("")
    lines.append(findings(sec))
    lines.append("")
    return "\n".join(lines)


def findings(sec):
    own = [max(c.get("max_rel_pos_engine_vs_extended", 0),
               c.get("max_rel_pos_rebound_vs_extended", 0)) for c in sec.values()]
    ratio = max(c["max_rel_pos_difference"] / max(own_i, 1e-300)
                for c, own_i in zip(sec.values(), own))
    return (
        f"**Findings.** The largest difference seen between the two codes is "
        f"{f(worst_difference(sec))} "
        f"(relative), over runs of up to {max(c['steps'] for c in sec.values())} steps. It is "
        f"round-off: each code differs from the extended-precision run of the same algorithm by "
        f"up to {f(max(own))}, and the two codes differ from each other by at most "
        f"{ratio:.2g} times that. The difference grows with the number of steps (the rounding "
        "errors of a leapfrog orbit accumulate as a phase error), so it is smallest on short runs: "
        "the tests assert agreement to 1e-12 over 256 steps.")


def glance(sec, level):
    lines = [f"- **Same algorithm, two codes**: the engine's `leapfrog` and REBOUND's "
             f"`leapfrog` agree to {f(worst_difference(sec))} (largest relative difference, up to "
             f"{max(v['steps'] for v in sec.values())} steps; round-off, section 1)."]
    return lines, []
