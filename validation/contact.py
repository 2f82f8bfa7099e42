"""Contact checked against physics and against REBOUND: a hard-sphere gas and an accreting
planetesimal disk (the validation report's section 7; the suite runs smaller cases).

- **Gas.** Equal hard disks (2-D) or spheres (3-D) in a periodic box, started with one speed
  for all. Elastic contacts relax the speeds to the Maxwell-Boltzmann law of the dimension
  (Rayleigh in 2-D, Maxwell in 3-D; tested with Kolmogorov-Smirnov), and the pressure from
  the collisional virial, P V = N kT + (1/dim) <sum J sigma> / time (Allen & Tildesley,
  Computer Simulation of Liquids, section 2.4), matches the equation of state: Henderson's for
  hard disks (1975, Mol. Phys. 30, 971), Carnahan & Starling's for hard spheres (1969,
  J. Chem. Phys. 51, 635).
- **Accretion.** Planetesimals on near-circular, nearly coplanar orbits about a star, merging
  on contact, run three ways on the same scene, integrator (leapfrog) and step: REBOUND's
  ``collision = "line"`` with its merge; the engine's ``resolve_at="end"`` (REBOUND's way of
  finding and resolving); the engine's default, each contact at the moment of touching. The
  disk is chaotic (round-off in the force sums grows until the orbits part), so the merges
  agree one for one only for a while: the comparison gives how many of the first merges are
  identical (same step, same pair), and then the statistics of the whole run (merges over
  time, bodies left, the largest body). Mass, momentum and charge are checked through every
  merge, and the energy with its ledger.
"""
import math

import numpy as np

#: the gas's sphere radius (the unit of length)
RADIUS = 0.5

#: the gas runs of the report: dimension -> (spheres, packing fraction)
GAS = {2: (400, 0.2), 3: (512, 0.1)}

#: the gas runs' times by the report's level: (relax, span measured over)
GAS_TIMES = {"smoke": (2.0, 4.0), "quick": (20.0, 60.0), "full": (20.0, 300.0)}

#: bins of the speed histograms, in units of sqrt(kT)
SPEED_BINS = np.linspace(0.0, 4.0, 21)


# -- the gas ---------------------------------------------------------------------------------

def gas(dim, n, packing, seed=1):
    """A ``Simulation`` of n equal spheres (unit mass, radius ``RADIUS``) filling ``packing``
    of a periodic box, speeds all 1 in random directions (zero total momentum, mean square
    speed 1), placed without overlaps on a jittered lattice, elastic contacts."""
    from engine import Collisions, Simulation

    rng = np.random.default_rng(seed)
    volume = n * (math.pi * RADIUS ** 2 if dim == 2 else 4 / 3 * math.pi * RADIUS ** 3) / packing
    side = volume ** (1 / dim)
    per_side = math.ceil(n ** (1 / dim))
    spacing = side / per_side
    cells = np.stack(np.meshgrid(*[np.arange(per_side)] * dim, indexing="ij"), -1)
    cells = cells.reshape(-1, dim)[rng.permutation(per_side ** dim)[:n]]
    jitter = rng.uniform(-1, 1, (n, dim)) * (spacing / 2 - RADIUS) * 0.9
    pos = (cells + 0.5) * spacing - side / 2 + jitter
    direction = rng.normal(size=(n, dim))
    vel = direction / np.linalg.norm(direction, axis=1)[:, None]
    vel -= vel.mean(axis=0)
    vel /= np.sqrt((vel ** 2).sum(axis=1).mean())
    sim = Simulation(dim=dim, integrator="leapfrog", dt=0.05, box=side)
    sim.add_many(mass=1.0, pos=pos, vel=vel, radius=RADIUS)
    sim.collisions = Collisions(restitution=1.0)
    return sim


