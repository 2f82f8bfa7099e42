"""The report's figures (matplotlib, Agg backend: no display needed)."""
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from engine.atomic import atomic_write  # noqa: E402

STYLE = {
    "engine:euler": ("tab:red", "-", "o"),
    "engine:symplectic_euler": ("tab:orange", "-", "v"),
    "engine:leapfrog": ("tab:blue", "-", "s"),
    "engine:verlet": ("tab:cyan", "-", "^"),
    "engine:rk4": ("tab:purple", "-", "D"),
    "engine:yoshida4": ("tab:green", "-", "P"),
    "engine:pefrl": ("tab:olive", "-", "X"),
    "engine:rk45": ("tab:brown", "-", "*"),
    "engine:whfast": ("tab:pink", "-", "h"),
    "engine:whfast_c11": ("deeppink", "-", "h"),
    "engine:whfast_c17": ("crimson", "-", "h"),
    "engine:saba": ("teal", "-", "d"),
    "engine:sabac4": ("darkcyan", "-", "d"),
    "engine:ias15": ("goldenrod", "-", "p"),
    "engine:janus": ("darkkhaki", "-", "8"),
    "rebound:ias15": ("black", "--", "o"),
    "rebound:whfast": ("dimgray", "--", "s"),
    "rebound:leapfrog": ("navy", "--", "^"),
    "rebound:saba": ("magenta", "--", "D"),
    "rebound:whfast_c11": ("gray", "--", "h"),
    "rebound:whfast_c17": ("darkgray", "--", "h"),
    "rebound:sabac4": ("orchid", "--", "d"),
}


def label(method):
    code, name = method.split(":")
    return name if code == "engine" else f"REBOUND {name}"


#: colours for methods missing from STYLE, and line styles for a method's further settings
SPARE_COLOURS = ("tab:gray", "darkorange", "steelblue", "seagreen", "sienna", "slateblue",
                 "olivedrab", "indianred")
LINE_STYLES = ("-", "--", ":", "-.")


def line_styles(keys):
    """A distinct ``(colour, line style, marker)`` for each ``(method, setting)`` key, in order.

    A method's first key gets its colour from ``STYLE`` (a method missing there gets the next
    spare colour); each further setting of the same method keeps the colour and takes the next
    line style, so two lines of one method (Euler at two step sizes) are never drawn alike."""
    styles, spare, used = {}, iter(SPARE_COLOURS * 4), {}
    for key in keys:
        if key in styles:
            continue
        method = key[0]
        if method not in used:
            colour, ls, marker = STYLE.get(method) or (next(spare), "-", ".")
            used[method] = [colour, marker, [ls]]
            styles[key] = (colour, ls, marker)
            continue
        colour, marker, taken = used[method]
        ls = next((s for s in LINE_STYLES if s not in taken), LINE_STYLES[len(taken) % 4])
        taken.append(ls)
        styles[key] = (colour, ls, marker)
    return styles


def _save(fig, path):
    """Write the figure as a PNG atomically (never a truncated plot at ``path``)."""
    try:
        atomic_write(path, lambda f: fig.savefig(f, format="png", dpi=110, bbox_inches="tight"),
                     "wb")
    finally:
        plt.close(fig)


def _grid(n, width=4.6, height=3.6, cols=3):
    cols = min(cols, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows), squeeze=False,
                             layout="constrained")
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:n])


def _figure_legend(fig, axes):
    """One legend for all panels, from every panel's lines (without duplicates)."""
    seen = {}
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            seen.setdefault(lab, h)
    fig.legend(list(seen.values()), list(seen), loc="outside lower center", ncol=5, fontsize=8)


