"""``engine.advise(sim, t_end, error)``: the cheapest integrator and step for this scene.

The advisor runs short pilot integrations of the user's own scene (on copies: the simulation
passed in is never changed) with every candidate method, measures the error each one makes
against a reference run, extrapolates it to ``t_end`` and searches, per method, the longest
step (the loosest tolerance, for the adaptive ones) whose predicted error at ``t_end`` is
within the requested ``error``. It recommends the method whose verified setting costs least.

What is measured
----------------
**Error.** ``metric="position"`` (the default): the largest distance of an active particle
from where the reference puts it, over ``length`` (default: the scene's extent, the largest
distance of a particle from its centre, see ``scene_length``), max_i |r_i - r_i^ref| / L.
``metric="energy"``: |E(t) - E(t0)| / |E(t0)| (only for conservative forces; no reference run
is needed, the energy at the start is the reference). The reference is ``ias15`` at epsilon
``REFERENCE_EPSILON``; its own uncertainty, the *floor*, is twice its distance from a second
run at epsilon ``CHECK_EPSILON``: an error below the floor is not measured, it is taken as the
floor. Where ``ias15`` cannot run the scene (its step criterion collapses where an
acceleration passes through zero, as a spring's does at rest length) ``rk45`` at tolerance
1e-13 is the reference, checked at 1e-11 (``REFERENCES``; ``Advice.notes`` says so).

**Cost.** Deterministic *work*: force evaluations times the pair interactions of one
evaluation (``interactions``: n_src (n_src - 1) / 2 + n_src n_test for ``NBodyGravity``, the
charged pairs for ``Coulomb``, one per particle for ``PointMass`` and the per-particle terms,
one per spring), plus, for ``whfast`` and ``saba``, ``KEPLER_DRIFT_WORK`` per Kepler drift of
one body. ``ias15`` counts its actual force evaluations (its predictor-corrector iterations
vary), ``rk45`` six per accepted step (its rejected attempts are not visible). The wall time
per step of each pilot is measured too and gives the predicted seconds; ``rank="time"`` ranks
by those instead of by work (machine-dependent, so not repeatable).

The method
----------
1. **Time scale** (``time_scale``): the shortest osculating two-body period in the scene, each
   moving particle about the body (or ``PointMass``) that pulls it hardest (bound: 2 pi
   sqrt(a^3 / mu); unbound: 2 pi sqrt(r^3 / mu)), and 2 pi / omega_max of the declared springs
   (``engine.stability.spring_frequency``); the span itself if nothing sets one.
2. **Pilot span** P: ``PILOT_PERIODS`` time scales, at least 1/``MAX_EXTRAPOLATION`` of the
   span S = t_end - sim.t. A *scout* run (``ias15`` at epsilon ``SCOUT_EPSILON`` over the
   whole span, in ``SCOUT_CHUNKS`` chunks) counts the adaptive steps each chunk takes, the
   scene's step rate. The pilot must contain a chunk at least ``SCOUT_HARD`` times as hard as
   the hardest of the whole run, or an extrapolation would miss a close encounter that only
   comes later (the Pythagorean problem's, at t = 16 and later); if that takes it past half
   the span, P = S: the pilots then run the whole span and nothing is extrapolated.
3. **Pilots.** A fixed-step pilot of N steps over P is sampled at ``SAMPLES`` equal times (as
   many as divide N), its error e_k at each sample t_k compared with the reference (an
   adaptive pilot only at its end: landing on the samples would change its step sequence,
   see ``_adaptive_pilot``). The error at t_end is predicted as max over the samples of the
   second half of

       max(e_k, floor_k) (S / t_k)^q

   with q the error's growth in time, stated per method (``growth``): for positions, q = 1
   for the symplectic methods (bounded energy error, a phase error growing linearly in time)
   and q = 2 for the others (energy drifting linearly, so the phase quadratically; ``ias15``'s
   round-off random walk grows as t^1.5 (Brouwer's law), taken as 2); for the energy, q = 0.5
   (symplectic: bounded, allowing for a round-off random walk) and 1 (the others). Taking the
   largest over the second half is conservative when t_end falls at another orbital phase than
   the pilot's end (the error of an eccentric orbit peaks at pericentre). When P = S the
   error at t_end is the one measured, nothing is assumed.
4. **Search**, per method: start at ``STEPS_PER_PERIOD`` steps per time scale; from the
   predicted error E at N pilot steps, aim at ``AIM`` times the requested error with
   N' = N (E / (AIM error))^(1/p), p the order measured between the last two pilots (the
   method's order from ``engine.ORDERS`` until there are two), keep the steps bracketed by the
   pilots that passed and failed, and stop when a passing pilot is within ``GOOD_ENOUGH`` of
   the ideal step count, after ``MAX_PILOTS`` pilots, or when the next pilot would cost more
   than ``ABANDON`` times the best method found so far (predicted from two pilots, or from
   one when even ``ABANDON``^2 times; the methods are tried in the order of ``SEARCH_ORDER``,
   strongest first, so that bound is found early). An error at the
   reference's floor (an exact method: ``whfast`` on a two-body scene) makes the step 16 times
   longer, up to the whole span in one step. Adaptive methods search their tolerance the same
   way (cost ~ tolerance^(-1/(order+1)), so a passing pilot within a factor 3 of the ideal
   tolerance is good enough). A pilot that blows up (``SimulationError``) counts as failed.
5. **Choice**: among the candidates with a *verified* setting (a pilot at exactly that step or
   tolerance met the requested error), the one of least predicted work (or time). Candidates
   only extrapolated (abandoned, or out of pilots) are listed with their predicted figures and
   marked unverified; if none is verified, the most accurate is recommended and
   ``Advice.reached`` is False. For an adaptive method ``Advice.dt`` is the first step its
   pilot took, so that a run with the advice repeats the pilot's step sequence.

Measured (the harness of ``tests/engine/test_advisor.py``: a sweep of 1, 2, 4, ... steps per
span for every method, cost as work) on the outer solar system over 1e5 days, Kepler e = 0.9
over 100 orbits, a star with 200 test particles over 20 orbits (each with all candidates and
without ``whfast`` and ``saba``) and the Pythagorean problem to t = 30 (energy; positions to
1e-7), at errors 1e-3, 1e-5, 1e-7 and 1e-9, 31 cases: the advised setting, run to t_end,
reached at most 1.86 times the requested error (the outer solar system at 1e-5 with ``whfast``:
its error grew faster than linearly after the pilot) and cost 0.62 to 1.22 times the work of
the sweep's cheapest; the advisor took 0.03 to 1.4 s on the 2-core development machine. The
Pythagorean positions at 1e-9 are beyond measuring: two ias15 references at epsilon 1e-12 from
different first steps differ by 1e-9 at t = 30.

Whatever the advisor predicts, the pilots only see the pilot span: close encounters the scout
does not resolve, or chaos over many Lyapunov times, are beyond what an extrapolation can
promise (``Advice.notes`` says when the scout forced whole-span pilots).
"""
import copy
import math
import time
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from . import forces as _forces
from . import integrators as _integrators
from ._validate import finite_float, positive_float
from .errors import SimulationError
from .integrators import ias15 as _ias15
from .integrators import janus as _janus
from .integrators import wisdom_holman as _wh
from .units import strip_without_units

