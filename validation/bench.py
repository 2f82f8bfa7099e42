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
8. ``spacewar.learning.LearningBatch``: 4096 matches stepped with observations and rewards,
   at 1 thread and at every thread;
9. the planetary integrators on the outer solar system (Sun, four giants and Pluto): time per
   step of the engine's ``whfast`` with corrector 11 and of ``ias15`` (epsilon 1e-9) against
   REBOUND's, side by side;
10. tournaments and sweeps on Dask (``bench_cluster``);
11. the tree's gravity, by its fast multipole walk (``NBodyGravity(method="fmm")``) and its
    Barnes-Hut walk (``method="tree"``), on a Plummer sphere against pytreegrav's and
    REBOUND's trees at equal median force error, its scaling with N, its crossover with the
    direct sum and its memory (``tree_bench``);
12. contact: a hard-sphere gas's collisions found and resolved, against REBOUND's tree
    collision search on the same scene (``contact_bench``).
"""
import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from engine.atomic import OutputPathError, atomic_write, check_output_path

SOLAR_MASS = 4.0 * math.pi ** 2
DAYS_PER_YEAR = 365.24
# The Benchmarks Game n-body initial conditions (Sun, Jupiter, Saturn, Uranus, Neptune), in
# AU, AU/year and solar masses (times 4 pi^2), as published with the benchmark.
NBODY_BODIES = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
    [4.84143144246472090e+00, -1.16032004402742839e+00, -1.03622044471123109e-01,
     1.66007664274403694e-03, 7.69901118419740425e-03, -6.90460016972063023e-05,
     9.54791938424326609e-04],
    [8.34336671824457987e+00, 4.12479856412430479e+00, -4.03523417114321381e-01,
     -2.76742510726862411e-03, 4.99852801234917238e-03, 2.30417297573763929e-05,
     2.85885980666130812e-04],
    [1.28943695621391310e+01, -1.51111514016986312e+01, -2.23307578892655734e-01,
     2.96460137564761618e-03, 2.37847173959480950e-03, -2.96589568540237556e-05,
     4.36624404335156298e-05],
    [1.53796971148509165e+01, -2.59193146099879641e+01, 1.79258772950371181e-01,
     2.68067772490389322e-03, 1.62824170038242295e-03, -9.51592254519715870e-05,
     5.15138902046611451e-05],
])


def nbody_state():
    b = NBODY_BODIES
    pos = b[:, :3].copy()
    vel = b[:, 3:6] * DAYS_PER_YEAR
    mass = b[:, 6] * SOLAR_MASS
    # the benchmark first removes the total momentum through the Sun
    vel[0] -= (mass[:, None] * vel).sum(axis=0) / mass[0]
    return pos, vel, mass


def _timed(fn):
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def side_by_side(ours, reference, repeats):
    """Median of per-repetition ratios reference/ours, and the median times."""
    t_ours, t_ref, ratios = [], [], []
    for _ in range(repeats):
        a = _timed(ours)
        b = _timed(reference)
        t_ours.append(a)
        t_ref.append(b)
        ratios.append(b / a)
    return statistics.median(t_ours), statistics.median(t_ref), statistics.median(ratios)


# -- 1. direct-sum gravity ---------------------------------------------------------------
def _cluster(n, seed=1):
    rng = np.random.default_rng(seed)
    return (np.full(n, 1.0 / n), rng.normal(size=(n, 3)), rng.normal(size=(n, 3)) * 0.1)


def _engine_nbody(n, integrator="leapfrog", dt=1e-4, softening=0.01, precision="float64"):
    from engine import Simulation, forces

    mass, pos, vel = _cluster(n)
    sim = Simulation(dim=3, integrator=integrator, dt=dt, capacity=n)
    sim.add_many(mass=mass, pos=pos, vel=vel)
    sim.add_force(forces.NBodyGravity(softening=softening, precision=precision))
    sim.step(1)  # compile / load
    return sim


def _rebound_nbody(n, dt=1e-4, softening=0.01):
    import rebound

    mass, pos, vel = _cluster(n)
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


def _kernel_against_both_ends(n, repeats, eps2=1e-4):
    """The engine's pair kernel (``engine.forces.pairwise.field``, each pair once, on all
    cores) against ``_both_ends_loop`` on the same n bodies, side by side: the median ratio of
    their times, and the largest difference of their fields relative to the field's size."""
    from engine.forces import pairwise

    both_ends = _both_ends_loop()
    mass, pos, _ = _cluster(n)
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
        ours = _engine_nbody(n)
        ref = _rebound_nbody(n)
        t_ours, t_ref, ratio = side_by_side(lambda: ours.step(steps), lambda: ref.steps(steps),
                                            repeats)
        single = _engine_nbody(n, precision="float32")
        t_single, _, ratio_single = side_by_side(lambda: single.step(steps),
                                                 lambda: ref.steps(steps), repeats)
        kernel_ms, both_ends_ms, kernel_ratio, difference = _kernel_against_both_ends(n, repeats)
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


# -- 2. the Benchmarks Game n-body ------------------------------------------------------
def _plain_loop():
    from numba import njit

    @njit(cache=False)
    def advance(pos, vel, mass, steps, dt):
        n = mass.shape[0]
        for _ in range(steps):
            for i in range(n):
                for j in range(i + 1, n):
                    dx = pos[i, 0] - pos[j, 0]
                    dy = pos[i, 1] - pos[j, 1]
                    dz = pos[i, 2] - pos[j, 2]
                    d2 = dx * dx + dy * dy + dz * dz
                    mag = dt / (d2 * math.sqrt(d2))
                    mj = mass[j] * mag
                    mi = mass[i] * mag
                    vel[i, 0] -= dx * mj
                    vel[i, 1] -= dy * mj
                    vel[i, 2] -= dz * mj
                    vel[j, 0] += dx * mi
                    vel[j, 1] += dy * mi
                    vel[j, 2] += dz * mi
            for i in range(n):
                pos[i, 0] += dt * vel[i, 0]
                pos[i, 1] += dt * vel[i, 1]
                pos[i, 2] += dt * vel[i, 2]

    return advance


def bench_small_n(steps, repeats):
    import rebound
    from engine import Simulation, forces

    pos, vel, mass = nbody_state()
    sim = Simulation(dim=3, integrator="symplectic_euler", dt=0.01)
    sim.add_many(mass=mass, pos=pos, vel=vel)
    sim.add_force(forces.NBodyGravity())
    sim.step(10)
    plain = _plain_loop()
    p, v = pos.copy(), vel.copy()
    plain(p, v, mass, 10, 0.01)
    reb = rebound.Simulation()
    reb.integrator = "leapfrog"  # one force evaluation per step, like symplectic Euler
    reb.dt = 0.01
    for i in range(5):
        reb.add(m=mass[i], x=pos[i, 0], y=pos[i, 1], z=pos[i, 2], vx=vel[i, 0], vy=vel[i, 1],
                vz=vel[i, 2])
    reb.steps(10)
    t_sim, t_plain, vs_plain = side_by_side(lambda: sim.step(steps),
                                            lambda: plain(p, v, mass, steps, 0.01), repeats)
    _, t_reb, vs_reb = side_by_side(lambda: sim.step(steps), lambda: reb.steps(steps), repeats)
    # the engine's result is the same computation as the plain loop's
    check = Simulation(dim=3, integrator="symplectic_euler", dt=0.01)
    check.add_many(mass=mass, pos=pos, vel=vel)
    check.add_force(forces.NBodyGravity())
    check.step(1000)
    p2, v2 = pos.copy(), vel.copy()
    plain(p2, v2, mass, 1000, 0.01)
    return {
        "steps": steps,
        "engine_steps_per_second": steps / t_sim,
        "plain_loop_steps_per_second": steps / t_plain,
        "rebound_leapfrog_steps_per_second": steps / t_reb,
        "engine_time_over_plain_loop": 1.0 / vs_plain,
        "speedup_vs_rebound": vs_reb,
        "max_position_difference_vs_plain_after_1000_steps": float(np.abs(check.pos - p2).max()),
    }