def two_body_convergence(section, path, checkpoint_index=1):
    """Position error after the second checkpoint against steps per orbit."""
    keys = list(section)
    fig, axes = _grid(len(keys))
    for ax, key in zip(axes, keys):
        entry = section[key]
        cp = entry["checkpoints"][min(checkpoint_index, len(entry["checkpoints"]) - 1)]
        by_method = {}
        for run in entry["runs"]:
            if "steps_per_orbit" not in run:
                continue
            err = run["pos_err_kepler"][min(checkpoint_index, len(run["pos_err_kepler"]) - 1)]
            if err is None:
                continue
            point = (run["steps_per_orbit"], max(err, 1e-17))
            by_method.setdefault(run["method"], []).append(point)
        styles = line_styles([(method, "") for method in by_method])
        for method, pts in by_method.items():
            pts.sort()
            c, ls, mk = styles[method, ""]
            ax.loglog(*zip(*pts), ls=ls, marker=mk, color=c, label=label(method), ms=4)
        ax.set_title(f"{entry['title']}: after {cp} P")
        ax.set_xlabel("steps per P")
        ax.set_ylabel("|r - r_kepler| / max(|r_kepler|, |a|)")
        ax.grid(True, which="both", alpha=0.3)
    _figure_legend(fig, axes)
    _save(fig, path)


