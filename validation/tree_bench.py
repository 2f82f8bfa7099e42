"""The tree section of ``python -m validation bench`` (and of the validation report): the
engine's tree gravity, by its fast multipole walk (``NBodyGravity(method="fmm")``, what
``method="auto"`` uses: the code named "engine" here) and by its Barnes-Hut walk
(``method="tree"``: "engine_tree"), against pytreegrav's and REBOUND's trees, measured side
by side in one run.

The scene: a Plummer (1911) sphere of total mass 1 and scale radius 1 (G = 1, 3-D, float64;
``engine.initial_conditions.plummer``, sampled as Aarseth, Henon & Wielen 1974), Plummer
softening eps = 1e-3, every thread numba has.

- **Error.** The relative force error of a body, |a - a_exact| / |a_exact|, against the exact
  sum over every other body of the code's own softened kernel (``exact_field``, every pair in
  float64, on ``targets`` bodies drawn at random), its median and 99th percentile, for each
  code at several opening angles theta. Each code is held to its own kernel, so the error is
  the tree's alone: the engine and REBOUND soften with Plummer's kernel, G m d / (r^2 +
  eps^2)^(3/2); pytreegrav with the cubic spline of compact support h (Monaghan & Lattanzio
  1985), taken at h = 2.8 eps, the spline whose potential at r = 0 is Plummer's,
  -G m / eps (Springel, Yoshida & White 2001, New Astron. 6, 79). Beyond r = h the spline's
  force is exactly Newtonian and Plummer's differs from it by -(3/2) (eps/r)^2 relatively:
  below 1e-5 of the force from r = 0.4 on, where 95% of the sphere's mass lies (the two
  exact fields differ by 1e-5 at the median body of a 5000-body sphere): the two kernels
  give the same forces, well below the errors compared.
- **Equal error.** For each code the theta at which the median error is ``TARGET_ERROR``
  (``theta_for_error``: log-log interpolation on the error-against-theta curve at
  ``error_n``), then at each timed N the theta for that error on that very scene
  (``tuned_theta``: a curve of three or more thetas around it), and the time of one force
  evaluation there, the codes timed one after the other in each repetition and the median of
  the per-repetition ratios kept. The median error of each code at each timed N is measured
  on the evaluation timed, to show the match holds there.
- **Scaling.** The engine's time against N and the exponent a of a least-squares fit of
  time ~ N^a; the N where the FMM (at its matched theta) becomes faster than the engine's
  direct sum (``method="direct"``), from the two timed side by side at small N.
- **Memory.** ``engine.tree.layout.bytes_per_particle(N)``.

One force evaluation means the same in every code: the tree built from the positions, its
moments, the walk and the sum, for every body. The engine's is ``sim.accelerations()``;
pytreegrav's ``Accel(pos, m, h, theta=theta, parallel=True, method="tree")`` (its tree
method named: its default "adaptive" sums small N directly), with ``quadrupole=False`` (its
default) and ``True``; REBOUND's ``reb_simulation_update_acceleration`` with ``gravity =
"tree"``, ``opening_angle2 = theta^2`` and the box (``root_size``) around the bodies (its pip
build has the monopole tree and no OpenMP: one core).
"""
import ctypes
import math
import statistics
import time

import numpy as np
from numba import prange

from engine.cache import compiler

jit = compiler("validation")

SOFTENING = 1e-3
#: pytreegrav's spline support radius per Plummer softening length (Springel et al. 2001)
SPLINE_PER_PLUMMER = 2.8
#: the median relative force error the codes are compared at
TARGET_ERROR = 1e-3
#: the opening angles of the error curves (extended where the target is not bracketed)
THETAS = (0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 1.0)
#: the engine takes theta in [0, 2)
MAX_THETA = {"engine": 1.9, "engine_tree": 1.9}
#: a code whose one evaluation is predicted (or measured) above this is not timed (further)
SLOW_SECONDS = 60.0
#: at most about this many seconds of repetitions at one N
REPEAT_BUDGET_SECONDS = 150.0

CODES = ("engine", "engine_tree", "pytreegrav", "pytreegrav_quadrupole", "rebound")
LABELS = {"engine": "engine FMM (quadrupole)",
          "engine_tree": "engine Barnes-Hut (quadrupole)", "pytreegrav": "pytreegrav (monopole)",
          "pytreegrav_quadrupole": "pytreegrav (quadrupole)",
          "rebound": "REBOUND tree (monopole, 1 core)"}
#: short names, for table headings
SHORT = {"engine": "engine", "engine_tree": "engine Barnes-Hut", "pytreegrav": "pytreegrav",
         "pytreegrav_quadrupole":
         "pytreegrav quadrupole", "rebound": "REBOUND"}
#: the kernel each code's error is measured against
KERNELS = {"engine": "plummer", "engine_tree": "plummer", "pytreegrav": "spline",
           "pytreegrav_quadrupole": "spline",
           "rebound": "plummer"}

