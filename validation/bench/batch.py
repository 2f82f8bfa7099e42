"""Section 7: ``engine.Batch``, 4096 systems of the game's size advanced by one call, against one
``Simulation.step`` call per system, at 1 thread and at every thread."""
import numpy as np

from .timing import each_thread_count, side_by_side

NAME = "batch"
KEYS = ("batch",)
NEEDS = ()


def run(quick):
    return {"batch": bench_batch(1024 if quick else 4096, repeats=3 if quick else 5)}


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
    for count in each_thread_count():
        t_batch, t_sims, ratio = side_by_side(lambda: batch.step(1), separate, repeats)
        rows[str(count)] = {"batch_systems_per_second": systems / t_batch,
                            "separate_simulations_per_second": systems / t_sims,
                            "speedup": ratio}
    # the same steps, the same numbers: the batch is bit-identical to the separate simulations
    same = all(np.array_equal(batch.pos[m], sims[m].pos) for m in range(0, systems, 97))
    return {"systems": systems, "slots": slots, "threads": rows,
            "bit_identical_to_separate": bool(same)}


def text(r):
    lines = []
    b = r["batch"]
    same = "bit-identical to" if b["bit_identical_to_separate"] else "DIFFERENT from"
    lines.append(f"\n7. engine.Batch: {b['systems']} systems of {b['slots']} slots, one step per call "
                 f"({same} separate simulations)")
    for count, row in b["threads"].items():
        lines.append(f"  {count} thread(s): batch {row['batch_systems_per_second']:.3e} "
                     f"system-steps/s; separate Simulation.step calls "
                     f"{row['separate_simulations_per_second']:.3e}; {row['speedup']:.1f}x")
    return lines


def markdown(r):
    out = []
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
    return out


def targets(r):
    return []