#: the candidates, in the order of ``engine.INTEGRATORS``: (integrator, options)
CANDIDATES = (
    ("euler", {}), ("symplectic_euler", {}), ("leapfrog", {}), ("verlet", {}), ("rk4", {}),
    ("yoshida4", {}), ("pefrl", {}), ("rk45", {}),
    ("whfast", {"corrector": 0}), ("whfast", {"corrector": 11}), ("whfast", {"corrector": 17}),
    ("saba", {"saba": "SABA(10,6,4)"}), ("ias15", {}), ("janus", {"janus_order": 6}),
)
#: the order in which candidates are searched: the usually strongest first, so that the
#: ``ABANDON`` bound is known early and the weak ones stop after a pilot or two
SEARCH_ORDER = ("ias15", "saba SABA(10,6,4)", "whfast corrector=17", "whfast corrector=11",
                "whfast corrector=0", "janus order=6", "pefrl", "yoshida4", "rk45", "rk4",
                "leapfrog", "verlet", "symplectic_euler", "euler")

METRICS = ("position", "energy")
RANKS = ("work", "time")

REFERENCE_EPSILON = 1e-12  # ias15's epsilon for the reference run
CHECK_EPSILON = 1e-10      # ... and for the second run that measures the reference's floor
#: the reference runs: (method, tolerance of the reference, of its check), the next one used
#: when one fails (ias15's step criterion collapses where an acceleration passes through zero,
#: as a spring's does at its rest length)
REFERENCES = (("ias15", REFERENCE_EPSILON, CHECK_EPSILON), ("rk45", 1e-13, 1e-11))
SCOUT_EPSILON = 1e-6       # ias15's epsilon for the scout over the whole span
SCOUT_CHUNKS = 128         # the scout counts its steps in this many equal chunks
SCOUT_HARD = 0.8           # the pilot must contain a chunk this hard (step rate) as the hardest
SCOUT_MAX_STEPS = 200_000  # the scout stops (and says so) after this many steps
PILOT_PERIODS = 4.0        # the pilot span in time scales ...
MAX_EXTRAPOLATION = 100.0  # ... and at least this fraction of the span
SAMPLES = 8                # error samples over a pilot
STEPS_PER_PERIOD = 32      # the first pilot's steps per time scale
MAX_PILOTS = 7             # pilots per candidate
AIM = 0.5                  # a pilot aims at this fraction of the requested error
GOOD_ENOUGH = 1.25         # stop when a passing pilot is within this factor of the ideal steps
ABANDON = 4.0              # stop a candidate whose next pilot predicts more than this x the best
MAX_PILOT_STEPS = 10_000_000
#: work of one Kepler drift of one body, in pair interactions of the gravity kernel: measured
#: on the 2-core development machine, a whfast step of 200 test particles about a star costs
#: what 700 pair interactions of leapfrog's step cost (3.5 per drift), one of the outer solar
#: system's five bodies 12; taken as 8
KEPLER_DRIFT_WORK = 8.0
_TINY = 1e-300


# -- results ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class Candidate:
    """One candidate method as the advisor measured it.

    ``dt`` (fixed-step methods) or ``tolerance`` (``rk45``, ``ias15``) is its setting for the
    whole run; ``steps``, ``error``, ``work`` and ``seconds`` are predicted for t_end.
    ``verified``: a pilot at exactly this setting met the requested error (otherwise the
    figures are extrapolated from other settings). ``skipped`` is the reason the method cannot
    run this scene (``whfast`` and ``saba`` without a dominant mass), else None. ``pilots``
    lists ``(setting, predicted error at t_end, pilot steps)`` of every pilot, in order."""

    label: str
    method: str
    options: dict
    dt: float = None
    tolerance: float = None
    steps: float = math.nan
    error: float = math.nan
    work: float = math.nan
    seconds: float = math.nan
    verified: bool = False
    skipped: str = None
    note: str = ""
    pilots: tuple = ()

    @property
    def setting(self):
        return self.tolerance if self.method in _integrators.ADAPTIVE_INTEGRATORS else self.dt