#: sizes and repetitions by report level; the bench's full run is "full", --quick is "quick"
SIZES = {
    "full": {"error_n": 100_000, "compare_n": (10_000, 100_000, 1_000_000),
             "scaling_n": (10_000, 30_000, 100_000, 300_000, 1_000_000),
             "crossover_n": (1024, 2048, 4096, 8192), "memory_n": 1_000_000,
             "targets": 1000, "repeats": 5},
    "quick": {"error_n": 30_000, "compare_n": (10_000, 100_000),
              "scaling_n": (10_000, 30_000, 100_000),
              "crossover_n": (1024, 2048, 4096, 8192), "memory_n": 1_000_000,
              "targets": 1000, "repeats": 3},
    # the tests' level: pytreegrav left out (its parallel walk is compiled afresh in every
    # process, for about 20 s)
    "smoke": {"error_n": 3000, "compare_n": (2000, 4000), "scaling_n": (2000, 4000, 8000),
              "crossover_n": (256, 512, 1024), "memory_n": 1_000_000,
              "targets": 200, "repeats": 1, "codes": ("engine", "engine_tree", "rebound")},
}


# -- the scene and the exact field ---------------------------------------------------------
def plummer_sphere(n, seed=0):
    """(mass (n,), pos (n, 3)) of an n-body Plummer sphere, total mass 1, scale radius 1."""
    from engine.initial_conditions import plummer

    bodies = plummer(n, dim=3, seed=seed, mass=1.0, scale=1.0)
    return bodies.mass, bodies.pos


@jit(inline="always")
def _spline_force(r, h):
    """The cubic spline of support h (Monaghan & Lattanzio 1985, A&A 149, 135), as the mass
    within r over r^3 (G m times it times d is the acceleration): with q = r / h,
    (32/3 - 38.4 q^2 + 32 q^3) / h^3 for q <= 1/2, (64/3 - 48 q + 38.4 q^2 - 32/3 q^3
    - 1/(15 q^3)) / h^3 for 1/2 < q <= 1, 1/r^3 beyond (Springel et al. 2001, eq. A2)."""
    if r >= h:
        return 1.0 / (r * r * r)
    q = r / h
    h3 = h * h * h
    if q <= 0.5:
        return (32.0 / 3.0 + q * q * (32.0 * q - 38.4)) / h3
    return (64.0 / 3.0 - 48.0 * q + 38.4 * q * q - 32.0 / 3.0 * q * q * q
            - 1.0 / (15.0 * q * q * q)) / h3


@jit(parallel=True, error_model="numpy")
def _exact_field(targets, pos, mass, length, spline, out):
    """out[k] = sum over j != targets[k] of m_j d_kj w(r_kj): Plummer's w = (r^2 +
    length^2)^(-3/2), or the spline of support ``length``; every pair, float64, in order."""
    n = pos.shape[0]
    eps2 = length * length
    for k in prange(targets.shape[0]):
        i = targets[k]
        sx = 0.0
        sy = 0.0
        sz = 0.0
        for j in range(n):
            if j == i:
                continue
            dx = pos[j, 0] - pos[i, 0]
            dy = pos[j, 1] - pos[i, 1]
            dz = pos[j, 2] - pos[i, 2]
            r2 = dx * dx + dy * dy + dz * dz
            if spline:
                w = mass[j] * _spline_force(math.sqrt(r2), length)
            else:
                s = r2 + eps2
                w = mass[j] / (s * math.sqrt(s))
            sx += w * dx
            sy += w * dy
            sz += w * dz
        out[k, 0] = sx
        out[k, 1] = sy
        out[k, 2] = sz


def exact_field(pos, mass, targets, kernel="plummer", softening=SOFTENING):
    """The exact accelerations (G = 1) of the bodies ``targets`` (indices), (k, 3): every
    other body summed with Plummer's kernel of length ``softening``, or (``kernel="spline"``)
    the cubic spline of support ``SPLINE_PER_PLUMMER * softening``."""
    if kernel not in ("plummer", "spline"):
        raise ValueError(f"kernel must be 'plummer' or 'spline', got {kernel!r}")
    spline = kernel == "spline"
    length = SPLINE_PER_PLUMMER * softening if spline else softening
    targets = np.ascontiguousarray(targets, dtype=np.int64)
    out = np.empty((targets.shape[0], 3))
    _exact_field(targets, np.ascontiguousarray(pos, dtype=np.float64),
                 np.ascontiguousarray(mass, dtype=np.float64), float(length), spline, out)
    return out


def relative_errors(approx, exact):
    """|a - a_exact| / |a_exact| for each row."""
    return np.linalg.norm(approx - exact, axis=1) / np.linalg.norm(exact, axis=1)


def error_stats(errors):
    """{"median": ..., "p99": ...} of relative errors."""
    return {"median": float(np.median(errors)), "p99": float(np.percentile(errors, 99))}


