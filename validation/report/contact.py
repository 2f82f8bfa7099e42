"""Section 7: contact, a hard-sphere gas against statistical mechanics and an accreting disk
against REBOUND (the runs: ``validation.contact``)."""
import math
import os

from .. import contact
from .. import plots as draw
from ..jobs import Job
from .text import f, table

NAME = "contact"
CONTENTS = "7. Contact: a hard-sphere gas and an accreting disk"
PHASE = "untimed"
FIGURES = {"contact": "contact.png"}


def jobs(level):
    """The two gases and the accretion disk."""
    relax, span = contact.GAS_TIMES[level.name]
    n, steps, dt, radius = contact.ACCRETION[level.name]
    out = [Job(("contact", "gas", dim), "contact:gas_run",
               dict(dim=dim, n=n_gas, packing=packing, relax=relax, span=span),
               cost=n_gas * (relax + span) * 4000)
           for dim, (n_gas, packing) in contact.GAS.items()]
    out.append(Job(("contact", "accretion"), "contact:accretion_run",
                   dict(n=n, steps=steps, dt=dt, radius=radius), cost=n * steps * 3))
    return out


def gather(level, results, progress):
    return {"gas": {f"{dim}-D": results[("contact", "gas", dim)] for dim in contact.GAS},
            "accretion": results[("contact", "accretion")]}


def plots(sec, level, out_dir):
    draw.contact(sec, os.path.join(out_dir, FIGURES["contact"]))
    return dict(FIGURES)


def markdown(sec, level, figs):
    lines = ["## 7. Contact: a hard-sphere gas and an accreting disk", ""]
    lines.append(
        "`sim.collisions = engine.Collisions(...)` finds every pair whose spheres touch during "
        "a step along the bodies' paths and resolves each at the moment of contact "
        "(`docs/engine.md`, \"Contact\"). **The gas**: equal hard disks (2-D) and hard spheres "
        "(3-D) in a periodic box, started at one speed in random directions, elastic. Their "
        "speeds should relax to the Maxwell-Boltzmann law of the dimension (Rayleigh in 2-D, "
        "Maxwell in 3-D: a Kolmogorov-Smirnov test, whose p-value at the start is the "
        "control), and the compressibility Z = PV/NkT from the collisional virial "
        "(Allen & Tildesley, *Computer Simulation of Liquids*, section 2.4) should match "
        "Henderson's hard-disk equation of state (1975) and Carnahan & Starling's "
        "hard-sphere one (1969).")
    lines.append("")
    lines.append(f"![speeds of the gas, and merges in the disk]({figs['contact']})")
    lines.append("")
    rows = []
    for name, g in sec["gas"].items():
        rows.append([name, g["n"], g["packing"], f"{g['contacts_per_sphere']:.0f}",
                     f(g["start_p"]), ", ".join(f(p) for p in g["p_values"]),
                     f"{g['z']:.4f}", f"{g['z_expected']:.4f} ({g['z_law']})",
                     f"{100 * (g['z'] / g['z_expected'] - 1):+.2f}%", f(g["energy_error"])])
    lines.append(table(["gas", "spheres", "packing", "contacts a sphere", "KS p at start",
                        "KS p after relaxing", "Z measured", "Z expected", "difference",
                        "energy error"], rows))
    lines.append("")
    a = sec["accretion"]
    lines.append(
        f"**The accretion disk**: a star and {a['n']} planetesimals (mass 1e-6, radius "
        f"{a['radius']:g}, a in [0.8, 1.2], e < 0.05, inclination < 0.01, none touching at "
        f"the start, G = 1), {a['steps']} leapfrog steps of {a['dt']:g} "
        f"({a['steps'] * a['dt'] / (2 * math.pi):.1f} orbits at a = 1), merging on contact, "
        "three ways: REBOUND's `collision = \"line\"` with its merge (a Python "
        "`collision_resolve` that does what `reb_collision_resolve_merge` does and logs the "
        "pair); the engine with `resolve_at=\"end\"` (REBOUND's way: pairs whose segments "
        "traced back from the end of the step come within reach, approaching or not, merged "
        "with their end-of-step state); the engine's default (each contact at the moment of "
        "touching, approaching pairs only). The disk is chaotic, so the runs can agree merge "
        "for merge only until round-off has grown; a merge counts as identical when the "
        "same body is absorbed in the same step.")
    lines.append("")
    rows = []
    for name, run in a["runs"].items():
        same = {"rebound": "—", "end": a["identical_end"],
                "contact": a["identical_contact"]}[name]
        picks = [run["merges_by_step"][k] for k in range(4, len(a["marks"]), 10)]
        rows.append([draw.ACCRETION_STYLE[name][0], run["merges"], same,
                     ", ".join(map(str, picks)), run["bodies_left"],
                     f"{run['largest_planetesimal'] / 1e-6:.0f}"])
    marks = [a["marks"][k] for k in range(4, len(a["marks"]), 10)]
    lines.append(table(["run", "merges", "first merges identical to REBOUND's",
                        f"merges by step {', '.join(map(str, marks))}", "bodies left",
                        "largest planetesimal (initial masses)"], rows))
    lines.append("")
    rows = []
    for name in ("end", "contact"):
        k = a[name + "_conservation"]
        rows.append([draw.ACCRETION_STYLE[name][0], f(k["mass"]), f(k["momentum"]),
                     f(k["charge"]), f(k["energy_without_ledger"]), f(k["energy_with_ledger"])])
    lines.append(table(["engine run", "mass", "momentum (of sum m|v|)", "charge",
                        "energy", "energy + ledger"], rows))
    lines.append("")
    lines.append(findings(sec))
    lines.append("")
    return "\n".join(lines)