# -- 3. scaling ---------------------------------------------------------------------------
def _time_per_step(sim, budget=0.25):
    steps = 1
    while True:
        t = _timed(lambda: sim.step(steps))
        if t > budget or steps > 1 << 20:
            return t / steps
        steps *= 4


def bench_scaling(max_n):
    from engine import Simulation, forces

    sizes = [2 ** k for k in range(1, int(math.log2(max_n)) + 1)]
    direct, tests = [], []
    for n in sizes:
        direct.append(_time_per_step(_engine_nbody(n)))
        rng = np.random.default_rng(n)
        sim = Simulation(dim=3, integrator="leapfrog", dt=1e-3, capacity=n + 4)
        sim.add_many(mass=1.0, pos=rng.normal(size=(4, 3)) * 3)
        sim.add_many(mass=0.0, pos=rng.normal(size=(n, 3)) * 10, test=True)
        sim.add_force(forces.NBodyGravity(softening=0.01))
        sim.step(1)
        tests.append(_time_per_step(sim))

    def slope(ns, ts, smallest):
        keep = [i for i, n in enumerate(ns) if n >= smallest]
        return float(np.polyfit(np.log(np.array(ns)[keep]), np.log(np.array(ts)[keep]), 1)[0])

    return {"n": sizes, "direct_seconds_per_step": direct, "test_seconds_per_step": tests,
            "direct_slope_large_n": slope(sizes, direct, 1024),
            "test_particle_slope_large_n": slope(sizes, tests, 1024)}


# -- 4. declared terms ----------------------------------------------------------------------
def bench_terms(n=128, repeats=5):
    from engine import Simulation, forces

    sets = {
        "1: gravity": lambda: [forces.NBodyGravity(softening=0.01)],
        "2: + drag": lambda: [forces.NBodyGravity(softening=0.01), forces.Drag(linear=0.01)],
        "4: + uniform gravity, Coulomb": lambda: [
            forces.NBodyGravity(softening=0.01), forces.Drag(linear=0.01),
            forces.UniformGravity(g=(0.0, -1.0, 0.0)), forces.Coulomb(k=0.1, softening=0.01)],
    }
    out = {}
    mass, pos, vel = _cluster(n)
    charge = np.random.default_rng(2).choice([-1.0, 1.0], n)
    for name, make in sets.items():
        sim = Simulation(dim=3, integrator="leapfrog", dt=1e-4)
        sim.add_many(mass=mass, pos=pos, vel=vel, charge=charge)
        for term in make():
            sim.add_force(term)
        sim.step(1)
        out[name] = statistics.median(_time_per_step(sim, budget=0.1) for _ in range(repeats))
    base = out["1: gravity"]
    return {"n": n, "seconds_per_step": out,
            "relative_to_gravity_alone": {k: v / base for k, v in out.items()}}


# -- 5. start-up ------------------------------------------------------------------------------
_STARTUP = """
import time
t0 = time.perf_counter()
import engine
from engine import Simulation, forces
sim = Simulation(dim=3, integrator="leapfrog", dt=0.01)
sim.add_many(mass=[1.0, 1e-3], pos=[(0, 0, 0), (1, 0, 0)], vel=[(0, 0, 0), (0, 1, 0)])
sim.add_force(forces.NBodyGravity())
sim.step(1)
print(time.perf_counter() - t0)
"""


#: the commands whose start-up is tracked, by name: ``python -m`` module and arguments (the
#: tournament is the README's first command, played in full: quick runs leave it out)
STARTUP_COMMANDS = {
    "python -m engine": ("engine",),
    "spacewar match": ("spacewar", "match", "--p1", "chaser", "--p2", "sniper", "--rounds", "1"),
    "README tournament": ("spacewar", "tournament", "--bots", "idle,random,chaser,sniper",
                          "--games", "10", "--seed", "1", "--no-progress"),
}


def _shown(name):
    """A start-up command as a user types it."""
    argv = STARTUP_COMMANDS[name]
    return "python -m engine" if argv == ("engine",) else " ".join(argv)


def _wall_seconds(argv, env):
    start = time.perf_counter()
    subprocess.run(argv, env=env, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def bench_startup(quick=False):
    """Start-up from an empty compiled-code cache (a first run after install, an upgrade or
    an edit of everything) and warm (the same command again): ``import engine`` plus a first
    step, and each of ``STARTUP_COMMANDS`` as a whole process, each in a cache of its own."""
    def run(env):
        out = subprocess.run([sys.executable, "-c", _STARTUP], env=env, capture_output=True,
                             text=True, check=True)
        return float(out.stdout.strip().splitlines()[-1])

    env = dict(os.environ)
    with tempfile.TemporaryDirectory() as cold:
        env["NUMBA_CACHE_DIR"] = cold
        cold_s = run(env)
        warm_s = run(env)  # the same (now filled) cache
    commands = {}
    for name, argv in STARTUP_COMMANDS.items():
        if quick and name == "README tournament":
            continue
        with tempfile.TemporaryDirectory() as cold:
            env["NUMBA_CACHE_DIR"] = cold
            full = [sys.executable, "-m", *argv]
            commands[name] = {"cold_seconds": _wall_seconds(full, env),
                              "warm_seconds": _wall_seconds(full, env)}
    return {"cold_cache_seconds": cold_s, "warm_cache_seconds": warm_s, "commands": commands}


#: measurements of ``python -m validation compile-times --out``, shown with the start-up
COMPILE_TIMES_DIR = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                 "docs", "compile_times")


def stored_compile_times():
    """``{file name: measurement}`` of the compile-time measurements kept in the docs (each
    made by ``python -m validation compile-times --out docs/compile_times/NAME.json -- ...``;
    they take a cold run of the command, the test suite's a whole run, so the bench shows the
    stored ones rather than measuring them again)."""
    found = {}
    try:
        names = sorted(n for n in os.listdir(COMPILE_TIMES_DIR) if n.endswith(".json"))
    except OSError:
        return found
    for name in names:
        with open(os.path.join(COMPILE_TIMES_DIR, name), encoding="utf-8") as f:
            found[name[:-5]] = json.load(f)
    return found


