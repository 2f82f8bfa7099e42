"""Simulation: particles + declared force terms + an integrator + time.

The friendly object around the compiled kernels. ``step(n)`` runs n steps inside one compiled
call; Python only runs between calls (checks, re-reading changed force parameters).
"""
import math
import numbers

import numpy as np

from . import diagnostics
from . import integrators as _integrators
from ._validate import MAX_STEPS, finite_float, nonnegative_float, positive_float, real_array, step_count
from .errors import SimulationError
from .forces.base import Force
from .forces.dispatch import pack, potential_terms
from .particles import Particles
from .units import UnitSystem, strip_without_units

_MAX_STEPS = MAX_STEPS


MAX_CAPACITY = 2 ** 31  # initial room beyond this is a mistake, not a plan (16 GiB of positions)


class Simulation:
    """A set of particles moved by declared force terms with a chosen integrator.

    Parameters
    ----------
    dim : 2 or 3
    integrator : one of ``engine.INTEGRATORS``
    dt : the (signed, non-zero) step; for ``rk45`` the first step, then adapted
    tolerance : error tolerance of ``rk45`` (relative and absolute), > 0
    units : ``None`` (code units, G = 1) or three astropy units of length, time and mass
    G : override the gravitational constant (default 1, or astropy's G in ``units``)
    capacity : initial room for particles (an int in [0, 2**31]; grows as needed)

    ``pos``, ``vel``, ``mass``, ``charge`` and ``radius`` are writable views of the state. A
    step first checks them: a non-finite value written there (or a negative mass or radius)
    raises ValueError naming the field and particle, and nothing is changed. Step counts are
    ints in ``[0, 2**62]``; a step that would take ``t`` past the largest float is refused.
    """

    def __init__(self, dim=2, integrator="symplectic_euler", dt=1.0, tolerance=1e-9,
                 units=None, G=None, capacity=16):
        if isinstance(dim, bool) or dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        self._units = None if units is None else UnitSystem(units)
        self._integrator = _integrators.check_name(integrator)
        self._dt = self._check_dt(dt)
        self._tolerance = positive_float("tolerance", tolerance)
        if G is None:
            self._G = self._units.G if self._units is not None else 1.0
        else:
            self._G = nonnegative_float("G", G)
        if isinstance(capacity, (bool, np.bool_)) or not isinstance(capacity, numbers.Integral):
            raise TypeError(f"capacity must be an int >= 0, got {capacity!r}")
        if not 0 <= capacity <= MAX_CAPACITY:
            raise ValueError(f"capacity must be an int in [0, {MAX_CAPACITY}], got {capacity!r}")
        self.dim = int(dim)
        self._particles = Particles(self.dim, int(capacity))
        self._forces = []
        self._model = None
        self._model_key = None
        # bumped by every add and remove of a force term: the packed model is keyed on it (a
        # key of the terms' id() would match a removed term's reused address)
        self._revision = 0
        self.t = 0.0
        self.steps = 0

    # -- configuration ---------------------------------------------------------------
    @property
    def integrator(self):
        return self._integrator

    @integrator.setter
    def integrator(self, name):
        self._integrator = _integrators.check_name(name)

    @property
    def dt(self):
        return self._dt

    @dt.setter
    def dt(self, value):
        self._dt = self._check_dt(value)

    def _check_dt(self, value):
        value = finite_float("dt", self._code(value, "time", "dt"))
        if value == 0.0:
            raise ValueError("dt must be non-zero (negative runs backwards), got 0.0")
        return value

    @property
    def tolerance(self):
        return self._tolerance

    @tolerance.setter
    def tolerance(self, value):
        self._tolerance = positive_float("tolerance", value)

    @property
    def G(self):
        return self._G

    @G.setter
    def G(self, value):
        self._G = nonnegative_float("G", self._code(value, "G", "G"))

    @property
    def units(self):
        """The UnitSystem, or None in plain code units."""
        return self._units

    @property
    def t(self):
        return self._t

    @t.setter
    def t(self, value):
        self._t = finite_float("t", self._code(value, "time", "t"))

    # -- particles -------------------------------------------------------------------
    @property
    def n(self):
        """Number of particle slots used (active or not)."""
        return self._particles.n

    def __len__(self):
        return self._particles.n

    @property
    def pos(self):
        """Positions, (N, dim): a writable view of the engine's state."""
        p = self._particles
        return p.pos[:, : p.n].T

    @property
    def vel(self):
        """Velocities, (N, dim): a writable view of the engine's state."""
        p = self._particles
        return p.vel[:, : p.n].T

    @property
    def mass(self):
        return self._particles.mass[: self.n]

    @property
    def charge(self):
        return self._particles.charge[: self.n]

    @property
    def radius(self):
        return self._particles.radius[: self.n]

    @property
    def active(self):
        """Read-only view of the active flags; change them with activate/deactivate."""
        view = self._particles.active[: self.n]
        view.flags.writeable = False
        return view

    @property
    def test(self):
        view = self._particles.test[: self.n]
        view.flags.writeable = False
        return view

    def add(self, mass=1.0, pos=None, vel=None, charge=0.0, radius=0.0, test=False):
        """Add one particle; return its index. Quantities are converted when units are set."""
        return int(self.add_many(mass=[self._code(mass, "mass", "mass")],
                                 pos=None if pos is None else [self._code(pos, "length", "pos")],
                                 vel=None if vel is None else [self._code(vel, "velocity", "vel")],
                                 charge=[charge], radius=[self._code(radius, "length", "radius")],
                                 test=[test], _single=True)[0])

    def add_many(self, mass, pos, vel=None, charge=0.0, radius=0.0, test=False, _single=False):
        """Add k particles from arrays (``pos``/``vel`` of shape (k, dim)); return their indices."""
        pos = self._code(pos, "length", "pos")
        vel = self._code(vel, "velocity", "vel")
        mass = self._code(mass, "mass", "mass")
        radius = self._code(radius, "length", "radius")
        if pos is None:
            pos = np.zeros((1, self.dim))
        p = self._rows("pos", pos, _single)
        k = p.shape[0]
        v = np.zeros((k, self.dim)) if vel is None else self._rows("vel", vel, _single)
        if v.shape[0] != k:
            raise ValueError(f"vel has {v.shape[0]} rows but pos has {k}")
        m = self._column("mass", mass, k, minimum=0.0, single=_single)
        q = self._column("charge", charge, k, single=_single)
        r = self._column("radius", radius, k, minimum=0.0, single=_single)
        try:
            tst = np.broadcast_to(np.asarray(test), (k,))
        except ValueError:
            raise ValueError(f"test must be True or False (or one per particle), got {test!r}") from None
        if tst.dtype != np.bool_:
            raise TypeError(f"test must be True or False, got {test!r}")
        return self._particles.append(p, v, m, q, r, tst)

    def _rows(self, field, value, single):
        arr = real_array(field, value, "numbers")
        shown = value[0] if single else value
        if arr.ndim != 2 or arr.shape[1] != self.dim:
            got = arr.shape[-1] if arr.ndim >= 1 else "a scalar"
            raise ValueError(f"{field} must have length {self.dim} (dim={self.dim}), "
                             f"got {got if single else arr.shape} ({shown!r})")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{field} must be finite, got {shown!r}")
        return arr

    def _column(self, field, value, k, minimum=None, single=False):
        arr = real_array(field, value, "a number")
        arr = np.broadcast_to(arr, (k,)) if arr.ndim <= 1 else arr
        if arr.shape != (k,):
            raise ValueError(f"{field} must be a scalar or have length {k}, got shape {arr.shape}")
        bad = ~np.isfinite(arr)
        if minimum is not None:
            bad |= arr < minimum
        if np.any(bad):
            val = arr[bad][0]
            rule = "finite" if minimum is None else f"finite and >= {minimum}"
            where = "" if single else f" (particle {int(np.flatnonzero(bad)[0])} of the batch)"
            raise ValueError(f"{field} must be {rule}, got {val!r}{where}")
        return arr

    def _index(self, i):
        if isinstance(i, bool) or not isinstance(i, numbers.Integral) or not 0 <= i < self.n:
            raise ValueError(f"particle index must be an int in [0, {self.n}), got {i!r}")
        return int(i)

    def deactivate(self, i):
        """Remove particle ``i`` from the dynamics (frozen, feels and exerts nothing)."""
        self._particles.active[self._index(i)] = False

    def activate(self, i):
        self._particles.active[self._index(i)] = True

    # -- forces ----------------------------------------------------------------------
    @property
    def forces(self):
        return tuple(self._forces)

    def add_force(self, force):
        """Declare a force term; it acts from the next step. Returns the term."""
        if not isinstance(force, Force):
            raise TypeError(f"force must be an engine.forces term, got {force!r}")
        if any(f is force for f in self._forces):
            raise ValueError(f"{force!r} is already declared in this simulation")
        force._attach(self)
        self._forces.append(force)
        self._revision += 1
        return force

    def remove_force(self, force):
        for k, f in enumerate(self._forces):
            if f is force:
                del self._forces[k]
                force._sim = None
                self._revision += 1
                return
        raise ValueError(f"{force!r} is not declared in this simulation")

    def _current_model(self):
        key = (self._G, self._revision) + tuple(f._version for f in self._forces)
        if key != self._model_key:
            self._model = pack(self._forces, self)
            self._model_key = key
        return self._model

    def _kernel_state(self):
        p = self._particles
        return p.pos, p.vel, p.kernel_args(), p.n, self._current_model()

    # -- time ------------------------------------------------------------------------
    def step(self, n=1):
        """Advance ``n`` steps in one compiled call (``n`` accepted steps for rk45).

        ``n`` is an int in ``[0, 2**62]`` (bools and floats are refused).
        """
        n = step_count("n", n)
        if n:
            self._run(self._dt, n, math.nan)

    def integrate(self, t_end):
        """Advance to exactly ``t_end`` (forwards or backwards).

        Fixed-step methods take whole steps of |dt| towards ``t_end`` and one shorter last
        step; rk45 shortens its last adaptive step. ``sim.t == t_end`` afterwards.
        ``t_end`` must be finite and (fixed-step methods) reachable in at most 2**62 steps.
        """
        t_end = finite_float("t_end", self._code(t_end, "time", "t_end"))
        remaining = t_end - self._t
        if remaining == 0.0:
            return
        if not math.isfinite(remaining):
            raise ValueError(f"t_end={t_end!r} is too far from t={self._t!r}: the interval "
                             "overflows a float")
        h = math.copysign(abs(self._dt), remaining)
        needed = abs(remaining) / abs(h)
        if self._integrator != "rk45" and not needed <= _MAX_STEPS:
            raise ValueError(f"t_end={t_end!r} needs {needed:.3g} steps of dt={self._dt!r} from "
                             f"t={self._t!r}, more than the 2**62 one call can take; use a "
                             "larger dt or a nearer t_end")
        if self._integrator == "rk45":
            self._run(h, _MAX_STEPS, t_end)
            return
        t0 = self._t
        full = int(abs(remaining) // abs(h))
        if full and (t0 + full * h - t_end) * h > 0.0:
            full -= 1  # round-off would overshoot
        if full:
            self._run(h, full, math.nan, keep_dt=True)
        last = t_end - self._t
        if abs(last) > 4.0 * np.finfo(float).eps * max(abs(t_end), abs(self._t)):
            self._run(last, 1, math.nan, keep_dt=True)
        self._t = t_end

    def _run(self, h, steps, t_end, keep_dt=False):
        if self._integrator != "rk45" and not math.isfinite(self._t + steps * h):
            raise ValueError(f"{steps} steps of {h!r} from t={self._t!r} take the time past the "
                             "largest float (t would not be finite); nothing was changed")
        pos, vel, prm, n, model = self._kernel_state()
        self._check_state(pos, vel, prm, n)
        vdep = any(f.velocity_dependent for f in self._forces)
        t, h_next, done, bad = _integrators.advance(
            self._integrator, self._t, h, steps, pos, vel, prm, n, model, vdep, t_end,
            self._tolerance)
        failed_step = self.steps + done
        self._t = t
        self.steps += done
        if (self._integrator == "rk45" and not keep_dt and bad < 0
                and bad != _integrators.common.TIME_OVERFLOW):
            self._dt = h_next
        if bad >= 0:
            raise SimulationError(
                f"step {failed_step} from t={t!r} with {self._integrator} gave particle {bad} a "
                "non-finite position or velocity (singular force, or dt too large for a stiff "
                "force); the last finite state is kept",
                step=failed_step, time=t, particle=int(bad))
        if bad == _integrators.common.TIME_OVERFLOW:
            raise SimulationError(
                f"rk45 step {failed_step} from t={t!r} with step {h_next!r} would take the time "
                "past the largest float (t would not be finite); the last finite state is kept",
                step=failed_step, time=t, particle=None)
        if bad == _integrators.common.STEP_COLLAPSED:
            raise SimulationError(
                f"rk45 step size collapsed at step {failed_step}, t={t!r} (tolerance "
                f"{self._tolerance!r} cannot be met); the last accepted state is kept",
                step=failed_step, time=t, particle=None)

    def _check_state(self, pos, vel, prm, n):
        """Refuse to step from a state the user made invalid by writing the arrays directly.

        ``sim.pos``, ``vel``, ``mass``, ``charge`` and ``radius`` are writable views: a
        non-finite value written there is bad input of that field (ValueError naming it, state
        unchanged), never reported as a numerical blow-up of the step.
        """
        if not (np.isfinite(pos[:, :n]).all() and np.isfinite(vel[:, :n]).all()):
            bad = np.flatnonzero(~(np.isfinite(pos[:, :n]).all(0) & np.isfinite(vel[:, :n]).all(0)))
            i = int(bad[0])
            field = "pos" if not np.isfinite(pos[:, i]).all() else "vel"
            raise ValueError(f"particle {i} has a non-finite pos or vel: {field}[{i}] = "
                             f"{(pos if field == 'pos' else vel)[:, i]} was written with a "
                             "non-finite value (bad input); nothing was changed")
        mass, charge, radius = prm[0], prm[1], prm[2]
        for field, arr, minimum in (("mass", mass, 0.0), ("charge", charge, None),
                                    ("radius", radius, 0.0)):
            values = arr[:n]
            bad = ~np.isfinite(values)
            if minimum is not None:
                bad |= values < minimum
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                rule = "finite" if minimum is None else f"finite and >= {minimum}"
                raise ValueError(f"{field}[{i}] must be {rule}, got {float(values[i])!r} (written into "
                                 f"sim.{field} directly: bad input, not a blow-up); nothing was "
                                 "changed")

    # -- diagnostics -----------------------------------------------------------------
    def kinetic_energy(self):
        p = self._particles
        return diagnostics.kinetic_energy(p.vel, p.mass, p.active, p.n)

    def potential_energy_terms(self):
        """Potential energy of each declared term, in declaration order."""
        pos, vel, prm, n, model = self._kernel_state()
        out = np.zeros(len(self._forces))
        potential_terms(self._t, pos, vel, *prm, n, *model, out)
        return out

    def potential_energy(self):
        """Sum of the potentials of the declared conservative terms."""
        return float(self.potential_energy_terms().sum())

    def energy(self):
        return self.kinetic_energy() + self.potential_energy()

    def momentum(self):
        p = self._particles
        return diagnostics.momentum(p.vel, p.mass, p.active, p.n)

    def angular_momentum(self):
        """About the origin: a 3-vector in 3-D, the scalar L_z in 2-D."""
        p = self._particles
        L = diagnostics.angular_momentum(p.pos, p.vel, p.mass, p.active, p.n)
        return float(L[0]) if self.dim == 2 else L

    def center_of_mass(self):
        p = self._particles
        return diagnostics.center_of_mass(p.pos, p.vel, p.mass, p.active, p.n)

    # -- units -----------------------------------------------------------------------
    def _code(self, value, kind, field):
        if value is None:
            return None
        if self._units is None:
            return strip_without_units(value, field)
        return self._units.to_code(value, kind, field)

    def quantity(self, value, kind):
        """Turn a code-unit value (e.g. ``sim.pos``) into an astropy Quantity of ``kind``."""
        if self._units is None:
            raise ValueError("the simulation has no units; create it with units=(length, time, mass)")
        return self._units.to_quantity(value, kind)

    def __repr__(self):
        return (f"Simulation(dim={self.dim}, integrator={self._integrator!r}, dt={self._dt!r}, "
                f"n={self.n}, t={self._t!r}, forces={self._forces!r})")


__all__ = ["Simulation"]