@dataclass(frozen=True)
class Advice:
    """What ``advise`` recommends, and every candidate's figures (``candidates``).

    ``method``, ``options``, ``dt`` (the step; for the adaptive methods the first step) and
    ``tolerance`` (adaptive methods; else None) are the recommendation, ``error``, ``work``,
    ``seconds`` and ``steps`` its predicted figures at ``t_end``. ``reached`` is False when
    no candidate's pilot met the requested error (the recommendation is then the most accurate
    candidate measured). ``simulation_options()`` gives the keyword arguments to set.
    """

    method: str
    options: dict
    dt: float
    tolerance: float
    error: float
    work: float
    seconds: float
    steps: float
    reached: bool
    requested_error: float
    t_end: float
    span: float
    metric: str
    length: float
    rank: str
    time_scale: float
    pilot_span: float
    floor: float
    candidates: tuple
    advisor_seconds: float
    advisor_work: float
    notes: tuple = ()

    @property
    def label(self):
        return label(self.method, self.options)

    @property
    def chosen(self):
        """The chosen ``Candidate``."""
        for c in self.candidates:
            if c.label == self.label:
                return c
        return None

    def simulation_options(self):
        """``{"integrator": ..., "dt": ..., "tolerance": ..., **options}``: keyword arguments
        of ``Simulation`` (or attributes to set) for the recommended method."""
        out = {"integrator": self.method, "dt": self.dt}
        if self.tolerance is not None:
            out["tolerance"] = self.tolerance
        out.update(self.options)
        return out

    def apply(self, sim):
        """Set the recommended integrator, step, tolerance and options on ``sim``."""
        for name, value in self.simulation_options().items():
            setattr(sim, name, value)
        return sim

    def table(self):
        """The candidates' figures as a text table."""
        return format_table(self)

    def __str__(self):
        return self.table()


# -- input -----------------------------------------------------------------------------------

def _check_inputs(sim, t_end, error, metric, length, rank):
    from .simulation import Simulation

    if not isinstance(sim, Simulation):
        raise TypeError(f"sim must be an engine.Simulation, got {sim!r}")
    if sim.n == 0 or not np.any(sim.active):
        raise ValueError(f"sim has no active particles to advise on (n={sim.n})")
    if sim.units is not None:
        t_end = sim.units.to_code(t_end, "time", "t_end")
    else:
        t_end = strip_without_units(t_end, "t_end")
    t_end = finite_float("t_end", t_end)
    if t_end == sim.t:
        raise ValueError(f"t_end must differ from the simulation's time t={sim.t!r}, got "
                         f"t_end={t_end!r}")
    if not math.isfinite(t_end - sim.t):
        raise ValueError(f"t_end={t_end!r} is too far from t={sim.t!r}: the span overflows")
    error = positive_float("error", error)
    if metric not in METRICS:
        raise ValueError(f"metric must be one of {', '.join(METRICS)}, got {metric!r}")
    if metric == "energy":
        for f in sim.forces:
            if not f.conservative:
                raise ValueError(f"metric='energy' needs conservative forces only; "
                                 f"{type(f).__name__} is not (use metric='position')")
    if length is not None:
        if sim.units is not None:
            length = sim.units.to_code(length, "length", "length")
        length = positive_float("length", length)
    if rank not in RANKS:
        raise ValueError(f"rank must be one of {', '.join(RANKS)}, got {rank!r}")
    return t_end, error, length


def label(method, options):
    """The candidate's name in the advisor's table: ``"whfast corrector=17"``, ``"saba
    SABA(10,6,4)"``, ``"janus order=6"``, else the integrator's name."""
    if method == "whfast":
        name = f"whfast corrector={options.get('corrector', 0)}"
        if options.get("kernel", "standard") != "standard":
            name += f" kernel={options['kernel']}"
        return name
    if method == "saba":
        return f"saba {options.get('saba', _wh.DEFAULT_SABA)}"
    if method == "janus":
        return f"janus order={options.get('janus_order', 6)}"
    return method


def _select(methods):
    """The candidates ``methods`` names (integrator names or candidate labels)."""
    every = [(m, dict(o), label(m, o)) for m, o in CANDIDATES]
    if methods is None:
        return every
    if isinstance(methods, str):
        methods = [methods]
    names = list(methods)
    for name in names:
        if not any(name in (c[0], c[2]) for c in every):
            raise ValueError(f"methods: {name!r} is not a candidate; the candidates are "
                             f"{', '.join(c[2] for c in every)} (or an integrator name)")
    if not names:
        raise ValueError(f"methods must name at least one candidate, got {methods!r}")
    return [c for c in every if c[0] in names or c[2] in names]


# -- copies of the user's simulation ------------------------------------------------------

def clone_simulation(sim, integrator=None, dt=None, **options):
    """An independent copy of ``sim`` (particles, force terms, settings, time), optionally
    with another ``integrator``, ``dt`` and integrator options (``tolerance``, ``corrector``,
    ``kernel``, ``saba``, ``janus_order``).

    Force terms are copied with it (a term belongs to one simulation), so the copy can be
    stepped without touching ``sim``. The copy starts with no ``ias15`` predictor memory and no
    ``janus`` lattice, as a fresh simulation would. ``engine.Simulation`` has no public copy,
    so this is a deep copy."""
    c = copy.deepcopy(sim)
    c._ias15_memory = None
    c.janus_lattice = None
    if integrator is not None:
        c.integrator = integrator
    if dt is not None:
        c.dt = dt
    for name, value in options.items():
        setattr(c, name, value)
    return c


# -- the scene -------------------------------------------------------------------------------

def _orbit_time(mu, r, v):
    """2 pi sqrt(a^3 / mu) of the osculating orbit (bound), else 2 pi sqrt(r^3 / mu)."""
    rn = float(np.sqrt(np.dot(r, r)))
    if mu <= 0.0 or rn == 0.0:
        return math.inf
    energy = 0.5 * float(np.dot(v, v)) - mu / rn
    a = -mu / (2.0 * energy) if energy < 0.0 else rn
    return 2.0 * math.pi * math.sqrt(a ** 3 / mu)