def compile_time_markdown(stored):
    """Markdown lines for the stored compile-time measurements: one row per command with its
    totals after and before the change (``NAME.json`` and ``NAME.before.json``), then each
    command's longest compiles after it, and before it."""
    from .compile_times import format_table

    after = {k: v for k, v in stored.items() if not k.endswith(".before")}
    if not after:
        return []

    def totals(m):
        return (f"{m['compile_seconds']:.1f} s in {len(m['functions'])} functions "
                f"({m['compilations']} compilations)")

    out = ["### What each command compiles, from an empty cache", "",
           "CPU seconds of compiling in one process (`python -m validation compile-times`; "
           "compiling ahead off), exclusive of the callees compiled inside each function.", "",
           "| command | before | after |", "|---|---|---|"]
    for name, m in after.items():
        before = stored.get(name + ".before")
        out.append(f"| `python -m {' '.join(m['command'])}` | "
                   f"{totals(before) if before else 'not measured'} | {totals(m)} |")
    out.append("")
    for name, m in after.items():
        out += [f"#### `python -m {' '.join(m['command'])}`", "", m.get("note", ""), "",
                format_table(m, top=25), ""]
        before = stored.get(name + ".before")
        if before:
            out += [f"Before ({before.get('note', '')}):", "", format_table(before, top=10), ""]
    return out


# -- 6. Spacewar -------------------------------------------------------------------------------
def bench_spacewar(matches=256, frames=2000, repeats=5):
    from spacewar import Game, Rules
    from spacewar.match import play_match

    play_match("chaser", "sniper", seed=1, rounds=1)  # compiled code loaded, bots' too
    # The same match inline and with both bots each in its own confined process (as untrusted
    # bots play), alternating, ``repeats`` times: frames per second once both seats are
    # ready, the start-up of the seats apart.
    inline_fps, confined_fps, ratios, startups = [], [], [], []
    for _ in range(repeats):
        result, _, timing = play_match("chaser", "sniper", seed=1, rounds=3)
        confined, _, confined_timing = play_match("chaser", "sniper", seed=1, rounds=3,
                                                  isolation="process")
        inline_fps.append(timing["play_frames_per_second"])
        confined_fps.append(confined_timing["play_frames_per_second"])
        ratios.append(confined_fps[-1] / inline_fps[-1])
        startups.append(confined_timing["startup_seconds"])
    # A confined bot can fault (a timeout on a loaded machine) and change the match: reported,
    # not asserted, so the rest of the bench still runs.
    agrees = confined["steps"] == result["steps"] and confined["score"] == result["score"]
    rng = np.random.default_rng(0)
    game = Game(Rules(), seeds=range(matches), rounds=1000)
    game.step(rng.integers(0, 48, size=(matches, 2)))
    codes = rng.integers(0, 48, size=(frames, matches, 2))
    start = time.perf_counter()
    for f in range(frames):
        game.step(codes[f])
    batch = time.perf_counter() - start
    single = Game(Rules(), seeds=[0], rounds=1000)
    start = time.perf_counter()
    for f in range(frames):
        single.step(codes[f, :1])
    alone = time.perf_counter() - start
    played = [f for f in confined_fps if f > 0]
    return {
        "one_match_with_bots": {"bots": result["bots"], "frames": result["steps"],
                                "frames_per_second": statistics.median(inline_fps)},
        "one_match_confined_bots": {
            "frames": confined["steps"],
            "repeats": repeats,
            "frames_per_second": statistics.median(confined_fps),
            # confined over inline, each pair measured one after the other
            "over_inline": statistics.median(ratios),
            "startup_seconds": statistics.median(startups),
            "wall_seconds": confined_timing["wall_seconds"],
            # None when the confined match played no frame (a bot that could not start)
            "slowdown": (statistics.median(inline_fps) / statistics.median(played)
                         if played else None),
            "agrees_with_inline": agrees,
            "faults": [seat["total"] for seat in confined["faults"]],
            "fault_kinds": [{k: n for k, n in seat.items() if isinstance(n, int) and n and
                             k != "total"} for seat in confined["faults"]],
            "forfeits": confined["forfeits"]},
        "one_match_no_bots_frames_per_second": frames / alone,
        "batch": {"matches": matches, "frames": frames,
                  "match_frames_per_second": matches * frames / batch},
        "confined_bot_ready_seconds": {spec: _confined_ready_seconds(spec, repeats)
                                       for spec in ("idle", "chaser", "sniper")},
    }


def _confined_ready_seconds(spec, repeats):
    """Median seconds from opening a confined seat for ``spec`` to its bot's being ready (its
    process started and confined, its module imported, the bot made and reset)."""
    from spacewar import Rules
    from spacewar.seats import Limits, ProcessSeat

    seconds = []
    for _ in range(repeats):
        start = time.perf_counter()
        seat = ProcessSeat(spec, 1, Limits(), Rules())
        fault = seat.wait_ready()
        seconds.append(time.perf_counter() - start if fault is None else math.inf)
        seat.close()
    return statistics.median(seconds)


def _each_thread_count():
    """1, then every thread numba has: numba's thread count set to each in turn while the
    caller measures, and put back afterwards."""
    import numba

    threads = numba.get_num_threads()
    try:
        for count in sorted({1, numba.config.NUMBA_NUM_THREADS}):
            numba.set_num_threads(count)
            yield count
    finally:
        numba.set_num_threads(threads)


# -- 7. Many systems per call: engine.Batch ----------------------------------------------------
def _batch_scene(systems, slots, seed=1):
    """The game's size and forces: 2 ships and slots - 2 test particles per system on the unit
    torus, a star (PointMass), ship gravity (NBodyGravity) and thrust, symplectic Euler."""
    rng = np.random.default_rng(seed)
    return {"pos": rng.uniform(-0.5, 0.5, (systems, slots, 2)),
            "vel": rng.normal(0.0, 1e-3, (systems, slots, 2)),
            "test": np.arange(slots) >= 2,
            "thrust": rng.normal(0.0, 1e-6, (systems, 2, 2))}


def _batch_terms():
    from engine import forces
    return [forces.PointMass(mu=2.5e-7, softening=4e-3),
            forces.NBodyGravity(G=1e-6, softening=1e-2), forces.Thrust()]


def bench_batch(systems=4096, slots=66, repeats=5):
    """Systems advanced per second: one ``Batch.step`` for all against one ``Simulation.step``
    per system, at 1 and at every thread; one frame (one step) per call, as a game takes."""
    from engine import Batch, Simulation

    scene = _batch_scene(systems, slots)
    batch = Batch(systems=systems, dim=2, integrator="symplectic_euler", dt=1.0, capacity=slots,
                  box=1.0)
    batch.add_many(mass=1.0, pos=scene["pos"], vel=scene["vel"], test=scene["test"])
    terms = [batch.add_force(t) for t in _batch_terms()]
    force = np.zeros((systems, slots, 2))
    force[:, :2] = scene["thrust"]
    batch.set_parameter(terms[-1], "force", force)
    sims = []
    for m in range(systems):
        sim = Simulation(dim=2, integrator="symplectic_euler", dt=1.0, capacity=slots, box=1.0)
        sim.add_many(mass=1.0, pos=scene["pos"][m], vel=scene["vel"][m], test=scene["test"])
        thrust = [sim.add_force(t) for t in _batch_terms()][-1]
        thrust.set(0, scene["thrust"][m, 0])
        thrust.set(1, scene["thrust"][m, 1])
        sims.append(sim)
    batch.step(2)  # compiled code loaded; every system two steps in, alone as in the batch
    for sim in sims:
        sim.step(2)

    def separate():
        for sim in sims:
            sim.step(1)

    rows = {}
    for count in _each_thread_count():
        t_batch, t_sims, ratio = side_by_side(lambda: batch.step(1), separate, repeats)
        rows[str(count)] = {"batch_systems_per_second": systems / t_batch,
                            "separate_simulations_per_second": systems / t_sims,
                            "speedup": ratio}
    # the same steps, the same numbers: the batch is bit-identical to the separate simulations
    same = all(np.array_equal(batch.pos[m], sims[m].pos) for m in range(0, systems, 97))
    return {"systems": systems, "slots": slots, "threads": rows,
            "bit_identical_to_separate": bool(same)}