def two_body_growth(section, path, steps_per_orbit):
    """Position error against time at one step setting (rk45 at its middle tolerance)."""
    keys = list(section)
    fig, axes = _grid(len(keys))
    for ax, key in zip(axes, keys):
        entry = section[key]
        tols = sorted({r["tolerance"] for r in entry["runs"] if "tolerance" in r})
        mid_tol = tols[len(tols) // 2] if tols else None
        drawn = [run for run in entry["runs"] if run.get("steps_per_orbit") == steps_per_orbit
                 or run.get("tolerance") == mid_tol]
        styles = line_styles([(run["method"], run.get("tolerance")) for run in drawn])
        for run in drawn:
            pts = [(t, max(e, 1e-17)) for t, e in zip(entry["checkpoints"], run["pos_err_kepler"])
                   if e is not None]
            if not pts:
                continue
            c, ls, mk = styles[run["method"], run.get("tolerance")]
            name = label(run["method"]) + (f" tol {mid_tol:g}" if "tolerance" in run else "")
            ax.loglog(*zip(*pts), ls=ls, marker=mk, color=c, label=name, ms=4)
        ias = entry["ias15_vs_kepler"]["pos"]
        ax.loglog(entry["checkpoints"], [max(e, 1e-17) for e in ias], color="black", ls=":",
                  marker=".", label="REBOUND ias15 vs Kepler")
        ax.set_title(f"{entry['title']} ({steps_per_orbit} steps/P)")
        ax.set_xlabel("time [P]")
        ax.set_ylabel("|r - r_kepler| / max(|r_kepler|, |a|)")
        ax.grid(True, which="both", alpha=0.3)
    _figure_legend(fig, axes)
    _save(fig, path)


def energy_drift(section, path):
    keys = list(section)
    fig, axes = _grid(len(keys), width=6.8, height=4.8, cols=2)
    for ax, key in zip(axes, keys):
        entry = section[key]
        unit = entry["time_unit"]
        styles = line_styles([(run["method"], run["setting"]) for run in entry["runs"]])
        for run in entry["runs"]:
            t = np.asarray(run["t"], dtype=float) / unit
            e = np.maximum(np.asarray(run["err"], dtype=float), 1e-17)
            if t.size == 0:
                continue
            c, ls, mk = styles[run["method"], run["setting"]]
            slope = run["growth_exponent"]
            tag = "" if slope is None else f" (slope {0.0 if abs(slope) < 0.005 else slope:.2f})"
            ax.loglog(t, e, ls=ls, color=c, label=f"{label(run['method'])}, {run['setting']}{tag}",
                      lw=1.3)
        ax.set_title(entry["title"])
        ax.set_xlabel(f"time [{entry['time_unit_name']}]")
        ax.set_ylabel("|E - E0| / |E0|")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    _save(fig, path)


#: work-precision points with a larger error (in units of L, or relative energy) are not drawn
WP_ERROR_CAP = 1e2


def work_precision_lines(entry):
    """Each method's drawable runs (finished, error at most ``WP_ERROR_CAP``), in order of
    cost (force evaluations, then wall time): a line follows the work done, whatever order
    the sweep ran its settings in (an adaptive method's tolerances, a fixed step's counts)."""
    by_method = {}
    for run in entry["runs"]:
        if run.get("error") is None or not run["error"] <= WP_ERROR_CAP:
            continue
        by_method.setdefault(run["method"], []).append(run)
    for runs in by_method.values():
        runs.sort(key=lambda r: (r["evaluations"], r["time_s"]))
    return by_method


def work_precision(entry, path):
    fig, axes = plt.subplots(1, 2, figsize=(12.5, 4.8), layout="constrained")
    metric = entry["metric"]
    by_method = work_precision_lines(entry)
    styles = line_styles([(method, "") for method in by_method])
    for method, runs in by_method.items():
        c, ls, mk = styles[method, ""]
        err = [max(r["error"], 1e-17) for r in runs]
        axes[0].loglog(err, [r["time_s"] for r in runs], ls=ls, marker=mk, color=c,
                       label=label(method), ms=4)
        axes[1].loglog(err, [max(r["evaluations"], 1) for r in runs], ls=ls, marker=mk, color=c,
                       label=label(method), ms=4)
    xlabel = ("|E - E0| / |E0| at t_end" if metric == "energy"
              else f"max |r - r_ref| / L at t_end (L = {entry['length_name']})")
    for ax, ylabel in zip(axes, ("wall time [s]", "force evaluations")):
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        if metric == "position" and entry["reference"]["floor"] > 0:
            ax.axvline(entry["reference"]["floor"], color="gray", ls=":", lw=1)
    axes[0].set_title(f"{entry['title']}: wall time")
    axes[1].set_title(f"{entry['title']}: force evaluations")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside right center", fontsize=8)
    _save(fig, path)


def spring_limits(limits, path):
    names = [n for n in limits if limits[n]["theory"] is not None]
    fig, ax = plt.subplots(figsize=(8.5, 3.8))
    x = np.arange(len(names))
    theory = [limits[n]["theory"] for n in names]
    ax.bar(x - 0.2, theory, width=0.4, color="lightgray", edgecolor="black", label="theory")
    ks = sorted({k for n in names for k in limits[n]["measured"]})
    for j, k in enumerate(ks):
        vals = [limits[n]["measured"].get(k, {}).get("limit") or 0.0 for n in names]
        ax.scatter(x + 0.08 + 0.12 * j, vals, marker="o^sDv"[j % 5], s=36,
                   label=f"measured, k = {k:g}", zorder=3)
    ax.set_xticks(x)
    ax.set_xticklabels(names, rotation=15)
    ax.set_ylabel("largest stable omega dt")
    ax.axhline(2.0, color="tab:blue", ls=":", lw=1)
    ax.set_title("stiff spring: stability limit of each integrator")
    ax.legend(fontsize=8)
    ax.grid(True, axis="y", alpha=0.3)
    _save(fig, path)


#: the tree section's codes: (colour, line style, marker)
TREE_STYLE = {
    "engine": ("tab:blue", "-", "o"),
    "engine_tree": ("tab:cyan", "-", "x"),
    "direct": ("tab:gray", ":", "s"),
    "pytreegrav": ("tab:orange", "--", "^"),
    "pytreegrav_quadrupole": ("tab:red", "--", "v"),
    "rebound": ("black", "-.", "D"),
}


def tree_error(section, path):
    """Median and 99th-percentile relative force error against theta, one line per code,
    with the target error and each code's theta at it marked."""
    fig, axes = plt.subplots(1, 2, figsize=(12.5, 4.6), layout="constrained")
    target = section["target_error"]
    for code, curve in section["error"]["curves"].items():
        c, ls, mk = TREE_STYLE.get(code, ("tab:gray", "-", "."))
        theta = [r["theta"] for r in curve["rows"]]
        for ax, key in zip(axes, ("median", "p99")):
            ax.loglog(theta, [max(r[key], 1e-17) for r in curve["rows"]], ls=ls, marker=mk,
                      color=c, ms=4, label=section["labels"][code])
        if curve["theta_at_target"] is not None:
            axes[0].plot([curve["theta_at_target"]], [target], marker="*", ms=12, color=c,
                         ls="none")
    axes[0].axhline(target, color="gray", ls=":", lw=1)
    for ax, what in zip(axes, ("median", "99th percentile")):
        ax.set_xlabel("opening angle theta")
        ax.set_ylabel(f"{what} of |a - a_exact| / |a_exact|")
        ax.set_title(f"Plummer sphere, N = {section['error']['n']}: {what} error")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    _save(fig, path)


def tree_time(section, path):
    """Time of one force evaluation against N: the engine's FMM (at its equal-error theta)
    and direct sum, and its Barnes-Hut walk and each reference at their own equal-error
    thetas."""
    fig, ax = plt.subplots(figsize=(7.5, 5.0), layout="constrained")
    lines = {}
    s = section.get("scaling")
    if s:
        lines["engine"] = list(zip(s["n"], s["time_s"]))
    c = section.get("crossover")
    if c:
        lines.setdefault("engine", [])
        lines["engine"] += list(zip(c["n"], c["tree_s"]))
        lines["direct"] = list(zip(c["n"], c["direct_s"]))
    for row in section.get("compare", []):
        for code, seconds in row["time_s"].items():
            if code != "engine" or not s:
                lines.setdefault(code, []).append((row["n"], seconds))
    names = {**section["labels"], "direct": "engine direct sum"}
    for code, points in lines.items():
        points = sorted(dict(points).items())  # one point per N
        colour, ls, mk = TREE_STYLE.get(code, ("tab:gray", "-", "."))
        ax.loglog(*zip(*points), ls=ls, marker=mk, color=colour, ms=5, label=names.get(code, code))
    ax.set_xlabel("N (Plummer sphere)")
    ax.set_ylabel("seconds per force evaluation")
    ax.set_title(f"one evaluation; trees at median error {section['target_error']:g}, "
                 "direct sum exact")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    _save(fig, path)


#: the accretion runs' styles: (label, colour, line style)
ACCRETION_STYLE = {
    "rebound": ("REBOUND, line search + merge", "black", "-"),
    "end": ("engine, resolve_at='end'", "tab:orange", "--"),
    "contact": ("engine, at the moment of contact", "tab:blue", ":"),
}


def contact(section, path):
    """Left: the gas's speeds (histogram, in units of sqrt(kT)) against the Maxwell-Boltzmann
    law of each dimension. Right: merges done by each step in the three accretion runs."""
    from .contact import speed_cdf

    fig, (left, right) = plt.subplots(1, 2, figsize=(11.0, 4.0), layout="constrained")
    for (name, g), colour in zip(section["gas"].items(), ("tab:blue", "tab:red")):
        bins = np.array(g["speed_bins"])
        counts = np.array(g["speed_counts"])
        density = counts / (counts.sum() * np.diff(bins))
        left.stairs(density, bins, color=colour, label=f"{name}, {g['n']} spheres")
        x = np.linspace(bins[0], bins[-1], 200)
        pdf = np.gradient(speed_cdf(x, g["dim"], 1.0), x)
        left.plot(x, pdf, color=colour, ls="--", lw=1,
                  label="Rayleigh" if g["dim"] == 2 else "Maxwell")
    left.set_xlabel("speed / sqrt(kT/m)")
    left.set_ylabel("probability density")
    left.set_title("hard-sphere gas after relaxing (started at one speed)")
    left.legend(fontsize=8)
    a = section["accretion"]
    for name, run in a["runs"].items():
        label, colour, ls = ACCRETION_STYLE[name]
        right.step([0] + a["marks"], [0] + run["merges_by_step"], where="post", color=colour,
                   ls=ls, label=label)
    right.set_xlabel("step")
    right.set_ylabel("merges done")
    right.set_title(f"accretion: {a['n']} planetesimals, leapfrog, dt = {a['dt']:g}")
    right.legend(fontsize=8)
    for ax in (left, right):
        ax.grid(True, alpha=0.3)
    _save(fig, path)