def time_scale(sim):
    """The scene's shortest characteristic period (see the module): osculating two-body
    periods of each moving particle about what pulls it hardest, and the springs' fastest
    mode; ``inf`` if nothing declared sets one."""
    pos, vel, mass = sim.pos, sim.vel, sim.mass
    active, test, pinned = np.asarray(sim.active), np.asarray(sim.test), np.asarray(sim.pinned)
    moving = np.flatnonzero(active & ~pinned)
    best = math.inf
    sources = np.flatnonzero(active & ~test & (mass > 0.0))
    for f in sim.forces:
        if isinstance(f, _forces.NBodyGravity) and sources.size:
            G = sim.G if f.G is None else float(f.G)
            if G <= 0.0:
                continue
            for i in moving:
                js = sources[sources != i]
                if js.size == 0:
                    continue
                d = pos[js] - pos[i]
                r2 = np.einsum("ij,ij->i", d, d)
                with np.errstate(divide="ignore"):
                    pull = mass[js] / r2
                j = js[int(np.argmax(pull))]
                mu = G * (mass[j] + (0.0 if test[i] else mass[i]))
                best = min(best, _orbit_time(mu, pos[i] - pos[j], vel[i] - vel[j]))
        elif isinstance(f, _forces.PointMass):
            mu = float(sim.parameter(f, "mu"))
            centre = sim.parameter(f, "pos")
            acted = moving if f.particles.size == 0 else np.intersect1d(moving, f.particles)
            for i in acted:
                best = min(best, _orbit_time(mu, pos[i] - centre, vel[i]))
        elif isinstance(f, _forces.Springs):
            from .stability import spring_frequency
            omega = spring_frequency(sim)[0]
            if 0.0 < omega < math.inf:
                best = min(best, 2.0 * math.pi / omega)
    return best


def _centre(sim, pos):
    for f in sim.forces:
        if isinstance(f, _forces.PointMass):
            return sim.parameter(f, "pos")
    active = np.asarray(sim.active)
    weights = np.where(active & ~np.asarray(sim.test), sim.mass, 0.0)
    if weights.sum() > 0.0:
        return (weights[:, None] * pos).sum(axis=0) / weights.sum()
    return pos[active].mean(axis=0)


def scene_length(sim, positions=()):
    """The default ``length`` of the position error: the largest distance of an active
    particle from the scene's centre (the first ``PointMass``, else the centre of mass of the
    massive particles, else the particles' mean) at the start and at each of ``positions``
    (the reference's samples); 1.0 if all particles sit at the centre."""
    active = np.asarray(sim.active)
    top = 0.0
    for pos in (sim.pos,) + tuple(positions):
        d = pos[active] - _centre(sim, pos)
        top = max(top, float(np.sqrt(np.einsum("ij,ij->i", d, d).max())))
    return top if top > 0.0 else 1.0


def interactions(sim):
    """Pair interactions of one force evaluation of ``sim``'s declared terms (see the
    module); at least 1."""
    active = np.asarray(sim.active)
    n = int(active.sum())
    total = 0
    for f in sim.forces:
        total += _term_interactions(sim, f, active, n)
    return max(total, 1)


def _term_interactions(sim, f, active, n):
    if isinstance(f, _forces.NBodyGravity):
        m = int((active & ~np.asarray(sim.test) & (sim.mass > 0.0)).sum())
        return m * (m - 1) // 2 + m * (n - m)
    if isinstance(f, _forces.Coulomb):
        q = int((active & (sim.charge != 0.0)).sum())
        return q * (q - 1) // 2
    if isinstance(f, _forces.PointMass):
        return n if f.particles.size == 0 else int(active[f.particles].sum())
    if isinstance(f, _forces.Springs):
        return len(f)
    return n


def step_work(sim, method=None, options=None):
    """Work (see the module) of one step of ``method`` (default: ``sim``'s integrator, with
    its options) on ``sim``; for ``ias15`` the typical 22 evaluations, for ``rk45`` 6."""
    method = sim.integrator if method is None else method
    if options is None:
        options = {"corrector": sim.corrector, "kernel": sim.kernel, "saba": sim.saba,
                   "janus_order": sim.janus_order}
    if method in _integrators.KEPLER_SPLITTING:
        active = np.asarray(sim.active & ~sim.pinned)
        attractor = [f for f in sim.forces if isinstance(f, _forces.PointMass)]
        kick = interactions(sim)
        if attractor:
            f = attractor[0]
            kick = max(kick - _term_interactions(sim, f, np.asarray(sim.active),
                                                 int(np.asarray(sim.active).sum())), 0)
            drifted = int(active.sum()) if f.particles.size == 0 else int(active[f.particles].sum())
        else:
            drifted = max(int(active.sum()) - 1, 0)
        if method == "whfast":
            kicks = 2 if options.get("kernel", "standard") == "lazy" else 1
            drifts = 1
        else:
            d, k, cc = _wh.saba_scheme(options.get("saba", _wh.DEFAULT_SABA))
            kicks = k.shape[0] + (2 if cc else 0)
            drifts = d.shape[0] - 1
        return kicks * kick + drifts * drifted * KEPLER_DRIFT_WORK
    if method == "janus":
        evaluations = _janus.FORCE_EVALUATIONS[options.get("janus_order", 6)]
    else:
        evaluations = _integrators.FORCE_EVALUATIONS[method]
    return evaluations * interactions(sim)


def run_work(sim):
    """Work (see the module) of the steps ``sim`` has taken since it was made: steps times
    ``step_work``, and for ``ias15`` its own count of force evaluations."""
    if sim.integrator == "ias15" and sim._ias15_memory is not None:
        return _ias15.statistics(sim._ias15_memory)["evaluations"] * interactions(sim)
    return sim.steps * step_work(sim)


def growth(method, metric):
    """The exponent q of the error's growth in time assumed for ``method`` (see the module)."""
    symplectic = method in _integrators.SYMPLECTIC
    if metric == "energy":
        return 0.5 if symplectic else 1.0
    return 1.0 if symplectic else 2.0


def _order(method, options):
    if method == "janus":
        return float(options.get("janus_order", 6))
    return float(_integrators.ORDERS[method])


# -- measurements ----------------------------------------------------------------------------