def speed_cdf(v, dim, kT):
    """The Maxwell-Boltzmann speed distribution's CDF for unit mass: Rayleigh in 2-D,
    1 - exp(-x^2/2); Maxwell in 3-D, erf(x/sqrt 2) - sqrt(2/pi) x exp(-x^2/2); x = v/sqrt(kT)."""
    x = np.asarray(v) / math.sqrt(kT)
    if dim == 2:
        return 1.0 - np.exp(-x * x / 2)
    erf = np.vectorize(math.erf)
    return erf(x / math.sqrt(2)) - np.sqrt(2 / math.pi) * x * np.exp(-x * x / 2)


def ks_test(samples, cdf):
    """Kolmogorov-Smirnov: (D, p): the largest gap between the samples' CDF and ``cdf``, and
    its p-value by Kolmogorov's asymptotic series with Stephens's small-sample correction
    (Stephens 1970, J. R. Stat. Soc. B 32, 115)."""
    x = np.sort(samples)
    n = len(x)
    f = cdf(x)
    d = max((np.arange(1, n + 1) / n - f).max(), (f - np.arange(n) / n).max())
    lam = (math.sqrt(n) + 0.12 + 0.11 / math.sqrt(n)) * d
    p = 2 * sum((-1) ** (k - 1) * math.exp(-2 * k * k * lam * lam) for k in range(1, 101))
    return float(d), min(max(p, 0.0), 1.0)


def compressibility(dim, packing):
    """Z = PV / NkT of hard disks (Henderson 1975: (1 + eta^2/8) / (1 - eta)^2) or hard
    spheres (Carnahan & Starling 1969: (1 + eta + eta^2 - eta^3) / (1 - eta)^3)."""
    eta = packing
    if dim == 2:
        return (1 + eta * eta / 8) / (1 - eta) ** 2
    return (1 + eta + eta ** 2 - eta ** 3) / (1 - eta) ** 3


def gas_run(dim, n, packing, relax=20.0, span=60.0, samples=3, seed=1):
    """Relax the gas for ``relax`` time units, then measure over ``span``: the KS p-values of
    the speeds against Maxwell-Boltzmann at ``samples`` moments (and at the start, the
    control), Z from the collisional virial against the equation of state, and the energy
    and momentum kept."""
    sim = gas(dim, n, packing, seed)
    kT = 1.0 / dim  # unit masses, mean square speed 1: kT = <v^2> / dim
    cdf = lambda v: speed_cdf(v, dim, kT)  # noqa: E731
    start_p = ks_test(np.linalg.norm(sim.vel, axis=1), cdf)[1]
    counts = np.zeros(len(SPEED_BINS) - 1)
    e0, p0 = sim.energy(), sim.momentum().copy()
    sim.integrate(relax)
    contacts = 0
    virial, p_values, d_values = 0.0, [], []
    for k in range(samples):
        sim.integrate(relax + span * (k + 1) / samples)
        # an elastic contact of equal unit masses exchanges J = u_n along the line of centres
        # at separation 2 RADIUS: its virial is J * 2 RADIUS
        virial += sum(c.speed * 2 * RADIUS for c in sim.contacts)
        contacts += len(sim.contacts)
        speeds = np.linalg.norm(sim.vel, axis=1)
        counts += np.histogram(speeds / math.sqrt(kT), SPEED_BINS)[0]
        d, p = ks_test(speeds, cdf)
        d_values.append(d)
        p_values.append(p)
    z = 1.0 + virial / (dim * span * n * kT)
    return {"dim": dim, "n": n, "packing": packing, "relax": relax, "span": span,
            "start_p": start_p, "p_values": p_values, "ks_d": d_values,
            "contacts_per_sphere": 2 * contacts / n, "z": z,
            "z_expected": compressibility(dim, packing),
            "z_law": "Henderson 1975" if dim == 2 else "Carnahan & Starling 1969",
            "speed_bins": SPEED_BINS.tolist(), "speed_counts": counts.tolist(),
            "energy_error": abs(sim.energy() - e0) / abs(e0),
            "momentum_error": float(np.abs(sim.momentum() - p0).max())}


# -- accretion -------------------------------------------------------------------------------

#: the accretion runs of the report by level: planetesimals, steps, step size, their radius
ACCRETION = {"smoke": (120, 300, 2e-3, 0.02), "quick": (300, 2000, 2e-3, 0.01),
             "full": (500, 50000, 2e-3, 0.01)}