def pick_targets(n, count, seed=12345):
    """``count`` distinct body indices out of n, at random (all of them if n <= count)."""
    if n <= count:
        return np.arange(n)
    return np.sort(np.random.default_rng(seed).choice(n, size=count, replace=False))


# -- the codes ------------------------------------------------------------------------------
def available():
    """{code: None if it can run here, else why not}."""
    out = {"engine": None, "engine_tree": None}
    for code, module in (("pytreegrav", "pytreegrav"), ("rebound", "rebound")):
        try:
            __import__(module)
            out[code] = None
        except ImportError:
            out[code] = (f"{module} is not installed (the [validation] extra: "
                         "pip install -e '.[validation]')")
    out["pytreegrav_quadrupole"] = out["pytreegrav"]
    if out["pytreegrav"] is None:
        import inspect
        from importlib.metadata import version

        import pytreegrav

        if "quadrupole" not in inspect.signature(pytreegrav.Accel).parameters:
            out["pytreegrav_quadrupole"] = (f"pytreegrav {version('pytreegrav')} has no "
                                            "quadrupole walk")
    return out


class EngineTree:
    """One evaluation: ``sim.accelerations()`` of ``NBodyGravity(method=...)``."""

    def __init__(self, mass, pos, theta, method="fmm"):
        from engine import Simulation, forces

        n = mass.shape[0]
        self.sim = Simulation(dim=3, integrator="leapfrog", dt=1e-3, capacity=n)
        self.sim.add_many(mass=mass, pos=pos, vel=np.zeros_like(pos))
        self.sim.add_force(forces.NBodyGravity(softening=SOFTENING, method=method,
                                               theta=theta, order=2))
        self.acc = None

    def run(self):
        self.acc = self.sim.accelerations()

    def accelerations(self):
        return self.acc


class Pytreegrav:
    """One evaluation: ``pytreegrav.Accel(..., method="tree", parallel=True)``."""

    def __init__(self, mass, pos, theta, quadrupole=False):
        self.mass, self.pos, self.theta, self.quadrupole = mass, pos, theta, quadrupole
        self.h = np.full(mass.shape[0], SPLINE_PER_PLUMMER * SOFTENING)
        self.acc = None

    def run(self):
        from pytreegrav import Accel

        options = {"quadrupole": True} if self.quadrupole else {}
        self.acc = Accel(self.pos, self.mass, self.h, theta=self.theta, parallel=True,
                         method="tree", **options)

    def accelerations(self):
        return self.acc


class ReboundTree:
    """One evaluation: ``reb_simulation_update_acceleration`` with REBOUND's tree gravity
    (the tree built from the bodies, its moments, the walk; then deleted)."""

    def __init__(self, mass, pos, theta):
        import rebound
        from rebound import Particle, clibrebound

        sim = rebound.Simulation()
        blank = Particle()
        for _ in range(mass.shape[0]):  # bodies added in C, then set from the arrays at once
            clibrebound.reb_simulation_add(ctypes.byref(sim), blank)
        sim.set_serialized_particle_data(m=np.ascontiguousarray(mass, dtype=np.float64),
                                         xyz=np.ascontiguousarray(pos, dtype=np.float64))
        size = 2.0 * float(np.abs(pos).max()) * (1.0 + 1e-6)  # every body inside the box
        if hasattr(sim, "configure_box"):  # REBOUND 4
            sim.configure_box(size)
        else:
            sim.root_size = size
        sim.gravity = "tree"
        sim.softening = SOFTENING
        sim.opening_angle2 = theta * theta
        self.sim, self.clib = sim, clibrebound

    def run(self):
        self.clib.reb_simulation_update_acceleration(ctypes.byref(self.sim))

    def accelerations(self):
        """(n, 3): ax, ay, az of every particle struct, read in place."""
        from rebound import Particle

        n, size = self.sim.N, ctypes.sizeof(Particle)
        # REBOUND's own array of particle structs (the name is REBOUND's, not the engine's)
        particles = getattr(self.sim, "_particles")
        raw = np.ctypeslib.as_array(ctypes.cast(particles,
                                                ctypes.POINTER(ctypes.c_uint8)), shape=(n * size,))
        start = Particle.ax.offset
        return raw.reshape(n, size)[:, start:start + 24].copy().view(np.float64)


def make(code, mass, pos, theta):
    """The evaluator of ``code`` (one of ``CODES``, or "direct": the engine's direct sum)."""
    if code == "engine":
        return EngineTree(mass, pos, theta)
    if code == "engine_tree":
        return EngineTree(mass, pos, theta, method="tree")
    if code == "direct":
        return EngineTree(mass, pos, 0.5, method="direct")
    if code in ("pytreegrav", "pytreegrav_quadrupole"):
        return Pytreegrav(mass, pos, theta, quadrupole=code == "pytreegrav_quadrupole")
    if code == "rebound":
        return ReboundTree(mass, pos, theta)
    raise ValueError(f"code must be one of {CODES + ('direct',)}, got {code!r}")