class _Measure:
    """Errors of sampled states, against the reference (position) or the start (energy)."""

    def __init__(self, base, t0, sign, metric, length, time_scale, span):
        self.base, self.t0, self.sign = base, t0, sign
        self.metric, self.length = metric, length
        self.active = np.asarray(base.active).copy()
        self.first_dt = sign * min(time_scale, span) / 100.0
        self.cache = {}  # time -> (reference positions, distance of the check run)
        self.known = set()  # every time asked for
        self.runs = {}  # tolerance -> the reference simulation, where it stopped
        self.reference = 0  # index in REFERENCES
        self.notes = []
        self.work = 0.0  # of the reference runs
        if metric == "energy":
            k0, u0 = base.kinetic_energy(), base.potential_energy()
            self.e0 = k0 + u0
            self.e_scale = abs(self.e0) if self.e0 != 0.0 else abs(k0) + abs(u0)
            self.e_floor = (16.0 * np.finfo(float).eps * (abs(k0) + abs(u0))
                            / max(self.e_scale, _TINY))

    def time(self, span, frac):
        return self.t0 + self.sign * (span * float(frac))

    def prepare(self, times):
        """Run the reference (and its check) to every time of ``times`` not yet known."""
        if self.metric == "energy":
            return
        missing = sorted({t for t in times if t not in self.cache},
                         key=lambda t: self.sign * (t - self.t0))
        if not missing:
            return
        while True:
            method, reference, check = REFERENCES[self.reference]
            try:
                states = {eps: self._run(method, eps, missing) for eps in (reference, check)}
                break
            except SimulationError as exc:
                if self.reference + 1 == len(REFERENCES):
                    raise SimulationError(
                        f"advise: no reference run could integrate this scene ({exc})",
                        step=exc.step, time=exc.time, particle=exc.particle) from exc
                self.notes.append(f"the reference {method} at {reference:g} failed ({exc}); "
                                  f"the reference is {REFERENCES[self.reference + 1][0]}")
                self.reference += 1
                self.runs, self.cache = {}, {}
                missing = sorted({t for t in list(times) + list(self.known)},
                                 key=lambda t: self.sign * (t - self.t0))
        self.known.update(missing)
        for k, t in enumerate(missing):
            ref, other = states[reference][k], states[check][k]
            self.cache[t] = (ref, self._distance(other, ref))

    def _run(self, method, eps, times):
        """Positions of the reference ``method`` at tolerance ``eps`` at each of ``times``."""
        sim = self.runs.get(eps)
        if sim is None or self.sign * (times[0] - sim.t) < 0.0:
            sim = clone_simulation(self.base, method, dt=self.first_dt, tolerance=eps)
        before = run_work(sim)
        out = []
        try:
            for t in times:
                sim.integrate(t)
                out.append(sim.pos.copy())
        finally:
            self.work += run_work(sim) - before
        self.runs[eps] = sim
        return out

    def _distance(self, pos, ref):
        d = (pos - ref)[self.active]
        return float(np.sqrt(np.einsum("ij,ij->i", d, d).max()))

    def floor(self, t):
        """The reference's uncertainty at time ``t`` (twice its distance from the check)."""
        if self.metric == "energy":
            return self.e_floor
        return 2.0 * self.cache[t][1] / self.length

    def error(self, sim, t):
        """``(error, floor)`` of ``sim``'s state, sampled at time ``t``."""
        if self.metric == "energy":
            e = abs(sim.energy() - self.e0) / max(self.e_scale, _TINY)
        else:
            e = self._distance(sim.pos, self.cache[t][0]) / self.length
        return (e if math.isfinite(e) else math.inf), self.floor(t)


@dataclass
class _Pilot:
    setting: float       # steps over the whole span (fixed) or tolerance (adaptive)
    error: float         # predicted error at t_end
    at_floor: bool
    steps: float         # predicted steps to t_end
    work: float          # predicted work to t_end
    seconds: float       # measured wall time of the pilot's steps
    pilot_steps: int
    dt: float = None
    span: float = None

    @property
    def pilot_span_steps(self):
        return (int(round(self.span / abs(self.dt))), self.span)


