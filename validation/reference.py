"""Reference solutions: REBOUND runs of the same problems, and closed forms.

- ``RebRun``: a REBOUND simulation of a ``Problem`` (gravity problems only). A fixed attractor
  (``PointMass``) becomes a central body of mass mu/G with the problem's particles massless, so
  the centre never moves, as in the engine. REBOUND is never asked to move anything to the
  centre of mass: both codes start from the same coordinates.
- ``reference_states``: the high-accuracy solution a problem is measured against: the
  universal-variable Kepler solution (``engine.analytic.kepler``), REBOUND IAS15 at a tight
  epsilon, normal modes for the linear spring chain, or engine ``rk45`` at tolerance 1e-14.
- ``reference_uncertainty``: how far the reference is from an independent second solution,
  i.e. the floor below which an error cannot be measured.
"""
import math
import warnings

import numpy as np

from engine import analytic

from .problems import make_sim, stiffness_matrix

#: IAS15 epsilon of the gravity references, and the one they are checked against
IAS15_REFERENCE_EPSILON = 1e-11
IAS15_CHECK_EPSILON = 1e-13
#: rk45 tolerance of the references of non-gravity problems, and the check
RK45_REFERENCE_TOLERANCE = 1e-14
RK45_CHECK_TOLERANCE = 1e-13


def rebound_available():
    try:
        import rebound  # noqa: F401
    except ImportError:
        return False
    return True


def rebound_version():
    import rebound
    return rebound.__version__


class RebRun:
    """A REBOUND simulation of a problem; states are returned in the problem's coordinates."""

    def __init__(self, problem, integrator, dt=None, epsilon=None, count_evaluations=False,
                 max_evaluations=None, options=None):
        """``options``: attributes of REBOUND's integrator to set (``corrector``, ``type``,
        ``safe_mode``, ...). With ``safe_mode = 0`` every ``steps``/``integrate`` call ends
        with ``sim.synchronize()``, so the state read afterwards is the synchronised one."""
        import rebound

        kinds = [kind for kind, _ in problem.forces]
        params = [p for _, p in problem.forces]
        if kinds == ["point_mass"]:
            mu = params[0].get("mu", 1.0)
            centre = params[0].get("pos", (0.0,) * problem.dim)
            if any(centre) or params[0].get("softening", 0.0):
                raise ValueError("only an unsoftened attractor at the origin maps onto REBOUND")
            self.offset = 1
            source_mass = np.zeros(problem.n)
        elif kinds == ["nbody"]:
            if params[0].get("softening", 0.0):
                raise ValueError("softened gravity is not compared with REBOUND")
            self.offset = 0
            source_mass = problem.mass
            mu = None
        else:
            raise ValueError(f"{problem.key}: REBOUND runs need pure gravity, got {kinds}")
        self.problem = problem
        self.mu = mu
        sim = rebound.Simulation()
        sim.G = problem.G
        if self.offset:
            sim.add(m=mu / problem.G)
        for i in range(problem.n):
            p = np.zeros(3)
            v = np.zeros(3)
            p[:problem.dim] = problem.pos[i]
            v[:problem.dim] = problem.vel[i]
            sim.add(m=float(source_mass[i]), x=p[0], y=p[1], z=p[2], vx=v[0], vy=v[1], vz=v[2])
        if self.offset:
            sim.N_active = 1  # the problem's particles are test particles: no O(N^2) sum
        sim.integrator = integrator
        self.options = dict(options or {})
        for name, value in self.options.items():
            setattr(sim.integrator, name, value)
        self._synchronize = self.options.get("safe_mode", 1) == 0
        if dt is not None:
            sim.dt = dt
        if epsilon is not None:
            sim.integrator.epsilon = epsilon
        self.evaluations = 0
        self.warnings = []
        self.stopped = False
        if count_evaluations:
            def count(sim_pointer):
                self.evaluations += 1
                if max_evaluations is not None and self.evaluations > max_evaluations:
                    # e.g. IAS15 at a loose epsilon on the Pythagorean problem makes a spurious
                    # tight binary and then needs steps of 1e-8: stop instead of running for hours
                    self.stopped = True
                    sim_pointer.contents.stop()
            self._callback = count
            sim.additional_forces = count
            sim.force_is_velocity_dependent = 0
        self.sim = sim
        self._xyz = np.zeros((sim.N, 3))
        self._v = np.zeros((sim.N, 3))

    @property
    def t(self):
        return self.sim.t

    def integrate(self, t, exact=True):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            self.sim.integrate(t, exact_finish_time=1 if exact else 0)
            if self._synchronize:
                self.sim.synchronize()
        self._note(caught)

    def steps(self, n):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            self.sim.steps(int(n))
            if self._synchronize:
                self.sim.synchronize()
        self._note(caught)

    def _note(self, caught):
        """Keep REBOUND's warnings (e.g. IAS15 not converging at a coarse epsilon) as data."""
        for w in caught:
            msg = str(w.message).strip()
            if msg not in self.warnings:
                self.warnings.append(msg)

    def state(self):
        """(pos, vel) of the problem's particles, shape (N, dim)."""
        self.sim.serialize_particle_data(xyz=self._xyz, vxvyvz=self._v)
        d = self.problem.dim
        o = self.offset
        return self._xyz[o:, :d].copy(), self._v[o:, :d].copy()

    def energy(self):
        """Total energy with the engine's definition (the massless particles' own masses for a
        fixed attractor; REBOUND's sim.energy() for mutual gravity)."""
        if not self.offset:
            return self.sim.energy()
        self.sim.serialize_particle_data(xyz=self._xyz, vxvyvz=self._v)
        r = self._xyz[1:] - self._xyz[0]
        v = self._v[1:] - self._v[0]
        m = self.problem.mass
        kinetic = 0.5 * np.sum(v * v, axis=1)
        potential = -self.mu / np.sqrt(np.sum(r * r, axis=1))
        return float(np.sum(m * (kinetic + potential)))


