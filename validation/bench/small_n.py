"""Section 2: the Benchmarks Game n-body workload (Sun and four giant planets, symplectic Euler,
dt = 0.01) through ``sim.step(n)``, against a plain hand-written numba loop and REBOUND."""
import math

import numpy as np

from .timing import repeats, side_by_side

NAME = "small"
KEYS = ("small_n",)
NEEDS = ("rebound",)


def run(quick):
    return {"small_n": bench_small_n(100_000 if quick else 400_000, repeats(quick))}


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


def text(r):
    lines = []
    s = r["small_n"]
    lines.append("\n2. Benchmarks Game n-body (5 bodies, symplectic Euler, dt = 0.01)")
    lines.append(f"engine sim.step(n): {s['engine_steps_per_second']:.3e} steps/s; plain numba "
                 f"loop: {s['plain_loop_steps_per_second']:.3e}; REBOUND leapfrog: "
                 f"{s['rebound_leapfrog_steps_per_second']:.3e}")
    lines.append(f"engine time / plain loop: {s['engine_time_over_plain_loop']:.2f}; "
                 f"speed-up vs REBOUND: {s['speedup_vs_rebound']:.2f}x; same result to "
                 f"{s['max_position_difference_vs_plain_after_1000_steps']:.1e}")
    return lines


def markdown(r):
    out = []
    s = r["small_n"]
    out += ["## 2. Small N, many steps (Benchmarks Game n-body, symplectic Euler, dt = 0.01)", "",
            "| | steps per second |", "|---|---|",
            f"| engine `sim.step(n)` | {s['engine_steps_per_second']:.3e} |",
            f"| plain hand-written numba loop | {s['plain_loop_steps_per_second']:.3e} |",
            f"| REBOUND leapfrog | {s['rebound_leapfrog_steps_per_second']:.3e} |", "",
            f"Engine time over the plain loop: {s['engine_time_over_plain_loop']:.2f}; speed-up "
            f"over REBOUND: {s['speedup_vs_rebound']:.2f}x. Both compute the same thing: after "
            f"1000 steps the positions differ by {s['max_position_difference_vs_plain_after_1000_steps']:.1e}.", ""]
    return out


def targets(r):
    rows = []
    s = r["small_n"]
    rows.append(("Benchmarks Game n-body: within 1.3x of a plain numba loop",
                 f"{s['engine_time_over_plain_loop']:.2f}x the plain loop's time",
                 s["engine_time_over_plain_loop"] <= 1.3))
    rows.append(("Benchmarks Game n-body: at least 2x faster than REBOUND",
                 f"{s['speedup_vs_rebound']:.2f}x", s["speedup_vs_rebound"] >= 2.0))
    return rows