# -- 8. Spacewar for learning code: spacewar.learning and spacewar.envs -----------------------
def _vector_env_rate(opponent, matches, frames, repeats, seed=1, copy=True):
    """Agent-steps per second of ``SpacewarVectorEnv(matches, ...).step`` with random actions
    (the env's own checks, the conversion of actions, observations, rewards and flags
    included; match-frames per second but in self-play, ``opponent=None``, where ``matches``
    agents are ``matches / 2`` matches) and the final observations, so that runs at different
    thread counts can be compared."""
    from spacewar.envs import SpacewarVectorEnv

    env = SpacewarVectorEnv(matches, opponent=opponent, max_frames=3000, copy=copy)
    env.reset(seed=seed)
    actions = np.random.default_rng(0).integers(0, [3, 2, 2, 2], size=(frames, matches, 4))
    env.step(actions[0])
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        for f in range(frames):
            obs = env.step(actions[f])[0]
        best = min(best, time.perf_counter() - start)
    return matches * frames / best, obs


def bench_learning(matches=4096, frames=50, repeats=5, opponents=("random", "chaser")):
    """Match-frames per second, at 1 thread and at every thread, with the results compared
    between the two: ``LearningBatch.step`` (random actions; observations, rewards,
    terminations and resets included) and ``SpacewarVectorEnv.step`` against each compiled
    opponent (the learner's actions random), and in self-play (both seats learners: agent-steps
    per second, two per match-frame). Each figure is the best of ``repeats`` runs: this
    machine's speed varies by up to 2x from one minute to the next."""
    from spacewar.learning import LearningBatch, compiled_bots

    codes = np.random.default_rng(0).integers(0, 24, size=(frames, matches, 2))
    opponents = [o for o in opponents if o in compiled_bots.KINDS]
    rows, finals = {}, []
    for count in _each_thread_count():
        batch = LearningBatch(matches, seed=1, rounds=3, frame_cap=3000)
        batch.step(codes[0])
        best = math.inf
        for _ in range(repeats):
            start = time.perf_counter()
            for f in range(frames):
                batch.step(codes[f])
            best = min(best, time.perf_counter() - start)
        row = {"match_frames_per_second": matches * frames / best}
        final = [batch.observations.copy()]
        for opponent in opponents:
            rate, obs = _vector_env_rate(opponent, matches, frames, repeats)
            row[f"vector_env_vs_{opponent}_match_frames_per_second"] = rate
            final.append(obs.copy())
        rate, obs = _vector_env_rate("random", matches, frames, repeats, copy=False)
        row["vector_env_vs_random_no_copy_match_frames_per_second"] = rate
        final.append(obs.copy())
        rate, obs = _vector_env_rate(None, 2 * matches, frames, repeats)  # 2 agents a match
        row["vector_env_self_play_agent_steps_per_second"] = rate
        final.append(obs.copy())
        rows[str(count)] = row
        finals.append(final)
    same = all(np.array_equal(a, b) for other in finals[1:] for a, b in zip(finals[0], other))
    return {"matches": matches, "opponents": opponents, "threads": rows,
            "identical_across_threads": bool(same), "harness": bench_harness()}


def bench_harness(rounds=1, repeats=5):
    """One match between two idle Python bots: the harness's own cost per frame, i.e. the
    match's wall time per frame less the two bots' ``act`` calls (timed alone on the same
    observations)."""
    from spacewar import Game, Rules
    from spacewar.bots.idle import Idle
    from spacewar.match import play_match

    play_match("idle", "idle", seed=1, rounds=1)  # compiled code loaded
    per_frame = math.inf
    for _ in range(repeats):
        result, _, timing = play_match("idle", "idle", seed=1, rounds=rounds)
        per_frame = min(per_frame, timing["wall_seconds"] / result["steps"])
    game = Game(Rules(), seeds=[1], rounds=rounds)
    bot = Idle()
    obs = game.observe(0, 0)
    calls = 20000
    act = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(calls):
            bot.act(obs)
        act = min(act, (time.perf_counter() - start) / calls)
    return {"frames": result["steps"], "seconds_per_frame": per_frame,
            "act_seconds": act, "harness_seconds_per_frame": per_frame - 2 * act}


# -- 9. Planetary integrators: whfast and ias15 against REBOUND's ------------------------------
#: whfast's step on the outer solar system, in days (about 1/217 of Jupiter's period)
PLANETS_DT = 20.0
PLANETS_EPSILON = 1e-9


def _per_step_side_by_side(ours, reference, repeats):
    """Like ``side_by_side`` for calls that return how many steps they took: the median times
    per step and the median of the per-repetition ratios of time per step, ours / reference."""
    t_ours, t_ref, ratios = [], [], []
    for _ in range(repeats):
        start = time.perf_counter()
        n_ours = ours()
        a = (time.perf_counter() - start) / n_ours
        start = time.perf_counter()
        n_ref = reference()
        b = (time.perf_counter() - start) / n_ref
        t_ours.append(a)
        t_ref.append(b)
        ratios.append(a / b)
    return statistics.median(t_ours), statistics.median(t_ref), statistics.median(ratios)


def _relative_difference(sim, run):
    """Largest position difference of the two codes' states over the largest coordinate."""
    pos, _ = run.state()
    return float(np.abs(sim.pos - pos).max() / np.abs(pos).max())


def bench_planets(steps, span_days, repeats):
    """The outer solar system of the report's work-precision section (Hairer, Lubich & Wanner;
    AU, days, solar masses), in both codes from the same heliocentric state.

    - ``whfast`` with corrector 11, dt = 20 days: ``sim.step(steps)`` against REBOUND's WHFast
      (corrector 11, Jacobi coordinates, ``safe_mode = 0``) ``steps(steps)`` followed by
      ``synchronize()``: both apply the corrector and synchronise once per call, REBOUND's
      fastest use of it (with ``safe_mode = 1`` it applies the corrector at every step);
    - ``ias15`` at epsilon 1e-9: ``sim.integrate(t + span)`` against REBOUND's
      ``integrate(t + span)``, per step each code took (their adaptive steps differ slightly).
    """
    from validation.problems import make_sim, outer_solar_system
    from validation.reference import RebRun

    p = outer_solar_system()
    rows = {}
    sim = make_sim(p, "whfast", PLANETS_DT, options={"corrector": 11})
    run = RebRun(p, "whfast", dt=PLANETS_DT, options={"corrector": 11, "safe_mode": 0})
    sim.step(10)  # compiled code loaded
    run.steps(10)

    def engine_whfast():
        sim.step(steps)
        return steps

    def rebound_whfast():
        run.steps(steps)
        return steps

    ours, ref, ratio = _per_step_side_by_side(engine_whfast, rebound_whfast, repeats)
    rows["whfast_c11"] = {
        "method": "whfast, corrector 11", "dt_days": PLANETS_DT, "steps_per_call": steps,
        "engine_us_per_step": 1e6 * ours, "rebound_us_per_step": 1e6 * ref,
        "time_over_rebound": ratio, "steps_engine": sim.steps,
        "steps_rebound": int(run.sim.steps_done),
        "relative_position_difference": _relative_difference(sim, run)}

    sim = make_sim(p, "ias15", PLANETS_DT, tolerance=PLANETS_EPSILON)
    run = RebRun(p, "ias15", epsilon=PLANETS_EPSILON)
    sim.integrate(10 * PLANETS_DT)
    run.integrate(10 * PLANETS_DT)

    def engine_ias15():
        before = sim.steps
        sim.integrate(sim.t + span_days)
        return sim.steps - before

    def rebound_ias15():
        before = run.sim.steps_done
        run.integrate(run.t + span_days)
        return run.sim.steps_done - before

    ours, ref, ratio = _per_step_side_by_side(engine_ias15, rebound_ias15, repeats)
    rows["ias15"] = {
        "method": f"ias15, epsilon {PLANETS_EPSILON:g}", "span_days_per_call": span_days,
        "engine_us_per_step": 1e6 * ours, "rebound_us_per_step": 1e6 * ref,
        "time_over_rebound": ratio, "steps_engine": sim.steps,
        "steps_rebound": int(run.sim.steps_done), "t_days": sim.t,
        "relative_position_difference": _relative_difference(sim, run)}
    return {"problem": "outer solar system (Sun, Jupiter, Saturn, Uranus, Neptune, Pluto)",
            "rows": rows}