def warm_up(codes, n=2000):
    """Each code's compiled code loaded (pytreegrav compiles its parallel walk on its first
    call in a process), before anything is timed."""
    mass, pos = plummer_sphere(n, 1)
    for code in codes:
        make(code, mass, pos, 0.5).run()


def _timed(fn):
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


# -- equal error ----------------------------------------------------------------------------
def theta_for_error(thetas, medians, target=TARGET_ERROR):
    """The theta at which the median error reaches ``target``: on the curve sorted by theta,
    the first pair of neighbours with error <= target at the smaller theta and > target at
    the larger, interpolated linearly in log theta against log error (an error grows as a
    power of theta). None if the curve does not cross the target."""
    points = sorted(zip(thetas, medians))
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if e0 <= target < e1:
            if e0 <= 0.0:
                return float(t0)
            w = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return float(math.exp(math.log(t0) + w * (math.log(t1) - math.log(t0))))
    return None


def error_curve(code, mass, pos, targets, exact, thetas=THETAS, target=TARGET_ERROR):
    """Rows {theta, median, p99, time_s} of ``code`` at each theta, extended by up to three
    smaller (or larger) thetas while the target error is not bracketed; and the matched theta."""
    rows = []

    def measure(theta):
        ev = make(code, mass, pos, theta)
        seconds = _timed(ev.run)
        stats = error_stats(relative_errors(ev.accelerations()[targets], exact))
        rows.append({"theta": float(theta), **stats, "time_s": seconds})

    for theta in thetas:
        measure(theta)
    top = MAX_THETA.get(code, 2.5)
    for _ in range(3):
        ordered = sorted(rows, key=lambda r: r["theta"])
        if ordered[0]["median"] > target:
            measure(ordered[0]["theta"] / 1.5)
        elif ordered[-1]["median"] <= target and ordered[-1]["theta"] < top:
            measure(min(ordered[-1]["theta"] * 1.3, top))
        else:
            break
    rows.sort(key=lambda r: r["theta"])
    matched = theta_for_error([r["theta"] for r in rows], [r["median"] for r in rows], target)
    return {"rows": rows, "theta_at_target": matched}


# -- timing ---------------------------------------------------------------------------------
def _predicted(times, n):
    """A code's time at n from its time at the largest smaller N, scaled as N log N."""
    smaller = [(m, t) for m, t in times.items() if m < n]
    if not smaller:
        return None
    m, t = max(smaller)
    return t * (n / m) * (math.log(n) / math.log(m))


def tuned_theta(code, mass, pos, targets, exact, start, target=TARGET_ERROR):
    """``code``'s theta for median error ``target`` on this very scene (an error curve at
    start / 1.1, start and 1.1 start, extended until it brackets the target: ``error_curve``);
    ``start`` if the curve never crosses it. (theta, the curve's rows)."""
    curve = error_curve(code, mass, pos, targets, exact, thetas=(start / 1.1, start,
                                                                  start * 1.1), target=target)
    found = curve["theta_at_target"]
    return (start if found is None else found), curve["rows"]


def compare_at(n, codes, thetas, repeats, seed=0, targets=1000, past=None, tune=True):
    """One row of the equal-error comparison at n bodies: each code's median time of one
    evaluation at its theta for the target error at this n (``tuned_theta``, from its theta in
    ``thetas``; as given if not ``tune``), the speed-ups of the engine (median of the
    per-repetition ratios t_code / t_engine), and each code's median and 99th-percentile
    error on the evaluation timed. ``past``: {code: {n: seconds}} of smaller N, to skip a code
    predicted to take more than ``SLOW_SECONDS``."""
    past = past if past is not None else {}
    mass, pos = plummer_sphere(n, seed)
    chosen = pick_targets(n, targets)
    exact = {k: exact_field(pos, mass, chosen, k) for k in {KERNELS[c] for c in codes}}
    row = {"n": n, "time_s": {}, "error": {}, "notes": {}, "repeats": {}, "theta": {}}
    runs = {}
    for code in codes:
        guess = _predicted(past.get(code, {}), n)
        if guess is not None and guess > SLOW_SECONDS:
            row["notes"][code] = (f"not timed: one evaluation predicted to take {guess:.0f} s "
                                  f"(> {SLOW_SECONDS:.0f} s)")
            continue
        theta = thetas[code]
        if tune:
            theta, _ = tuned_theta(code, mass, pos, chosen, exact[KERNELS[code]], theta)
        row["theta"][code] = theta
        ev = make(code, mass, pos, theta)
        first = _timed(ev.run)  # compiled code loaded; the result checked below
        row["error"][code] = error_stats(relative_errors(ev.accelerations()[chosen],
                                                         exact[KERNELS[code]]))
        runs[code] = (ev, first)
    cost = sum(first for _, first in runs.values())
    reps = max(1, min(repeats, int(REPEAT_BUDGET_SECONDS / max(cost, 1e-9))))
    times = {code: [] for code in runs}
    for _ in range(reps):
        for code, (ev, first) in runs.items():
            if first > SLOW_SECONDS:  # measured once: that one evaluation is the figure
                continue
            times[code].append(_timed(ev.run))
    for code, (ev, first) in runs.items():
        if not times[code]:
            times[code] = [first]
            row["notes"][code] = f"timed once ({first:.0f} s > {SLOW_SECONDS:.0f} s)"
        row["time_s"][code] = statistics.median(times[code])
        row["repeats"][code] = len(times[code])
        past.setdefault(code, {})[n] = row["time_s"][code]
    row["speedup"] = {}
    if "engine" in times:
        for code in times:
            if code == "engine":
                continue
            if len(times[code]) == len(times["engine"]):
                ratios = [b / a for a, b in zip(times["engine"], times[code])]
            else:  # a code measured once: against the engine's median
                ratios = [times[code][0] / row["time_s"]["engine"]]
            row["speedup"][code] = statistics.median(ratios)
    return row