def kepler_states(problem, times):
    """Closed-form states of a fixed-attractor problem at ``times``: list of (pos, vel)."""
    mu = problem.forces[0][1].get("mu", 1.0)
    out = []
    for t in times:
        pos = np.empty_like(problem.pos)
        vel = np.empty_like(problem.vel)
        for i in range(problem.n):
            pos[i], vel[i] = analytic.kepler(problem.pos[i], problem.vel[i], mu, float(t))
        out.append((pos, vel))
    return out


def chain_states(problem, times):
    """Exact states of the linear 1-D spring chain from its normal modes.

    Displacements u from the rest configuration (x_i = i, every spring at its rest length)
    obey u'' = -K u; with K = Q diag(omega^2) Q^T each mode is a harmonic oscillator (the
    translation mode, omega = 0, moves uniformly).
    """
    params = problem.forces[0][1]
    k = np.asarray(params["k"], dtype=np.float64)
    rest = params["rest_length"]
    m = problem.mass
    x_rest = rest * np.arange(problem.n)
    w = np.sqrt(m)
    lam, Q = np.linalg.eigh(stiffness_matrix(k, m))
    omega = np.sqrt(np.clip(lam, 0.0, None))
    a0 = Q.T @ ((problem.pos[:, 0] - x_rest) * w)
    b0 = Q.T @ (problem.vel[:, 0] * w)
    out = []
    for t in times:
        c = np.cos(omega * t)
        # sin(omega t)/omega, continuous at omega = 0
        s_over = t * np.sinc(omega * t / math.pi)
        s = np.sin(omega * t)
        a = a0 * c + b0 * s_over
        adot = -a0 * omega * s + b0 * c
        u = (Q @ a) / w
        udot = (Q @ adot) / w
        pos = np.zeros_like(problem.pos)
        vel = np.zeros_like(problem.vel)
        pos[:, 0] = x_rest + u
        pos[:, 1] = problem.pos[:, 1]
        vel[:, 0] = udot
        out.append((pos, vel))
    return out