def findings(sec):
    """The contact section's findings, from its figures."""
    parts = []
    for name, g in sec["gas"].items():
        parts.append(
            f"The {name} gas relaxes from KS p = {f(g['start_p'])} to p >= "
            f"{f(min(g['p_values']))} against {'Rayleigh' if g['dim'] == 2 else 'Maxwell'}; "
            f"its Z is {g['z']:.4f} against {g['z_expected']:.4f} "
            f"({100 * (g['z'] / g['z_expected'] - 1):+.2f}%), energy kept to "
            f"{f(g['energy_error'])}.")
    a = sec["accretion"]
    theirs = a["runs"]["rebound"]["merges"]
    parts.append(
        f"In the disk REBOUND merges {theirs} times; the engine's end-of-step run shares the "
        f"first {a['identical_end']} of them and its default run the first "
        f"{a['identical_contact']}"
        + (" (found at the moment of contact, a merge can fall a step earlier than REBOUND's "
           "end-of-step search finds it, and from then on the chaotic disk goes its own way)"
           if a["identical_contact"] < theirs else "")
        + "; merges over the whole run: "
        f"{', '.join(str(r['merges']) for r in a['runs'].values())} (REBOUND, end, "
        f"contact). Through them mass is kept to {f(a['contact_conservation']['mass'])}, "
        f"momentum to {f(a['contact_conservation']['momentum'])} and charge to "
        f"{f(a['contact_conservation']['charge'])}; the energy plus the ledger to "
        f"{f(a['contact_conservation']['energy_with_ledger'])} (leapfrog's own error) where "
        f"the energy alone changes by {f(a['contact_conservation']['energy_without_ledger'])}.")
    return "**Findings.** " + " ".join(parts)


def glance(sec, level):
    a = sec["accretion"]
    zs = ", ".join(f"{name} Z {g['z']:.3f} against {g['z_expected']:.3f}"
                   for name, g in sec["gas"].items())
    return [f"- **Contact**: hard-sphere gases relax to Maxwell-Boltzmann, {zs}; an "
            f"accreting disk merges as REBOUND's line search does, the first "
            f"{a['identical_end']} of {a['runs']['rebound']['merges']} merges identical "
            f"(section 7)."], []