def disk(n, radius, seed=3):
    """A star (mass 1, radius 0.005) and n planetesimals (mass 1e-6 each, ``radius``, a charge
    each in [-1, 1] that no force reads, so merges must carry it) with a in [0.8, 1.2],
    e < 0.05, inclination < 0.01, random angles, no two touching at the start (a drawn body
    that would touch one already placed is drawn again); G = 1, centre-of-mass frame. Built
    with REBOUND's orbital elements so both codes start from the same floats. Returns (mass,
    radius, charge, pos, vel): arrays of n + 1 rows, the star first."""
    import rebound

    rng = np.random.default_rng(seed)
    accepted, placed = [], np.zeros((1, 3))
    while len(accepted) < n:  # candidates in batches, as test particles of the star alone
        batch = np.column_stack([rng.uniform(0.8, 1.2, n), rng.uniform(0.0, 0.05, n),
                                 rng.uniform(0.0, 0.01, n),
                                 rng.uniform(0.0, 2 * math.pi, (n, 3))])
        trial = rebound.Simulation()
        trial.G = 1.0
        trial.add(m=1.0)
        for a, e, inc, mean, omega, node in batch:
            trial.add(m=0.0, a=a, e=e, inc=inc, M=mean, omega=omega, Omega=node)
        for k, p in enumerate(trial.particles[1:]):
            x = np.array(p.xyz)
            if len(accepted) < n and np.linalg.norm(placed - x, axis=1).min() > 2 * radius + 0.005:
                accepted.append(batch[k])
                placed = np.vstack([placed, x])
    sim = rebound.Simulation()
    sim.G = 1.0
    sim.add(m=1.0, r=0.005)
    for a, e, inc, mean, omega, node in accepted:
        sim.add(m=1e-6, r=radius, a=a, e=e, inc=inc, M=mean, omega=omega, Omega=node,
                primary=sim.particles[0])
    sim.move_to_com()
    parts = sim.particles
    pos = np.array([[q.x, q.y, q.z] for q in parts])
    vel = np.array([[q.vx, q.vy, q.vz] for q in parts])
    mass = np.array([q.m for q in parts])
    radii = np.array([q.r for q in parts])
    charge = np.concatenate([[0.0], rng.uniform(-1.0, 1.0, n)])
    return mass, radii, charge, pos, vel


def rebound_accretion(scene, steps, dt):
    """REBOUND's leapfrog with ``collision = "line"`` and its merge, step by step. The merge is
    a Python ``collision_resolve`` that does what ``reb_collision_resolve_merge`` does (the
    higher index into the lower, at the pair's centre of mass, summed momentum, summed volume)
    and logs the pair by the bodies' first indices (REBOUND removes the absorbed body and
    renumbers the rest). Returns the merges, (step, survivor, absorbed), and the masses left."""
    import rebound

    mass, radii, _, pos, vel = scene
    sim = rebound.Simulation()
    sim.G = 1.0
    sim.integrator = "leapfrog"
    sim.dt = dt
    for k in range(len(mass)):
        sim.add(m=mass[k], r=radii[k], x=pos[k, 0], y=pos[k, 1], z=pos[k, 2],
                vx=vel[k, 0], vy=vel[k, 1], vz=vel[k, 2])
    sim.collision = "line"
    ids = list(range(len(mass)))
    merges = []
    step = [0]

    def merge(sim_pointer, collision):
        s = sim_pointer.contents
        i, j = sorted((collision.p1, collision.p2))
        pi, pj = s.particles[i], s.particles[j]
        m = pi.m + pj.m
        for c in ("x", "y", "z", "vx", "vy", "vz"):
            setattr(pi, c, (getattr(pi, c) * pi.m + getattr(pj, c) * pj.m) / m)
        pi.r = (pi.r ** 3 + pj.r ** 3) ** (1 / 3)
        pi.m = m
        merges.append((step[0], ids[i], ids[j]))
        del ids[j]
        return 2 if j == collision.p2 else 1  # remove the higher index

    sim.collision_resolve = merge
    for k in range(steps):
        step[0] = k
        sim.steps(1)
    masses = np.array([p.m for p in sim.particles])
    return merges, masses