# -- the machine --------------------------------------------------------------------------------
def machine():
    import numba

    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    info = {"cpu": cpu, "cores": os.cpu_count(), "numba_threads": numba.get_num_threads(),
            "python": platform.python_version(), "numpy": np.__version__,
            "numba": numba.__version__, "platform": platform.platform()}
    try:
        import llvmlite.binding as llvm

        info["llvm_cpu"] = llvm.get_host_cpu_name()
    except Exception:  # informational only
        pass
    try:
        import rebound

        info["rebound"] = rebound.__version__
    except ImportError:
        pass
    return info


def run(quick=False, sections=None):
    sections = sections or ["direct", "small", "scaling", "terms", "startup", "spacewar", "batch",
                            "learning", "planets", "cluster", "tree", "contact"]
    repeats = 3 if quick else 7
    report = {"machine": machine(), "quick": quick}
    if "direct" in sections:
        report["direct_sum"] = bench_direct_sum([256, 1024] if quick else [256, 1024, 4096], repeats)
    if "small" in sections:
        report["small_n"] = bench_small_n(100_000 if quick else 400_000, repeats)
    if "scaling" in sections:
        report["scaling"] = bench_scaling(2048 if quick else 16384)
    if "terms" in sections:
        report["terms"] = bench_terms(repeats=3 if quick else 5)
    if "startup" in sections:
        report["startup"] = bench_startup(quick)
        report["compile_times"] = stored_compile_times()
    if "spacewar" in sections:
        report["spacewar"] = bench_spacewar(64 if quick else 256, 500 if quick else 2000,
                                            3 if quick else 5)
    if "batch" in sections:
        report["batch"] = bench_batch(1024 if quick else 4096, repeats=3 if quick else 5)
    if "learning" in sections:
        report["learning"] = bench_learning(1024 if quick else 4096)
    if "planets" in sections:
        report["planets"] = bench_planets(20_000 if quick else 100_000,
                                          2e5 if quick else 1e6, repeats)
    if "cluster" in sections:
        from .bench_cluster import bench_cluster

        report["cluster"] = bench_cluster(quick)
    if "tree" in sections:
        from .tree_bench import SIZES, measure

        report["tree"] = measure(SIZES["quick" if quick else "full"],
                                 progress=lambda text: print(text, file=sys.stderr))
    if "contact" in sections:
        from . import contact_bench

        report["contact"] = contact_bench.measure(
            contact_bench.SIZES["quick" if quick else "full"], repeats=3,
            progress=lambda text: print(text, file=sys.stderr))
    return report


HOW_THE_TARGETS_ARE_MET = """How the engine gets there (the figures are this run's, in the tables below):

- **Direct sum.** From `pairwise.PARALLEL_MIN` (12) bodies on, the active particles are copied
  into contiguous coordinate arrays (each block padded to an odd number of cache lines) and
  the pair sum takes each pair once, in register tiles: four sources are held in registers
  while one pass over the targets below them, vectorised by LLVM, adds the four pulls into
  each target's accumulator and gathers the four reactions in scalar sums. (Writing the
  reaction into the other body inside the loop, the obvious form, does not vectorise; the
  engine used to visit each pair from both ends instead.) The pair triangle is cut into four
  row ranges of equal work with their own accumulators, added in a fixed order, so the result
  is the same to the bit on any number of threads; from `pairwise.THREADS_MIN` (192) bodies
  the ranges are spread over all cores. Section 1's last columns hold the kernel against the
  both-ends loop, side by side.
- **Five bodies.** A scene that is one open-space `NBodyGravity` term on fewer than 12 bodies
  runs a fused executor (`engine/integrators/fused_gravity.py`): the same drift/kick sequence and
  the same pair loop on an interleaved (n, 3) copy of the state, gravity inlined, finiteness
  checked once per 64 steps (a failed block is re-run step by step to stop at the last finite
  state). It is bit-identical to the general executor, without what that one pays per step:
  the force-table call with its array arguments, the strided (dim, n) indexing and the
  per-step save and check. Section 2 holds it against a plain hand-written numba loop.
- **Single precision, optional.** `NBodyGravity(precision="float32")` runs the same kernel on
  float32 copies of the coordinates, in a frame centred on the bodies' mean position and
  scaled by a power of two to their extent (any units: SI distances would overflow r^3 in
  float32 otherwise), with twice the lanes per instruction of float64; section 1's float32
  columns time it, and the tests check its forces against the float64 ones.
  State, small-N loop and energies stay float64.
- **Start-up.** A first run compiles what it uses and nothing else: its integrator, and the
  kernels of the force terms its scene declares (the force table calls them through their
  addresses, so no integrator carries ten force kernels inlined; a kernel is compiled for one
  signature, when a scene first declares its term; a function called from compiled code with a
  constant is compiled once for the constant's type, not once per constant). Each compiled
  function is cached under a key of the sources it is built from, so an edit recompiles only
  what is built from the edited file (section 5's cold figures are the first run after an
  install; after an edit of one force module a run recompiles that module's kernels at most).
  `python -m engine` compiles its integrators in one process per core on its first run, and
  `python -m engine compile` / `spacewar compile` fill the cache ahead (CI runs them). The
  tables under section 5 list what each command compiles, function by function.
- **What compiling costs now** (measured on this machine on 2026-12-05, one process,
  `python -m validation compile-times`; the tables below). The tour compiles for 56 s of CPU
  (275 s before this work), the first match for 25 s (57 s). numba links a compiled callee's
  code into every caller and optimises and emits it again there, up the whole chain: the
  Wisdom-Holman kernels therefore call their operators (steps loop, kick, lazy corrector,
  drift, the drift's fallback) through addresses made in Python for the scene's mode and
  scheme (`engine/address_calls.py`, as the force table calls its kernels), so each operator
  is compiled once and a scene compiles only the ones it uses (a Kepler problem: 62 s of
  Wisdom-Holman and drift code before, 14 s now); IAS15 runs in one kernel without
  reference counting.
  What is left is mostly numba's own front end, not LLVM's optimiser: with LLVM's
  optimisation off (`NUMBA_OPT=0`) the tour still compiles for 48 s, and typing, inlining and
  lowering each integrator's loop is what remains. The game's frame (`spacewar.core.step_match`,
  10 s) is compiled once and inlined by LLVM into its three callers. What each command compiled
  and never used before this work is gone: all ten force kernels inlined into every integrator
  (four copies in the Wisdom-Holman kick), the fused-gravity executor in scenes that cannot
  take it, numba's formatting of shape errors in `rk4` and `rk45`, a second specialisation per
  constant argument."""


