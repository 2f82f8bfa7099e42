"""Section 1: direct-sum gravity (leapfrog + ``NBodyGravity``) against REBOUND's leapfrog, with
pair interactions per second, single precision, and the pair kernel alone against the loop that
visits each pair from both ends (the engine's former kernel)."""
import math

import numpy as np

from .timing import repeats, side_by_side

NAME = "direct"
KEYS = ("direct_sum",)
NEEDS = ("rebound",)


def run(quick):
    sizes = [256, 1024] if quick else [256, 1024, 4096]
    return {"direct_sum": bench_direct_sum(sizes, repeats(quick))}


def random_cluster(n, seed=1):
    rng = np.random.default_rng(seed)
    return (np.full(n, 1.0 / n), rng.normal(size=(n, 3)), rng.normal(size=(n, 3)) * 0.1)


def engine_nbody(n, integrator="leapfrog", dt=1e-4, softening=0.01, precision="float64"):
    from engine import Simulation, forces

    mass, pos, vel = random_cluster(n)
    sim = Simulation(dim=3, integrator=integrator, dt=dt, capacity=n)
    sim.add_many(mass=mass, pos=pos, vel=vel)
    sim.add_force(forces.NBodyGravity(softening=softening, precision=precision))
    sim.step(1)  # compile / load
    return sim


def _rebound_nbody(n, dt=1e-4, softening=0.01):
    import rebound

    mass, pos, vel = random_cluster(n)
    sim = rebound.Simulation()
    sim.integrator = "leapfrog"
    sim.gravity = "basic"
    sim.softening = softening
    sim.dt = dt
    for i in range(n):
        sim.add(m=mass[i], x=pos[i, 0], y=pos[i, 1], z=pos[i, 2],
                vx=vel[i, 0], vy=vel[i, 1], vz=vel[i, 2])
    sim.steps(1)
    return sim


def _both_ends_loop():
    """The direct sum as the engine computed it before it took each pair once: every target
    against every source over contiguous coordinate arrays, vectorised by the compiler,
    targets over all cores, each pair visited from both ends. No masks, gathers or padding (so
    a little faster than the former kernel, which dropped a particle's own slot by a select):
    the reference the engine's pair kernel is held to, side by side."""
    from numba import njit, prange

    @njit(parallel=True, fastmath={"reassoc", "contract", "nsz", "arcp"}, error_model="numpy")
    def both_ends(x, y, z, beta, eps2, ax, ay, az):
        n = x.shape[0]
        for c in prange(n):
            sx = 0.0
            sy = 0.0
            sz = 0.0
            for j in range(n):
                dx = x[j] - x[c]
                dy = y[j] - y[c]
                dz = z[j] - z[c]
                r2 = dx * dx + dy * dy + dz * dz + eps2
                w = beta[j] / (r2 * math.sqrt(r2))
                sx += w * dx
                sy += w * dy
                sz += w * dz
            ax[c] = sx
            ay[c] = sy
            az[c] = sz

    return both_ends


def kernel_against_both_ends(n, repeats, eps2=1e-4):
    """The engine's pair kernel (``engine.forces.pairwise.field``, each pair once, on all
    cores) against ``_both_ends_loop`` on the same n bodies, side by side: the median ratio of
    their times, and the largest difference of their fields relative to the field's size."""
    from engine.forces import pairwise

    both_ends = _both_ends_loop()
    mass, pos, _ = random_cluster(n)
    work = np.zeros(pairwise.float_count(n))
    s = pairwise.stride(n, 8)
    x, y, z, alpha, beta = (work[k * s:k * s + n] for k in range(5))
    acc = work[5 * s:]
    x[:], y[:], z[:] = pos.T
    alpha[:] = 1.0
    beta[:] = mass
    reference = [np.empty(n) for _ in range(3)]
    steps = max(1, int(2e7 / (n * n)))

    def ours():
        for _ in range(steps):
            pairwise.field(x, y, z, alpha, beta, n, n, eps2, 0.0, acc, s)

    def theirs():
        for _ in range(steps):
            both_ends(x, y, z, beta, eps2, *reference)

    ours()
    theirs()
    field = np.array([acc[k * s:k * s + n] for k in range(3)])
    difference = float(np.abs(field - np.array(reference)).max() / np.abs(field).max())
    t_ours, t_ref, ratio = side_by_side(ours, theirs, repeats)
    return 1e3 * t_ours / steps, 1e3 * t_ref / steps, ratio, difference