def scaling(sizes, theta, repeats, seed=0):
    """The engine FMM's median time of one evaluation at each N, and the exponent a of the
    least-squares fit of log t = a log N + b."""
    times = []
    for n in sizes:
        mass, pos = plummer_sphere(n, seed)
        ev = make("engine", mass, pos, theta)
        ev.run()
        times.append(statistics.median(_timed(ev.run) for _ in range(repeats)))
    exponent = float(np.polyfit(np.log(sizes), np.log(times), 1)[0]) if len(sizes) > 1 else None
    return {"n": list(sizes), "time_s": times, "exponent": exponent}


def crossover_n(sizes, tree_s, direct_s):
    """The N where the FMM becomes faster than the direct sum: log-log interpolation of
    t_tree / t_direct between the first pair of sizes where it falls below 1. None if it
    never does at these sizes; the smallest size if it is already below 1 there."""
    ratios = [a / b for a, b in zip(tree_s, direct_s)]
    if ratios[0] < 1.0:
        return float(sizes[0])
    for (n0, r0), (n1, r1) in zip(zip(sizes, ratios), zip(sizes[1:], ratios[1:])):
        if r0 >= 1.0 > r1:
            w = math.log(r0) / (math.log(r0) - math.log(r1))
            return float(math.exp(math.log(n0) + w * (math.log(n1) - math.log(n0))))
    return None


def crossover(sizes, theta, repeats, seed=0):
    """The engine's FMM (at ``theta``) and direct sum timed side by side at each N."""
    tree_s, direct_s = [], []
    for n in sizes:
        mass, pos = plummer_sphere(n, seed)
        tree, direct = make("engine", mass, pos, theta), make("direct", mass, pos, theta)
        tree.run()
        direct.run()
        a, b = [], []
        for _ in range(max(repeats, 3)):
            a.append(_timed(tree.run))
            b.append(_timed(direct.run))
        tree_s.append(statistics.median(a))
        direct_s.append(statistics.median(b))
    return {"n": list(sizes), "tree_s": tree_s, "direct_s": direct_s,
            "crossover_n": crossover_n(sizes, tree_s, direct_s),
            "below_range": tree_s[0] < direct_s[0]}


# -- energy over a run -----------------------------------------------------------------------
#: the energy runs of the report's levels: a Plummer sphere of n bodies (softening
#: ``ENERGY_SOFTENING``), leapfrog at dt = ``ENERGY_DT``; the FMM for ``steps`` steps, the energy
#: measured every ``every``; the direct sum beside it for ``direct_steps`` (every
#: ``direct_every``): at 10^5 bodies a direct step takes seconds
ENERGY = {"full": {"n": 100_000, "steps": 1000, "every": 200, "direct_steps": 30,
                   "direct_every": 10},
          "quick": {"n": 10_000, "steps": 1000, "every": 100, "direct_steps": 200,
                    "direct_every": 50},
          "smoke": {"n": 1000, "steps": 40, "every": 10, "direct_steps": 20,
                    "direct_every": 10}}
ENERGY_SOFTENING = 0.01
#: 1/1250 of the sphere's crossing time G M^(5/2) / (2|E|)^(3/2) = 6.3
ENERGY_DT = 0.005


@jit(parallel=True, fastmath={"reassoc", "contract", "nsz", "arcp"}, error_model="numpy")
def _pair_potentials(pos, mass, eps2, out):
    """out[i] = -sum over j > i of m_i m_j / sqrt(r_ij^2 + eps^2) (G = 1), every pair once,
    float64; rows in parallel, each row's sum vectorised."""
    n = pos.shape[0]
    for i in prange(n):
        s = 0.0
        for j in range(i + 1, n):
            dx = pos[j, 0] - pos[i, 0]
            dy = pos[j, 1] - pos[i, 1]
            dz = pos[j, 2] - pos[i, 2]
            s += mass[j] / math.sqrt(dx * dx + dy * dy + dz * dz + eps2)
        out[i] = -mass[i] * s