def targets(r):
    """The performance targets against this run's figures: (target, measured, met) rows."""
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
    if "small_n" in r:
        s = r["small_n"]
        rows.append(("Benchmarks Game n-body: within 1.3x of a plain numba loop",
                     f"{s['engine_time_over_plain_loop']:.2f}x the plain loop's time",
                     s["engine_time_over_plain_loop"] <= 1.3))
        rows.append(("Benchmarks Game n-body: at least 2x faster than REBOUND",
                     f"{s['speedup_vs_rebound']:.2f}x", s["speedup_vs_rebound"] >= 2.0))
    if "scaling" in r:
        s = r["scaling"]
        rows.append(("scaling slope about 2 (direct) and about 1 (test particles)",
                     f"{s['direct_slope_large_n']:.2f} and {s['test_particle_slope_large_n']:.2f}",
                     abs(s["direct_slope_large_n"] - 2) < 0.25
                     and abs(s["test_particle_slope_large_n"] - 1) < 0.25))
    if "terms" in r:
        rel = list(r["terms"]["relative_to_gravity_alone"].values())
        rows.append(("step cost follows the declared terms",
                     ", ".join(f"{x:.2f}x" for x in rel) + " for 1, 2, 4 terms",
                     all(b >= a * 0.95 for a, b in zip(rel, rel[1:]))))
    if "learning" in r:
        g = r["learning"]
        fastest = max(g["threads"].values(), key=lambda row: row["match_frames_per_second"])
        for opponent, goal in (("random", 2e6), ("chaser", 1e6)):
            key = f"vector_env_vs_{opponent}_match_frames_per_second"
            if key in fastest:
                rows.append((f"SpacewarVectorEnv.step vs {opponent}, {g['matches']} matches: "
                             f"at least {goal:.0e} match-frames/s", f"{fastest[key]:.2e}",
                             fastest[key] >= goal))
        key = "vector_env_self_play_agent_steps_per_second"
        if key in fastest:
            rows.append((f"SpacewarVectorEnv.step in self-play, {g['matches']} matches: at least "
                         "4e+06 agent-steps/s", f"{fastest[key]:.2e}", fastest[key] >= 4e6))
        h = g["harness"]["harness_seconds_per_frame"]
        rows.append(("one match of two idle Python bots: the harness's own cost at most 10 us "
                     "per frame", f"{h * 1e6:.1f} us", h <= 10e-6))
    if "spacewar" in r:
        conf = r["spacewar"]["one_match_confined_bots"]
        if conf.get("over_inline") is not None:
            rows.append(("one match, both bots confined: at least 0.5 of the inline frame rate "
                         "once the seats are ready", f"{conf['over_inline']:.2f}",
                         conf["over_inline"] >= 0.5))
        ready = r["spacewar"].get("confined_bot_ready_seconds", {})
        for spec in ("idle", "chaser"):  # they import spacewar and numpy alone
            if spec in ready:
                rows.append((f"a confined {spec} (spacewar and numpy alone) ready within 0.3 s",
                             f"{ready[spec]:.2f} s", ready[spec] <= 0.3))
    for key, row in r.get("planets", {}).get("rows", {}).items():
        rows.append((f"outer solar system, {row['method']}: time per step at most 0.5 of "
                     "REBOUND's", f"{row['time_over_rebound']:.2f} of REBOUND's "
                     f"({row['engine_us_per_step']:.2f} us vs {row['rebound_us_per_step']:.2f} us)",
                     row["time_over_rebound"] <= 0.5))
    if "tree" in r:
        from .tree_bench import targets as tree_targets

        rows += tree_targets(r["tree"])
    if "contact" in r:
        from .contact_bench import targets as contact_targets

        rows += contact_targets(r)
    return rows


def _over_inline(conf):
    """The confined match's frame rate as a fraction of the inline one's."""
    ratio = conf.get("over_inline")
    return "ratio not measured" if ratio is None else f"{ratio:.2f} of the inline rate"


def _ready_text(spacewar):
    """``idle 0.21 s, chaser 0.24 s, ...``: each built-in bot's confined start-up."""
    ready = spacewar.get("confined_bot_ready_seconds", {})
    return ", ".join(f"{spec} {seconds:.2f} s" for spec, seconds in ready.items()) or "not measured"


def _confined_outcome(conf):
    """Whether the confined match replayed the inline one, and the confined bots' faults."""
    same = conf.get("agrees_with_inline")
    text = ("same frames and score as inline" if same else
            "DIFFERS from the inline match" if same is not None else "agreement not measured")
    faults = conf.get("faults")
    if faults is not None:
        kinds = conf.get("fault_kinds") or [{}, {}]
        text += "; confined bots' faults " + ", ".join(
            f"{n}" + (f" ({', '.join(f'{k} {c}' for k, c in kind.items())})" if kind else "")
            for n, kind in zip(faults, kinds))
    return text