def engine_accretion(scene, steps, dt, resolve_at):
    """The engine on the same scene: leapfrog, ``NBodyGravity``, ``Collisions(resolve="merge",
    resolve_at=...)``. Returns the merges (step, survivor, absorbed), the masses left, and the
    conservation of mass, momentum, charge and energy with its ledger (relative changes)."""
    from engine import Collisions, Simulation, forces

    mass, radii, charge, pos, vel = scene
    sim = Simulation(dim=3, integrator="leapfrog", dt=dt, capacity=len(mass))
    sim.add_many(mass=mass, pos=pos, vel=vel, radius=radii, charge=charge)
    sim.add_force(forces.NBodyGravity())
    sim.collisions = Collisions(resolve="merge", resolve_at=resolve_at)
    m0, p0, q0, e0 = (sim.mass.sum(), sim.momentum().copy(), sim.charge.sum(), sim.energy())
    scale = float(np.abs(sim.mass[:, None] * sim.vel).sum())  # sum m |v|, momentum's scale
    merges = []
    for k in range(steps):
        sim.step(1)
        merges += [(k, c.survivor, c.j if c.survivor == c.i else c.i)
                   for c in sim.contacts if c.action == "merge"]
    live = sim.active
    return merges, sim.mass[live].copy(), {
        "mass": abs(sim.mass[live].sum() - m0) / m0,
        "momentum": float(np.abs(sim.momentum() - p0).max()) / scale,
        "charge": abs(sim.charge[live].sum() - q0) / np.abs(charge).sum(),
        "energy_with_ledger": abs(sim.energy() + sim.energy_ledger - e0) / abs(e0),
        "energy_without_ledger": abs(sim.energy() - e0) / abs(e0),
        "ledger": sim.energy_ledger}


def first_identical(a, b):
    """How many of the first merges of two runs absorb the same body in the same step. (Who
    absorbs it can differ when three bodies meet in one step: REBOUND resolves a step's pairs
    in a shuffled order, the engine by index; the bodies that go on are the same.)"""
    same = 0
    for x, y in zip(sorted((s, gone) for s, _, gone in a), sorted((s, gone) for s, _, gone in b)):
        if x != y:
            break
        same += 1
    return same


def merges_by(merges, steps, checkpoints=50):
    """The number of merges done by each of ``checkpoints`` evenly spaced steps."""
    marks = [round(steps * (k + 1) / checkpoints) for k in range(checkpoints)]
    return marks, [sum(1 for s, _, _ in merges if s < mark) for mark in marks]


def accretion_run(n, steps, dt, radius, seed=3):
    """The three runs of the module's docstring on one scene, and their comparison: the
    merges of each (count, by step, the first 40), the bodies left, the largest planetesimal,
    and how many of the first merges REBOUND's run shares with each of the engine's."""
    scene = disk(n, radius, seed)
    runs = {"rebound": rebound_accretion(scene, steps, dt)}
    out = {"n": n, "steps": steps, "dt": dt, "radius": radius, "runs": {}}
    for name in ("end", "contact"):
        merges, masses, kept = engine_accretion(scene, steps, dt, name)
        runs[name] = (merges, masses)
        out[name + "_conservation"] = kept
    for name, (merges, masses) in runs.items():
        marks, counts = merges_by(merges, steps)
        out["runs"][name] = {"merges": len(merges), "bodies_left": len(masses),
                             "largest_planetesimal": float(np.sort(masses)[-2]),
                             "star_mass": float(masses[0]), "merges_by_step": counts,
                             "first_merges": [list(map(int, m)) for m in sorted(merges)[:40]]}
    out["marks"] = marks
    theirs = runs["rebound"][0]
    out["identical_end"] = first_identical(theirs, runs["end"][0])
    out["identical_contact"] = first_identical(theirs, runs["contact"][0])
    return out