def exact_energy(pos, vel, mass, softening):
    """Kinetic plus the softened potential energy of every pair (G = 1), summed exactly: the
    same bits at any thread count (each row's sum is made by one thread, the rows summed by
    numpy)."""
    rows = np.empty(mass.shape[0])
    _pair_potentials(np.ascontiguousarray(pos, dtype=np.float64),
                     np.ascontiguousarray(mass, dtype=np.float64), float(softening) ** 2, rows)
    return float(0.5 * np.sum(mass * np.sum(vel * vel, axis=1)) + rows.sum())


def energy_run(n, steps, every, method, theta, seed=3):
    """|dE/E| and |dP| / sum m|v| every ``every`` steps of a leapfrog run of an n-body Plummer
    sphere under ``NBodyGravity(method=method, theta=theta)``; the energy of each state by
    ``exact_energy`` (every pair), so that a tree's error in its own potential does not hide
    the run's. {t, dE, dP, growth (the fitted dE/E per unit time), seconds (the stepping alone)}."""
    from engine import Simulation, forces
    from engine import initial_conditions as ic

    bodies = ic.plummer(n, 3, seed=seed)
    sim = Simulation(dim=3, integrator="leapfrog", dt=ENERGY_DT, G=1.0, capacity=n)
    ic.add_to(sim, bodies)
    sim.add_force(forces.NBodyGravity(softening=ENERGY_SOFTENING, method=method, theta=theta))
    scale = float(np.sum(bodies.mass * np.linalg.norm(bodies.vel, axis=1)))

    def energy_now():
        return exact_energy(sim.pos, sim.vel, sim.mass, ENERGY_SOFTENING)

    e0, p0 = energy_now(), sim.momentum()
    out = {"t": [], "dE": [], "dP": []}
    seconds = 0.0
    for _ in range(steps // every):
        seconds += _timed(lambda: sim.step(every))
        out["t"].append(float(sim.t))
        out["dE"].append(float((energy_now() - e0) / abs(e0)))
        out["dP"].append(float(np.linalg.norm(sim.momentum() - p0) / scale))
    out["growth"] = (float(np.polyfit(out["t"], out["dE"], 1)[0]) if len(out["t"]) > 1
                     else None)
    out["seconds"] = seconds
    out["steps"] = steps
    return out


def energy(spec, theta):
    """The FMM's run and the direct sum's beside it (``ENERGY``'s ``spec``)."""
    return {"n": spec["n"], "dt": ENERGY_DT, "softening": ENERGY_SOFTENING, "theta": theta,
            "fmm": energy_run(spec["n"], spec["steps"], spec["every"], "fmm", theta),
            "direct": energy_run(spec["n"], spec["direct_steps"], spec["direct_every"],
                                 "direct", theta)}


def markdown_energy(e):
    """Markdown lines of an energy comparison."""
    out = [f"Energy over a run: a Plummer sphere of {e['n']} bodies (softening "
           f"{e['softening']:g}), leapfrog at dt = {e['dt']:g}, the FMM at theta = "
           f"{e['theta']:.3f} and the direct sum beside it (fewer steps: its steps cost "
           "N^2); the energy of each state by the direct sum.", "",
           "| run | steps | largest abs(dE/E) | fitted dE/E per unit time | largest abs(dP) / "
           "sum m abs(v) | stepping s |", "|---|---|---|---|---|---|"]
    for name in ("fmm", "direct"):
        r = e[name]
        growth = "—" if r["growth"] is None else f"{r['growth']:.2e}"
        out.append(f"| {'FMM' if name == 'fmm' else 'direct sum'} | {r['steps']} | "
                   f"{max(abs(x) for x in r['dE']):.2e} | {growth} | "
                   f"{max(r['dP']):.2e} | {r['seconds']:.3g} |")
    return out


# -- the section ------------------------------------------------------------------------------
def measure(sizes, progress=None, energy_spec=None):
    """The whole section at ``sizes`` (one of ``SIZES``'s values): a JSON-ready dict; with
    ``energy_spec`` (one of ``ENERGY``'s values) also the energy runs."""
    import numba

    say = progress or (lambda text: None)
    ok = available()
    wanted = sizes.get("codes", CODES)
    for code in CODES:
        if ok[code] is None and code not in wanted:
            ok[code] = "not run at this level"
    codes = [c for c in CODES if ok[c] is None]
    out = {"softening": SOFTENING, "spline_support": SPLINE_PER_PLUMMER * SOFTENING,
           "target_error": TARGET_ERROR, "labels": {c: LABELS[c] for c in codes},
           "skipped": {c: why for c, why in ok.items() if why is not None},
           "threads": numba.get_num_threads(),
           "sizes": {k: (list(v) if isinstance(v, tuple) else v) for k, v in sizes.items()}}
    say("compiled code loaded")
    warm_up(codes + ["direct"])
    n = sizes["error_n"]
    mass, pos = plummer_sphere(n, 0)
    chosen = pick_targets(n, sizes["targets"])
    exact = {k: exact_field(pos, mass, chosen, k) for k in {KERNELS[c] for c in codes}}
    curves = {}
    for code in codes:
        say(f"error against theta: {code}, N = {n}")
        curves[code] = error_curve(code, mass, pos, chosen, exact[KERNELS[code]])
    out["error"] = {"n": n, "targets": int(chosen.shape[0]), "curves": curves}
    thetas = {c: curves[c]["theta_at_target"] for c in codes}
    out["theta_at_target"] = thetas
    timed = [c for c in codes if thetas[c] is not None]
    for c in codes:
        if thetas[c] is None:
            out["skipped"][c] = (f"its median error does not cross {TARGET_ERROR:g} at the "
                                 "thetas tried")
    past, rows = {}, []
    for n in sizes["compare_n"]:
        say(f"equal error: N = {n}")
        rows.append(compare_at(n, timed, thetas, sizes["repeats"], targets=sizes["targets"],
                               past=past))
    out["compare"] = rows
    if thetas.get("engine") is not None:
        say("engine time against N")
        out["scaling"] = scaling(sizes["scaling_n"], thetas["engine"], sizes["repeats"])
        say("crossover with the direct sum")
        out["crossover"] = crossover(sizes["crossover_n"], thetas["engine"], sizes["repeats"])
    from engine.tree import layout

    if energy_spec is not None and thetas.get("engine") is not None:
        say(f"energy over a run: N = {energy_spec['n']}")
        out["energy"] = energy(energy_spec, thetas["engine"])
    out["memory"] = {"n": sizes["memory_n"],
                     "bytes_per_particle": float(layout.bytes_per_particle(sizes["memory_n"])),
                     "threads": int(layout.THREADS)}
    return out


# -- targets and text -----------------------------------------------------------------------
def _row(t, n):
    return next((r for r in t.get("compare", []) if r["n"] == n), None)


def best_pytreegrav(row):
    """(code, speed-up) of the faster pytreegrav configuration timed in ``row`` (None)."""
    found = [(c, row["speedup"][c]) for c in ("pytreegrav", "pytreegrav_quadrupole")
             if c in row.get("speedup", {})]
    return min(found, key=lambda cs: cs[1]) if found else None


def targets(t):
    """(target, measured, met) rows of the section ``t``."""
    rows = []
    big = _row(t, 1_000_000)
    if big and "engine" in big["time_s"]:
        rows.append(("FMM, N = 10^6: one force evaluation at median error 1e-3 in at most 1 s",
                     f"{big['time_s']['engine']:.2f} s", big["time_s"]["engine"] <= 1.0))
    for n in (100_000, 1_000_000):
        r = _row(t, n)
        best = best_pytreegrav(r) if r else None
        if best:
            rows.append((f"FMM, N = {n:.0e}: at least 4x faster than pytreegrav at equal median "
                         "error", f"{best[1]:.1f}x (against {LABELS[best[0]]})", best[1] >= 4.0))
    reb = [(r["n"], r["speedup"]["rebound"]) for r in t.get("compare", [])
           if "rebound" in r.get("speedup", {})]
    if reb:
        rows.append(("FMM: faster than REBOUND's tree at equal median error",
                     ", ".join(f"{s:.1f}x at N = {n:.0e}" for n, s in reb),
                     all(s > 1.0 for _, s in reb)))
    s = t.get("scaling")
    if s and s.get("exponent") is not None:
        rows.append(("FMM: time ~ N^a with a <= 1.15",
                     f"a = {s['exponent']:.2f} (N = {s['n'][0]:.0e} to {s['n'][-1]:.0e})",
                     s["exponent"] <= 1.15))
    c = t.get("crossover")
    if c:
        n_x = c["crossover_n"]
        rows.append(("FMM faster than the direct sum from N <= 5000", _crossover_text(c),
                     n_x is not None and n_x <= 5000))
    m = t.get("memory")
    if m:
        rows.append(("tree workspace: at most 300 bytes a particle at N = 10^6",
                     f"{m['bytes_per_particle']:.0f} B", m["bytes_per_particle"] <= 300))
    return rows


def _crossover_text(c):
    if c["crossover_n"] is None:
        return f"direct sum still faster at N = {c['n'][-1]}"
    if c["below_range"]:
        return f"FMM already faster at N = {c['n'][0]}"
    return f"N = {c['crossover_n']:.0f}"


def _seconds(x):
    return "—" if x is None else f"{x:.3g}"


def format_tree(t):
    """Text lines of the section."""
    lines = [f"  Plummer sphere, softening {t['softening']:g}; equal error: median relative "
             f"force error {t['target_error']:g}"]
    for code, why in t["skipped"].items():
        lines.append(f"  {code}: {why}")
    lines.append(f"  theta at median error {t['target_error']:g} (N = {t['error']['n']}): "
                 + ", ".join(f"{c} {_theta(v)}" for c, v in t["theta_at_target"].items()))
    codes = list(t["labels"])
    lines.append(f"{'N':>9}" + "".join(f"{c[:22]:>24}" for c in codes) + "   (s per evaluation)")
    for r in t["compare"]:
        lines.append(f"{r['n']:>9}" + "".join(f"{_seconds(r['time_s'].get(c)):>24}"
                                              for c in codes))
        lines.append(f"{'':>9}" + "".join(
            f"{('theta %.3f' % r['theta'][c]) if c in r.get('theta', {}) else '':>24}"
            for c in codes))
        lines.append(f"{'':>9}" + "".join(
            f"{('%.1fx' % r['speedup'][c]) if c in r['speedup'] else '':>24}" for c in codes)
            + "   (engine speed-up)")
        for c, note in r["notes"].items():
            lines.append(f"{'':>9}{c}: {note}")
    s = t.get("scaling")
    if s:
        lines.append("  engine time against N: " + ", ".join(
            f"{n:.0e} {x:.3g} s" for n, x in zip(s["n"], s["time_s"]))
            + f"; exponent {s['exponent']:.2f}")
    c = t.get("crossover")
    if c:
        lines.append("  FMM / direct: " + ", ".join(
            f"{n} {a / b:.2f}" for n, a, b in zip(c["n"], c["tree_s"], c["direct_s"]))
            + f"; crossover {_crossover_text(c)}")
    m = t["memory"]
    lines.append(f"  memory: {m['bytes_per_particle']:.0f} bytes a particle at N = {m['n']:.0e}")
    return lines


def _theta(v):
    return "not reached" if v is None else f"{v:.3f}"


def markdown_tree(t):
    """Markdown lines of the section."""
    codes = list(t["labels"])
    out = [f"A Plummer sphere (G = 1, total mass 1, scale radius 1, 3-D, float64), Plummer "
           f"softening {t['softening']:g}; pytreegrav's cubic spline at support "
           f"h = {t['spline_support']:g} (h = 2.8 eps: Springel, Yoshida & White 2001), and "
           "each code's error measured against the exact sum of its own kernel. The codes "
           f"are compared at equal median relative force error, {t['target_error']:g}: each "
           f"at the theta where its error curve ({t['error']['targets']} bodies at random) "
           f"crosses it, found at N = {t['error']['n']} (the table below) and again on each "
           "scene timed, around that theta (given with the times). Times are of one force "
           "evaluation (tree built, moments, walk), the median of repetitions timed one after "
           "the other; a speed-up is the median of the per-repetition ratios. The engine and "
           f"pytreegrav run on {t.get('threads', '?')} threads; REBOUND's pip build on one.", ""]
    for code, why in t["skipped"].items():
        out.append(f"- {code}: {why}")
    if t["skipped"]:
        out.append("")
    out += ["| code | theta at error " + f"{t['target_error']:g} |", "|---|---|"]
    out += [f"| {t['labels'][c]} | {_theta(v)} |" for c, v in t["theta_at_target"].items()]
    out += ["", "| N | " + " | ".join(f"{t['labels'][c]} s" for c in codes)
            + " | " + " | ".join(f"speed-up vs {SHORT[c]}" for c in codes if c != "engine")
            + " |",
            "|" + "---|" * (1 + 2 * len(codes) - 1)]
    for r in t["compare"]:
        out.append(f"| {r['n']:.0e} | " + " | ".join(
            _seconds(r["time_s"].get(c)) + (f" ({r['error'][c]['median']:.1e}, "
                                            f"theta {r['theta'][c]:.3f})"
                                            if c in r["error"] and c in r.get("theta", {})
                                            else "") for c in codes)
            + " | " + " | ".join(f"{r['speedup'][c]:.1f}x" if c in r["speedup"] else "—"
                                 for c in codes if c != "engine") + " |")
    out += ["", "(In brackets: each code's median error on that evaluation, and its theta, "
                "found for the target error on that scene.)"]
    notes = [f"N = {r['n']:.0e}, {c}: {note}" for r in t["compare"]
             for c, note in r["notes"].items()]
    if notes:
        out += [""] + [f"- {x}" for x in notes]
    s = t.get("scaling")
    if s:
        out += ["", "| N | engine FMM s |", "|---|---|"]
        out += [f"| {n:.0e} | {x:.3g} |" for n, x in zip(s["n"], s["time_s"])]
        out += ["", f"Fitted time ~ N^a: a = {s['exponent']:.2f}."]
    c = t.get("crossover")
    if c:
        out += ["", "| N | FMM s | direct s | FMM / direct |", "|---|---|---|---|"]
        out += [f"| {n} | {a:.3g} | {b:.3g} | {a / b:.2f} |"
                for n, a, b in zip(c["n"], c["tree_s"], c["direct_s"])]
        out += ["", f"Crossover with the direct sum: {_crossover_text(c)}."]
    m = t["memory"]
    out += ["", f"Tree workspace: {m['bytes_per_particle']:.0f} bytes a particle at "
                f"N = {m['n']:.0e} ({m['threads']} threads' interaction lists included)."]
    return out