class _Advisor:
    def __init__(self, sim, t_end, error, metric, length):
        self.t0 = sim.t
        self.t_end = t_end
        self.S = abs(t_end - sim.t)
        self.sign = 1.0 if t_end > sim.t else -1.0
        self.target = error
        self.metric = metric
        self.notes = []
        self.base = clone_simulation(sim)
        self.work = 0.0  # the advisor's own work
        T = time_scale(self.base)
        self.T = T if math.isfinite(T) else self.S
        self.P = self._pilot_span()
        self.measure = _Measure(self.base, self.t0, self.sign, metric, length or 1.0, self.T,
                                self.S)
        base_times = [self.measure.time(self.P, Fraction(k, SAMPLES))
                      for k in range(1, SAMPLES + 1)]
        self.measure.prepare(base_times)
        self.length = length
        if metric == "position" and length is None:
            # the extent the reference covers over the pilot span
            self.length = scene_length(self.base, [self.measure.cache[t][0] for t in base_times])
            self.measure.length = self.length
        self.floor = max(self.measure.floor(t) for t in base_times)
        self.best_work = math.inf

    # -- the pilot span --------------------------------------------------------------------------
    def _pilot_span(self):
        S = self.S
        P = min(S, max(PILOT_PERIODS * self.T, S / MAX_EXTRAPOLATION))
        if P >= S:
            return S
        scout = clone_simulation(self.base, "ias15", dt=self.sign * min(self.T, S) / 100.0,
                                 tolerance=SCOUT_EPSILON)
        try:
            scout.step(3)  # adapt the first step before counting
        except SimulationError:
            self.notes.append(f"the scout (ias15 at epsilon {SCOUT_EPSILON:g}) failed at once: "
                              "the pilots run the whole span")
            return S
        t_start = scout.t
        rates, ends = [], []
        for k in range(1, SCOUT_CHUNKS + 1):
            t = self.t0 + self.sign * S * k / SCOUT_CHUNKS
            if self.sign * (t - t_start) <= 0.0:
                continue
            before = scout.steps
            try:
                scout.integrate(t)
            except SimulationError as exc:
                self.notes.append(f"the scout (ias15 at epsilon {SCOUT_EPSILON:g}) failed at "
                                  f"t={exc.time!r}: the pilots run the whole span")
                self.work += run_work(scout)
                return S
            rates.append((scout.steps - before) / (S / SCOUT_CHUNKS))
            ends.append(abs(t - self.t0))
            if scout.steps > SCOUT_MAX_STEPS:
                self.notes.append(f"the scout stopped after {scout.steps} steps at "
                                  f"t={scout.t!r}: the rest of the span was not checked for "
                                  "close encounters")
                break
        self.work += run_work(scout)
        if rates:
            hardest = max(rates)
            first = next(e for r, e in zip(rates, ends) if r >= SCOUT_HARD * hardest)
            if first > P:
                P = first
                if P > S / 2.0:
                    where = self.t0 + self.sign * first
                    self.notes.append(
                        f"the scout found its hardest stretch at t={where:.6g} (close "
                        "encounters): the pilots run the whole span, nothing is extrapolated")
                    return S
        return P

    # -- one pilot ------------------------------------------------------------------------------
    def _predict(self, samples, span, q):
        """Predicted error at t_end and whether it is the floor's, from ``(frac, e, floor)``."""
        if any(not math.isfinite(e) for _, e, _ in samples):
            return math.inf, False
        if span >= self.S:
            _, e, f = samples[-1]
            return max(e, f), e <= f
        worst, floor_hit = 0.0, False
        for frac, e, f in samples:
            if frac < Fraction(1, 2):
                continue
            t = span * float(frac)
            v = max(e, f) * (self.S / t) ** q
            if v >= worst:
                worst, floor_hit = v, e <= f
        return worst, floor_hit

    def _snap(self, n):
        """``(N, span)``: ``n`` steps over the whole span as N whole steps over a pilot span
        (the pilot span, or for steps longer than it, one step over a longer span)."""
        N = int(round(n * self.P / self.S))
        if N >= 1:
            return N, self.P
        span = self.P
        while span < self.S / n and span < self.S:
            span = min(self.S, 2.0 * span)
        return 1, span

    def _fixed_pilot(self, cand, n):
        """A pilot of ``cand`` for ``n`` steps over the whole span (snapped by ``_snap``);
        returns a ``_Pilot``."""
        method, options, _ = cand
        N, span = self._snap(n)
        K = next(k for k in (SAMPLES, 4, 2, 1) if N % k == 0)
        fracs = [Fraction(j, K) for j in range(1, K + 1)]
        times = [self.measure.time(span, f) for f in fracs]
        self.measure.prepare(times)
        dt = self.sign * span / N
        sim = clone_simulation(self.base, method, dt=dt, **options)
        samples, seconds = [], 0.0
        try:
            for f, t in zip(fracs, times):
                start = time.perf_counter()
                sim.step(N // K)
                seconds += time.perf_counter() - start
                e, fl = self.measure.error(sim, t)
                samples.append((f, e, fl))
        except SimulationError:
            samples.append((Fraction(1), math.inf, 0.0))
        self.work += run_work(sim)
        error, at_floor = self._predict(samples, span, growth(method, self.metric))
        steps = math.ceil(self.S / abs(dt) * (1.0 - 1e-12))
        return _Pilot(setting=self.S / abs(dt), error=error, at_floor=at_floor, steps=steps,
                      work=steps * step_work(sim, method, options), seconds=seconds,
                      pilot_steps=sim.steps, dt=dt, span=span)

    def _adaptive_pilot(self, cand, tol):
        method, options, _ = cand
        span = self.P
        # sampled at the end only: landing on intermediate times would change the adaptive
        # step sequence (a run to t_end lands once, at its end; on Kepler e = 0.9 the error
        # after 4 orbits of ias15 at epsilon 3e-6 came out 2.3 times smaller with 8 landings)
        fracs = [Fraction(1)]
        times = [self.measure.time(span, f) for f in fracs]
        self.measure.prepare(times)
        sim = clone_simulation(self.base, method, dt=self.measure.first_dt, tolerance=tol,
                               **options)
        samples, seconds = [], 0.0
        try:
            for f, t in zip(fracs, times):
                start = time.perf_counter()
                sim.integrate(t)
                seconds += time.perf_counter() - start
                e, fl = self.measure.error(sim, t)
                samples.append((f, e, fl))
        except SimulationError:
            samples.append((Fraction(1), math.inf, 0.0))
        pilot_work = run_work(sim)
        self.work += pilot_work
        error, at_floor = self._predict(samples, span, growth(method, self.metric))
        scale = self.S / span
        return _Pilot(setting=tol, error=error, at_floor=at_floor,
                      steps=math.ceil(sim.steps * scale), work=pilot_work * scale,
                      seconds=seconds, pilot_steps=sim.steps, dt=self.measure.first_dt,
                      span=span)

    # -- the search per candidate -----------------------------------------------------------------
    def _warm(self, cand):
        """Compile (or load) the method's kernels; the reason it cannot run, or None."""
        method, options, _ = cand
        sim = clone_simulation(self.base, method, dt=self.measure.first_dt / 10.0, **options)
        try:
            sim.step(1)
            sim.step(1)
        except ValueError as exc:
            return str(exc)
        except SimulationError:
            pass
        self.work += run_work(sim)
        return None

    def _local_order(self, pilots, default, key):
        """Slope of log(error) against log(key) between the last two usable pilots."""
        usable = [p for p in pilots if math.isfinite(p.error) and not p.at_floor
                  and p.error > 0.0]
        if len(usable) < 2:
            return default
        a, b = usable[-2], usable[-1]
        if key(a) == key(b) or a.error == b.error:
            return default
        return math.log(a.error / b.error) / math.log(key(b) / key(a))

    def search_fixed(self, cand):
        method, options, _ = cand
        p_known = _order(method, options)
        n = max(1.0, STEPS_PER_PERIOD * self.S / self.T)
        pilots = []
        note = ""
        while len(pilots) < MAX_PILOTS:
            N, span = self._snap(n)
            if any(p.pilot_span_steps == (N, span) for p in pilots):
                break
            pilot = self._fixed_pilot(cand, n)
            pilots.append(pilot)
            ok = [p for p in pilots if p.error <= self.target]
            n_ok = min((p.setting for p in ok), default=math.inf)
            bad = [p.setting for p in pilots if p.error > self.target and p.setting < n_ok]
            n_bad = max(bad, default=0.0)
            if not math.isfinite(pilot.error):
                proposal = pilot.setting * 4.0
            elif pilot.at_floor:
                proposal = pilot.setting / 16.0
            else:
                p = self._local_order(pilots, p_known, key=lambda x: x.setting)
                p = min(max(p, 0.5), max(16.0, p_known))
                proposal = pilot.setting * (pilot.error / (AIM * self.target)) ** (1.0 / p)
                if ok:
                    best = min(ok, key=lambda x: x.setting)
                    if not best.at_floor:
                        ideal = best.setting * (best.error / self.target) ** (1.0 / p)
                        if best.setting <= GOOD_ENOUGH * ideal:
                            break
            # stay inside the bracket (n_bad, n_ok)
            if proposal >= n_ok:
                proposal = math.sqrt(n_ok * max(n_bad, n_ok / 16.0))
            if proposal <= n_bad:
                proposal = math.sqrt(n_bad * min(n_ok, 16.0 * n_bad))
            proposal = max(proposal, 1.0)
            if self.P * proposal / self.S > MAX_PILOT_STEPS:
                note = (f"not pursued: a pilot would take more than {MAX_PILOT_STEPS:.0e} "
                        "steps")
                break
            per_step = step_work(self.base, method, options)
            if math.isfinite(self.best_work) and not ok and \
                    proposal * per_step > ABANDON * self.best_work:
                # abandoned on the prediction of two pilots (a measured order), or of one
                # when that is hopeless even by ABANDON^2; else the next pilot measures the
                # order at the bound itself
                if len(pilots) >= 2 or proposal * per_step > ABANDON ** 2 * self.best_work:
                    note = f"not pursued: predicted work more than {ABANDON:g}x the best"
                    break
                proposal = max(ABANDON * self.best_work / per_step, n_bad * 1.25, 1.0)
            if ok and n_bad and n_ok / n_bad < 1.1:
                break
            n = proposal
        return self._summary(cand, pilots, note, p_known, adaptive=False)

    def search_adaptive(self, cand):
        method, options, _ = cand
        p_known = _order(method, options)
        tol = 1e-9 if method == "ias15" else min(max(self.target * 1e-2, 1e-13), 1e-3)
        pilots = []
        note = ""
        while len(pilots) < MAX_PILOTS:
            pilot = self._adaptive_pilot(cand, tol)
            pilots.append(pilot)
            ok = [p for p in pilots if p.error <= self.target]
            tol_ok = max((p.setting for p in ok), default=0.0)
            bad = [p.setting for p in pilots if p.error > self.target and p.setting > tol_ok]
            tol_bad = min(bad, default=math.inf)
            if not math.isfinite(pilot.error):
                proposal = tol / 100.0
            elif pilot.at_floor:
                proposal = tol * 100.0
            else:
                a = self._local_order(pilots, 1.0, key=lambda x: 1.0 / x.setting)
                a = min(max(a, 0.3), 3.0)
                proposal = tol * (AIM * self.target / pilot.error) ** (1.0 / a)
                if ok:
                    best = max(ok, key=lambda x: x.setting)
                    ideal = best.setting * (self.target / max(best.error, _TINY)) ** (1.0 / a)
                    if ideal <= 3.0 * best.setting:
                        break
            if proposal <= tol_ok:
                proposal = math.sqrt(tol_ok * min(tol_bad, 100.0 * tol_ok))
            if proposal >= tol_bad:
                proposal = math.sqrt(tol_bad * max(tol_ok, tol_bad / 100.0))
            proposal = min(max(proposal, 1e-15), 1e-1)
            if any(abs(p.setting - proposal) <= 1e-9 * proposal for p in pilots):
                break
            if ok and tol_bad < math.inf and tol_bad / tol_ok < 1.5:
                break
            if math.isfinite(self.best_work) and not ok and \
                    pilot.work > ABANDON * self.best_work and proposal < tol:
                note = f"not pursued: predicted work more than {ABANDON:g}x the best"
                break
            tol = proposal
        return self._summary(cand, pilots, note, p_known, adaptive=True)

    def _summary(self, cand, pilots, note, p_known, adaptive):
        method, options, label = cand
        ok = [p for p in pilots if p.error <= self.target]
        rows = tuple((p.setting if adaptive else p.dt, p.error, p.pilot_steps) for p in pilots)
        seconds_per_step = None
        timed = [p for p in pilots if p.pilot_steps > 0 and p.seconds > 0.0]
        if timed:
            big = max(timed, key=lambda p: p.pilot_steps)
            seconds_per_step = big.seconds / big.pilot_steps
        if ok:
            best = min(ok, key=lambda p: p.work)
            verified = True
        else:
            finite = [p for p in pilots if math.isfinite(p.error)]
            if not finite:
                return Candidate(label, method, options, verified=False, pilots=rows,
                                 note=note or "every pilot blew up")
            last = min(finite, key=lambda p: p.error)
            # extrapolate the last pilot to the requested error with the method's order
            if adaptive:
                factor = (self.target * AIM / last.error)
                best = _Pilot(last.setting * factor, self.target * AIM, False,
                              last.steps * factor ** (-1.0 / (p_known + 1.0)),
                              last.work * factor ** (-1.0 / (p_known + 1.0)), 0.0, 0,
                              dt=last.dt)
            else:
                factor = (last.error / (self.target * AIM)) ** (1.0 / p_known)
                steps = math.ceil(last.steps * factor)
                best = _Pilot(last.setting * factor, self.target * AIM, False, steps,
                              last.work / last.steps * steps, 0.0, 0, dt=last.dt / factor)
            verified = False
            note = note or "predicted, not verified"
        seconds = best.steps * seconds_per_step if seconds_per_step else math.nan
        if adaptive:
            return Candidate(label, method, options, dt=best.dt, tolerance=best.setting,
                             steps=best.steps, error=best.error, work=best.work,
                             seconds=seconds, verified=verified, note=note, pilots=rows)
        return Candidate(label, method, options, dt=best.dt, steps=best.steps, error=best.error,
                         work=best.work, seconds=seconds, verified=verified, note=note,
                         pilots=rows)

    def run(self, chosen):
        by_label = {c[2]: c for c in chosen}
        order = [by_label[name] for name in SEARCH_ORDER if name in by_label]
        order += [c for c in chosen if c not in order]
        results = {}
        for cand in order:
            method, options, label = cand
            reason = self._warm(cand)
            if reason is not None:
                results[label] = Candidate(label, method, options, skipped=reason)
                continue
            if method in _integrators.ADAPTIVE_INTEGRATORS:
                result = self.search_adaptive(cand)
            else:
                result = self.search_fixed(cand)
            results[label] = result
            if result.verified:
                self.best_work = min(self.best_work, result.work)
        return tuple(results[c[2]] for c in chosen)


def advise(sim, t_end, error, metric="position", length=None, rank="work", methods=None):
    """The cheapest integrator and step that integrates ``sim`` to ``t_end`` within ``error``.

    Runs short pilot integrations of copies of ``sim`` (``sim`` itself is not changed) with
    every candidate method (``CANDIDATES``, or the ``methods`` named: integrator names or
    labels such as ``"whfast corrector=17"``), extrapolates their measured errors to ``t_end``
    and returns an ``Advice``: the recommended method, options, ``dt`` (``tolerance`` for
    ``rk45`` and ``ias15``), the predicted error, work and wall time, and every candidate's
    figures (or why it was skipped). See the module for the method.

    ``error``: the largest acceptable error at ``t_end`` (> 0), in ``metric``: ``"position"``
    (max_i |r_i - r_i^ref| / ``length``; ``length`` defaults to the scene's extent) or
    ``"energy"`` (|E - E0| / |E0|). ``rank``: ``"work"`` (deterministic: force evaluations
    times pairs, see ``run_work``) or ``"time"`` (measured wall time).
    """
    start = time.perf_counter()
    t_end, error, length = _check_inputs(sim, t_end, error, metric, length, rank)
    chosen = _select(methods)
    advisor = _Advisor(sim, t_end, error, metric, length)
    candidates = advisor.run(chosen)
    key = (lambda c: c.work) if rank == "work" else (lambda c: c.seconds)
    verified = [c for c in candidates if c.verified and math.isfinite(key(c))]
    notes = list(advisor.notes) + advisor.measure.notes
    if verified:
        best = min(verified, key=key)
        reached = True
    else:
        measured = [c for c in candidates if c.skipped is None and math.isfinite(c.error)]
        if not measured:
            raise SimulationError("advise: no candidate method could integrate this scene "
                                  "(every pilot blew up or was skipped)")
        best = min(measured, key=lambda c: (c.error, c.work))
        reached = False
        notes.append(f"no candidate verified error <= {error:g}; the recommendation is "
                     "extrapolated")
    adaptive = best.method in _integrators.ADAPTIVE_INTEGRATORS
    return Advice(method=best.method, options=dict(best.options), dt=best.dt,
                  tolerance=best.tolerance if adaptive else None, error=best.error,
                  work=best.work, seconds=best.seconds, steps=best.steps, reached=reached,
                  requested_error=error, t_end=t_end, span=t_end - sim.t, metric=metric,
                  length=advisor.length if metric == "position" else None, rank=rank,
                  time_scale=advisor.T, pilot_span=advisor.P, floor=advisor.floor,
                  candidates=candidates, advisor_seconds=time.perf_counter() - start,
                  advisor_work=advisor.work + advisor.measure.work, notes=tuple(notes))


def format_table(advice):
    """The candidates of ``advice`` as a text table, the recommendation marked ``*``."""
    lines = [
        f"span {advice.span:.6g} (t_end {advice.t_end:.6g}), requested {advice.metric} error "
        f"{advice.requested_error:.3g}" + (f" (length {advice.length:.4g})"
                                            if advice.length else ""),
        f"time scale {advice.time_scale:.4g}, pilot span {advice.pilot_span:.4g}, reference "
        f"floor {advice.floor:.2g}; advisor: {advice.advisor_seconds:.2f} s, work "
        f"{advice.advisor_work:.3g}",
        f"{'':1} {'method':22} {'dt / tolerance':>15} {'steps':>10} {'pred. error':>11} "
        f"{'work':>10} {'time [s]':>9}  note",
    ]
    for c in advice.candidates:
        mark = "*" if c.label == advice.label else " "
        if c.skipped:
            lines.append(f"{mark} {c.label:22} {'-':>15} {'-':>10} {'-':>11} {'-':>10} "
                         f"{'-':>9}  skipped: {c.skipped.splitlines()[0][:90]}")
            continue
        setting = c.setting
        setting = "-" if setting is None or not math.isfinite(setting) else f"{setting:.4g}"
        note = c.note if c.note else ("verified" if c.verified else "")
        lines.append(f"{mark} {c.label:22} {setting:>15} {c.steps:>10.4g} {c.error:>11.2e} "
                     f"{c.work:>10.3g} {c.seconds:>9.3g}  {note}")
    for n in advice.notes:
        lines.append(f"note: {n}")
    return "\n".join(lines)


__all__ = ["advise", "Advice", "Candidate", "CANDIDATES", "clone_simulation", "time_scale",
           "scene_length", "interactions", "step_work", "run_work", "growth", "label",
           "format_table"]