def bench_direct_sum(sizes, repeats):
    rows = []
    for n in sizes:
        steps = max(1, int(2e7 / (n * n)))
        ours = engine_nbody(n)
        ref = _rebound_nbody(n)
        t_ours, t_ref, ratio = side_by_side(lambda: ours.step(steps), lambda: ref.steps(steps),
                                            repeats)
        single = engine_nbody(n, precision="float32")
        t_single, _, ratio_single = side_by_side(lambda: single.step(steps),
                                                 lambda: ref.steps(steps), repeats)
        kernel_ms, both_ends_ms, kernel_ratio, difference = kernel_against_both_ends(n, repeats)
        per_step = t_ours / steps
        rows.append({
            "n": n, "steps": steps, "engine_ms_per_step": 1e3 * per_step,
            "rebound_ms_per_step": 1e3 * t_ref / steps, "speedup_vs_rebound": ratio,
            "float32_ms_per_step": 1e3 * t_single / steps,
            "float32_speedup_vs_rebound": ratio_single,
            # each unique pair is one interaction, evaluated once
            "pairs_per_second": n * (n - 1) / 2 / per_step,
            "kernel_ms": kernel_ms, "both_ends_ms": both_ends_ms,
            "kernel_speedup_vs_both_ends": kernel_ratio,
            "kernel_difference_vs_both_ends": difference,
        })
    return {"rows": rows}


def text(r):
    lines = []
    d = r["direct_sum"]
    lines.append("\n1. direct-sum gravity, leapfrog (median of side-by-side repetitions)")
    lines.append(f"{'N':>6}{'engine ms/step':>16}{'REBOUND ms/step':>17}{'speed-up':>10}"
                 f"{'pairs/s':>11}{'float32 ms/step':>17}{'speed-up':>10}"
                 f"{'kernel ms':>11}{'both-ends ms':>14}{'speed-up':>10}")
    for row in d["rows"]:
        lines.append(f"{row['n']:>6}{row['engine_ms_per_step']:>16.3f}"
                     f"{row['rebound_ms_per_step']:>17.3f}{row['speedup_vs_rebound']:>9.1f}x"
                     f"{row['pairs_per_second']:>11.2e}"
                     f"{row['float32_ms_per_step']:>17.3f}"
                     f"{row['float32_speedup_vs_rebound']:>9.1f}x"
                     f"{row['kernel_ms']:>11.3f}{row['both_ends_ms']:>14.3f}"
                     f"{row['kernel_speedup_vs_both_ends']:>9.2f}x")
    lines.append("kernel: the pair kernel alone (each pair once) against the former "
                 "both-ends loop, all cores, same arrays")
    return lines


def markdown(r):
    out = []
    d = r["direct_sum"]
    out += ["## 1. Direct-sum gravity (leapfrog + NBodyGravity, float64)", "",
            "| N | engine ms/step | REBOUND ms/step | speed-up | pairs/s "
            "| float32 ms/step | float32 speed-up | pair kernel ms | both-ends loop ms "
            "| kernel speed-up |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    for row in d["rows"]:
        out.append(f"| {row['n']} | {row['engine_ms_per_step']:.3f} | {row['rebound_ms_per_step']:.3f} "
                   f"| {row['speedup_vs_rebound']:.1f}x | {row['pairs_per_second']:.2e} "
                   f"| {row['float32_ms_per_step']:.3f} "
                   f"| {row['float32_speedup_vs_rebound']:.1f}x | {row['kernel_ms']:.3f} "
                   f"| {row['both_ends_ms']:.3f} | {row['kernel_speedup_vs_both_ends']:.2f}x |")
    worst = max(row["kernel_difference_vs_both_ends"] for row in d["rows"])
    out += ["", "The last three columns time the pair kernel alone "
                "(`engine.forces.pairwise.field`, each pair once, all cores) against the "
                "loop the engine used before, which visits each pair from both ends "
                "(compiled the same way, without the former kernel's self-pair select, so "
                "a little faster than it was), on the same arrays, side by side; their fields "
                f"agree to {worst:.1e} of the field's size. The float32 columns are the same "
                "scene with `NBodyGravity(precision=\"float32\")` (pair sums in single "
                "precision, twice the lanes per instruction of float64).", ""]
    return out


def targets(r):
    rows = []
    d = {row["n"]: row for row in r.get("direct_sum", {}).get("rows", [])}
    if 1024 in d:
        others = ", ".join(f"{row['speedup_vs_rebound']:.1f}x at {n}" for n, row in d.items()
                           if n != 1024)
        rows.append(("direct sum at N = 1024: the pair kernel at least 1.6x the former "
                     "both-ends loop, side by side",
                     f"{d[1024]['kernel_speedup_vs_both_ends']:.2f}x; the whole step "
                     f"{d[1024]['speedup_vs_rebound']:.1f}x REBOUND's ({others})",
                     d[1024]["kernel_speedup_vs_both_ends"] >= 1.6))
    return rows