def ias15_states(problem, times, epsilon=IAS15_REFERENCE_EPSILON):
    run = RebRun(problem, "ias15", epsilon=epsilon)
    out = []
    for t in times:
        run.integrate(float(t))
        out.append(run.state())
    return out


def rk45_states(problem, times, tolerance=RK45_REFERENCE_TOLERANCE, integrator="rk45", dt=1e-3):
    sim = make_sim(problem, integrator, dt, tolerance=tolerance)
    out = []
    for t in times:
        sim.integrate(float(t))
        out.append((sim.pos.copy(), sim.vel.copy()))
    return out


def reference_states(problem, times):
    """The reference solution of ``problem`` at ``times`` (list of (pos, vel))."""
    if problem.reference == "kepler":
        return kepler_states(problem, times)
    if problem.reference == "modes":
        return chain_states(problem, times)
    if problem.reference == "ias15":
        return ias15_states(problem, times)
    if problem.reference == "rk45":
        return rk45_states(problem, times)
    raise ValueError(problem.reference)


def position_error(pos, ref_pos, length):
    """max_i |r_i - r_i^ref| / L."""
    with np.errstate(over="ignore", invalid="ignore"):
        return float(np.max(np.linalg.norm(pos - ref_pos, axis=1)) / length)


def reference_uncertainty(problem, t):
    """How well the reference is known at ``t``: differences to independent solutions.

    Returns ``{"checks": {name: error}, "floor": largest, "reference": description}`` with
    errors normalised like the work-precision errors (max_i |dr_i| / L).
    """
    ref = reference_states(problem, [t])[0][0]
    checks = {}
    if problem.reference == "kepler":
        desc = "engine.analytic.kepler (universal variables)"
        checks[f"REBOUND IAS15 eps={IAS15_REFERENCE_EPSILON:g}"] = ias15_states(problem, [t])[0][0]
    elif problem.reference == "ias15":
        desc = f"REBOUND IAS15, epsilon = {IAS15_REFERENCE_EPSILON:g}"
        checks[f"REBOUND IAS15 eps={IAS15_CHECK_EPSILON:g}"] = ias15_states(
            problem, [t], epsilon=IAS15_CHECK_EPSILON)[0][0]
        checks["REBOUND IAS15 eps=1e-9 (default)"] = ias15_states(problem, [t], epsilon=1e-9)[0][0]
        checks[f"engine rk45 tol={RK45_REFERENCE_TOLERANCE:g}"] = rk45_states(problem, [t])[0][0]
    elif problem.reference == "modes":
        desc = "normal modes of the linear chain (numpy eigh)"
        checks[f"engine rk45 tol={RK45_REFERENCE_TOLERANCE:g}"] = rk45_states(problem, [t])[0][0]
    else:
        desc = f"engine rk45, tolerance = {RK45_REFERENCE_TOLERANCE:g}"
        checks[f"engine rk45 tol={RK45_CHECK_TOLERANCE:g}"] = rk45_states(
            problem, [t], tolerance=RK45_CHECK_TOLERANCE)[0][0]
        checks["engine pefrl dt=1e-4"] = rk45_states(problem, [t], integrator="pefrl",
                                                     dt=1e-4)[0][0]
    errors = {name: position_error(p, ref, problem.length) for name, p in checks.items()}
    if problem.reference == "ias15":
        # IAS15 is the best solution at hand: its floor is how much it moves when epsilon
        # changes; the engine rk45 check is independent but itself less accurate.
        floor = max(v for k, v in errors.items() if "IAS15" in k)
    else:
        floor = max(errors.values())
    return {"reference": desc, "checks": errors, "floor": floor}