def format_report(r):
    lines = [f"machine: {r['machine']['cpu']}, {r['machine']['cores']} cores, numba "
             f"{r['machine']['numba']} ({r['machine']['numba_threads']} threads), numpy "
             f"{r['machine']['numpy']}, REBOUND {r['machine'].get('rebound', '-')}"]
    if "direct_sum" in r:
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
    if "small_n" in r:
        s = r["small_n"]
        lines.append("\n2. Benchmarks Game n-body (5 bodies, symplectic Euler, dt = 0.01)")
        lines.append(f"engine sim.step(n): {s['engine_steps_per_second']:.3e} steps/s; plain numba "
                     f"loop: {s['plain_loop_steps_per_second']:.3e}; REBOUND leapfrog: "
                     f"{s['rebound_leapfrog_steps_per_second']:.3e}")
        lines.append(f"engine time / plain loop: {s['engine_time_over_plain_loop']:.2f}; "
                     f"speed-up vs REBOUND: {s['speedup_vs_rebound']:.2f}x; same result to "
                     f"{s['max_position_difference_vs_plain_after_1000_steps']:.1e}")
    if "scaling" in r:
        s = r["scaling"]
        lines.append("\n3. scaling (seconds per leapfrog step)")
        lines.append(f"{'N':>7}{'direct':>12}{'N_test':>12}")
        for n, a, b in zip(s["n"], s["direct_seconds_per_step"], s["test_seconds_per_step"]):
            lines.append(f"{n:>7}{a:>12.2e}{b:>12.2e}")
        lines.append(f"fitted slopes (N >= 1024): direct {s['direct_slope_large_n']:.2f}, "
                     f"test particles {s['test_particle_slope_large_n']:.2f}")
    if "terms" in r:
        t = r["terms"]
        lines.append(f"\n4. declared terms (N = {t['n']}, leapfrog)")
        for k, v in t["seconds_per_step"].items():
            lines.append(f"  {k:<34}{v * 1e6:>9.1f} us/step  ({t['relative_to_gravity_alone'][k]:.2f}x)")
    if "startup" in r:
        s = r["startup"]
        lines.append(f"\n5. start-up (import engine + first step): warm cache "
                     f"{s['warm_cache_seconds']:.2f} s, cold cache {s['cold_cache_seconds']:.1f} s")
        for name, row in s.get("commands", {}).items():
            lines.append(f"   {name}: warm {row['warm_seconds']:.2f} s, cold "
                         f"{row['cold_seconds']:.1f} s (+{row['cold_seconds'] - row['warm_seconds']:.1f} s)")
    if "spacewar" in r:
        s = r["spacewar"]
        one = s["one_match_with_bots"]
        conf = s["one_match_confined_bots"]
        lines.append(f"\n6. Spacewar: one match {one['bots'][0]} vs {one['bots'][1]} with bots "
                     f"{one['frames_per_second']:.0f} frames/s; both bots confined in their "
                     f"own processes {conf['frames_per_second']:.0f} frames/s once ready, "
                     f"{_over_inline(conf)} "
                     f"({_confined_outcome(conf)}); start-up of both confined seats "
                     f"{conf.get('startup_seconds', math.nan):.2f} s; a confined bot ready in "
                     f"{_ready_text(s)}; without bots "
                     f"{s['one_match_no_bots_frames_per_second']:.0f} frames/s; "
                     f"{s['batch']['matches']} matches together "
                     f"{s['batch']['match_frames_per_second']:.3e} match-frames/s")
    if "batch" in r:
        b = r["batch"]
        same = "bit-identical to" if b["bit_identical_to_separate"] else "DIFFERENT from"
        lines.append(f"\n7. engine.Batch: {b['systems']} systems of {b['slots']} slots, one step per call "
                     f"({same} separate simulations)")
        for count, row in b["threads"].items():
            lines.append(f"  {count} thread(s): batch {row['batch_systems_per_second']:.3e} "
                         f"system-steps/s; separate Simulation.step calls "
                         f"{row['separate_simulations_per_second']:.3e}; {row['speedup']:.1f}x")
    if "learning" in r:
        g = r["learning"]
        same = "identical" if g["identical_across_threads"] else "DIFFERENT"
        lines.append(f"\n8. learning: {g['matches']} matches, observations and rewards included "
                     f"({same} at every thread count), match-frames/s")
        for count, row in g["threads"].items():
            lines.append(f"  {count} thread(s): LearningBatch.step "
                         f"{row['match_frames_per_second']:.3e}" + "".join(
                             f"; SpacewarVectorEnv.step vs {o} "
                             f"{row[f'vector_env_vs_{o}_match_frames_per_second']:.3e}"
                             for o in g["opponents"])
                         + f"; vs random with copy=False "
                           f"{row['vector_env_vs_random_no_copy_match_frames_per_second']:.3e}"
                         + (f"; self-play {row['vector_env_self_play_agent_steps_per_second']:.3e}"
                            " agent-steps/s"
                            if "vector_env_self_play_agent_steps_per_second" in row else ""))
        h = g["harness"]
        lines.append(f"  one match of two idle Python bots: {h['seconds_per_frame'] * 1e6:.1f} us "
                     f"per frame, of which the bots' act {2 * h['act_seconds'] * 1e6:.2f} us: the "
                     f"harness's own cost {h['harness_seconds_per_frame'] * 1e6:.1f} us per frame")
    if "planets" in r:
        pl = r["planets"]
        lines.append(f"\n9. planetary integrators, {pl['problem']} (time per step, median of "
                     "side-by-side repetitions)")
        lines.append(f"{'method':<24}{'engine us/step':>16}{'REBOUND us/step':>17}"
                     f"{'engine/REBOUND':>16}{'same state to':>15}")
        for row in pl["rows"].values():
            lines.append(f"{row['method']:<24}{row['engine_us_per_step']:>16.2f}"
                         f"{row['rebound_us_per_step']:>17.2f}{row['time_over_rebound']:>16.2f}"
                         f"{row['relative_position_difference']:>15.1e}")
    if "cluster" in r:
        from .bench_cluster import format_cluster

        lines.append("\n10. tournaments and sweeps on Dask (local processes against a "
                     "LocalCluster)")
        lines += format_cluster(r["cluster"])
    if "tree" in r:
        from .tree_bench import format_tree

        lines.append("\n11. Tree gravity (FMM and Barnes-Hut) against pytreegrav and REBOUND at "
                     "equal error")
        lines += format_tree(r["tree"])
    if "contact" in r:
        from .contact_bench import format_contact

        lines.append(format_contact(r))
    if targets(r):
        lines.append("\ntargets:")
        for name, measured, met in targets(r):
            lines.append(f"  {'met' if met else 'GAP':<4} {name}: {measured}")
    return "\n".join(lines)


def format_markdown(r, command):
    """The results as the body of ``docs/performance.md``."""
    m = r["machine"]
    out = ["# Performance", "",
           f"Measured with `{command}` on {m['cpu']} ({m.get('llvm_cpu', '?')}), {m['cores']} cores, "
           f"Python {m['python']}, numpy {m['numpy']}, numba {m['numba']} ({m['numba_threads']} "
           f"threads), REBOUND {m.get('rebound', '-')}. Every ratio is the median of per-repetition "
           "ratios measured side by side in the same run.", ""]
    if targets(r):
        out += ["## Targets, and where we stand", "", "| target | measured | status |",
                "|---|---|---|"]
        out += [f"| {name} | {measured} | {'met' if met else '**gap**'} |"
                for name, measured, met in targets(r)]
        out += ["", HOW_THE_TARGETS_ARE_MET, ""]
    if "direct_sum" in r:
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
    if "small_n" in r:
        s = r["small_n"]
        out += ["## 2. Small N, many steps (Benchmarks Game n-body, symplectic Euler, dt = 0.01)", "",
                "| | steps per second |", "|---|---|",
                f"| engine `sim.step(n)` | {s['engine_steps_per_second']:.3e} |",
                f"| plain hand-written numba loop | {s['plain_loop_steps_per_second']:.3e} |",
                f"| REBOUND leapfrog | {s['rebound_leapfrog_steps_per_second']:.3e} |", "",
                f"Engine time over the plain loop: {s['engine_time_over_plain_loop']:.2f}; speed-up "
                f"over REBOUND: {s['speedup_vs_rebound']:.2f}x. Both compute the same thing: after "
                f"1000 steps the positions differ by {s['max_position_difference_vs_plain_after_1000_steps']:.1e}.", ""]
    if "scaling" in r:
        s = r["scaling"]
        out += ["## 3. Scaling", "", "| N | direct sum s/step | N test particles around 4 bodies s/step |",
                "|---|---|---|"]
        for n, a, b in zip(s["n"], s["direct_seconds_per_step"], s["test_seconds_per_step"]):
            out.append(f"| {n} | {a:.2e} | {b:.2e} |")
        out += ["", f"Fitted log-log slopes for N >= 1024: direct sum {s['direct_slope_large_n']:.2f}, "
                    f"test particles {s['test_particle_slope_large_n']:.2f}.", ""]
    if "terms" in r:
        t = r["terms"]
        out += [f"## 4. Only the declared terms are paid for (N = {t['n']}, leapfrog)", "",
                "| declared terms | us/step | relative |", "|---|---|---|"]
        for k, v in t["seconds_per_step"].items():
            out.append(f"| {k} | {v * 1e6:.1f} | {t['relative_to_gravity_alone'][k]:.2f}x |")
        out.append("")
    if "startup" in r:
        s = r["startup"]
        out += ["## 5. Start-up", "",
                "From an empty compiled-code cache (cold: the first run after install or an "
                "upgrade) and again with the cache it filled (warm), each a whole process.", "",
                "| command | warm s | cold s | cold - warm s |", "|---|---|---|---|",
                f"| `import engine` and a first step | {s['warm_cache_seconds']:.2f} | "
                f"{s['cold_cache_seconds']:.1f} | "
                f"{s['cold_cache_seconds'] - s['warm_cache_seconds']:.1f} |"]
        for name, row in s.get("commands", {}).items():
            out.append(f"| `{_shown(name)}` | "
                       f"{row['warm_seconds']:.2f} | {row['cold_seconds']:.1f} | "
                       f"{row['cold_seconds'] - row['warm_seconds']:.1f} |")
        out.append("")
    out += compile_time_markdown(r.get("compile_times", {}))
    if "spacewar" in r:
        s = r["spacewar"]
        one = s["one_match_with_bots"]
        conf = s["one_match_confined_bots"]
        slowdown = ("no frame played" if conf.get("slowdown") is None
                    else f"{conf['slowdown']:.2f}x the time")
        out += ["## 6. Headless Spacewar", "",
                f"- one match, {one['bots'][0]} vs {one['bots'][1]}, bots included: "
                f"{one['frames_per_second']:.0f} frames per second",
                f"- the same match with each bot confined in its own process (as every bot that "
                f"is not built in plays), once both are ready: {conf['frames_per_second']:.0f} "
                f"frames per second, {_over_inline(conf)} ({slowdown}; the median of "
                f"{conf.get('repeats', 1)} pairs played one after the other); "
                f"{_confined_outcome(conf)}",
                f"- start-up of the two confined seats (process, confinement, the bot's "
                f"module): {conf.get('startup_seconds', math.nan):.2f} s; one confined bot "
                f"ready in {_ready_text(s)}",
                f"- one match, no bots (action codes only): {s['one_match_no_bots_frames_per_second']:.0f} "
                "frames per second",
                f"- {s['batch']['matches']} matches advanced together by one compiled call: "
                f"{s['batch']['match_frames_per_second']:.3e} match-frames per second", ""]
    if "batch" in r:
        b = r["batch"]
        out += [f"## 7. Many systems per call (`engine.Batch`, {b['systems']} systems of "
                f"{b['slots']} slots)", "",
                "The game's size and forces (2 ships and 64 test particles per system on the unit "
                "torus: star, ship gravity, thrust; symplectic Euler), one step per call as a game "
                "frame takes. Against a `Simulation.step` call per system; "
                + ("the results are bit-identical." if b["bit_identical_to_separate"]
                   else "**the results differ** from the separate simulations."), "",
                "| threads | batch system-steps/s | separate `Simulation.step` calls/s | speed-up |",
                "|---|---|---|---|"]
        out += [f"| {count} | {row['batch_systems_per_second']:.3e} | "
                f"{row['separate_simulations_per_second']:.3e} | {row['speedup']:.1f}x |"
                for count, row in b["threads"].items()]
        out.append("")
    if "learning" in r:
        g = r["learning"]
        opponents = g.get("opponents", [])
        out += [f"## 8. Spacewar for learning code ({g['matches']} matches)", "",
                "Random actions; every match's two egocentric observations, rewards, "
                "terminations and resets included in the compiled step; "
                "`SpacewarVectorEnv.step` also includes its action checks and conversion and "
                "the compiled opponent's decisions. Results "
                + ("identical" if g["identical_across_threads"] else "**different**")
                + " at every thread count. Match-frames per second:", "",
                "| threads | `LearningBatch.step` | "
                + " | ".join(f"`SpacewarVectorEnv.step` vs {o}" for o in opponents)
                + " | vs random, `copy=False` | self-play (agent-steps/s) |",
                "|---|---|" + "---|" * (len(opponents) + 2)]
        out += [f"| {count} | {row['match_frames_per_second']:.3e} | " + " | ".join(
                    f"{row[f'vector_env_vs_{o}_match_frames_per_second']:.3e}"
                    for o in opponents)
                + f" | {row['vector_env_vs_random_no_copy_match_frames_per_second']:.3e} | "
                + (f"{row['vector_env_self_play_agent_steps_per_second']:.3e}"
                   if "vector_env_self_play_agent_steps_per_second" in row else "-") + " |"
                for count, row in g["threads"].items()]
        h = g.get("harness")
        if h:
            out += ["", f"One match of two idle Python bots ({h['frames']} frames): "
                    f"{h['seconds_per_frame'] * 1e6:.1f} us per frame, of which the two bots' "
                    f"`act` {2 * h['act_seconds'] * 1e6:.2f} us: the harness's own cost is "
                    f"{h['harness_seconds_per_frame'] * 1e6:.1f} us per frame."]
        out.append("")
    if "planets" in r:
        pl = r["planets"]
        out += [f"## 9. Planetary integrators ({pl['problem']})", "",
                "Time per step, engine against REBOUND, from the same heliocentric state: "
                f"`whfast` with corrector 11 at dt = {PLANETS_DT:g} days (`sim.step(n)` against "
                "REBOUND's WHFast with corrector 11 in `safe_mode = 0`, `steps(n)` then "
                "`synchronize()`: both apply the corrector and synchronise once per call), and "
                f"`ias15` at epsilon {PLANETS_EPSILON:g} (`integrate` over the same span, per "
                "step each code took). The last column is the largest difference of the two "
                "codes' final positions over the largest coordinate.", "",
                "| method | engine us/step | REBOUND us/step | engine / REBOUND | same state to |",
                "|---|---|---|---|---|"]
        out += [f"| {row['method']} | {row['engine_us_per_step']:.2f} | "
                f"{row['rebound_us_per_step']:.2f} | {row['time_over_rebound']:.2f} | "
                f"{row['relative_position_difference']:.1e} |" for row in pl["rows"].values()]
        out.append("")
    if "cluster" in r:
        from .bench_cluster import markdown_cluster

        out += ["## 10. Tournaments and sweeps on Dask", ""] + markdown_cluster(r["cluster"])
        out.append("")
    if "tree" in r:
        from .tree_bench import markdown_tree

        out += ["## 11. Tree gravity (`NBodyGravity(method=\"fmm\")` and `method=\"tree\"`)", ""]
        out += markdown_tree(r["tree"]) + [""]
    if "contact" in r:
        from .contact_bench import markdown_contact

        out += markdown_contact(r)
    return "\n".join(out)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m validation bench",
                                     description="Measure the engine's speed against references.")
    parser.add_argument("--quick", action="store_true", help="smaller sizes, fewer repetitions")
    parser.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    parser.add_argument("--markdown", metavar="FILE", help="also write the results as Markdown")
    parser.add_argument("--only", metavar="SECTIONS",
                        help="comma-separated sections (default: every one): direct,small,"
                             "scaling,terms,startup,spacewar,batch,learning,planets,cluster,tree,"
                             "contact")
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


if __name__ == "__main__":
    sys.exit(main())
