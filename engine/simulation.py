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
from .collisions.settings import DeclaresCollisions
from .errors import Collision, SimulationError
from .forces.base import DeclaresTerms
from .forces import tree_terms
from .forces.dispatch import accelerations as _accelerations, pack, potential_terms
from .forces.pairwise import workspace as _pair_workspace
from .forces.springs import Springs
from .integrators import direct
from .integrators import ias15 as _ias15
from .integrators import janus as _janus
from .integrators import wisdom_holman
from .particles import Particles
from .space import check_box
from .state import INVALID_FIELDS, first_invalid
from .units import Readouts, UnitSystem, strip_without_units

_MAX_STEPS = MAX_STEPS


MAX_CAPACITY = 2 ** 31  # initial room beyond this is a mistake, not a plan (16 GiB of positions)


class Simulation(DeclaresTerms, DeclaresCollisions):
    """A set of particles moved by declared force terms with a chosen integrator.

    Parameters
    ----------
    dim : 2 or 3
    integrator : one of ``engine.INTEGRATORS``
    dt : the (signed, non-zero) step; for the adaptive ``rk45`` and ``ias15`` the first step,
        then adapted
    tolerance : error tolerance of ``rk45`` (relative and absolute), and ``ias15``'s epsilon
        (its step criterion's precision parameter; 1e-9 is REBOUND's default), > 0
    units : ``None`` (code units, G = 1) or three astropy units of length, time and mass
    G : override the gravitational constant (default 1, or astropy's G in ``units``)
    capacity : initial room for particles (an int in [0, 2**31]; grows as needed)
    box : side L of a periodic space, the torus [-L/2, L/2)^dim (``None``: open space). The
        drift wraps positions onto it and every pair force and collision takes separations
        by the nearest image (``engine.space``).
    corrector : ``whfast``'s symplectic corrector order, one of
        ``engine.integrators.wisdom_holman.CORRECTORS`` (0: none; 3, 5, 7, 11, 17)
    kernel : ``whfast``'s kernel, ``"standard"`` or ``"lazy"`` (the lazy implementer's
        modified kick, one more force evaluation per step)
    saba : the ``saba`` integrator's method: ``"SABA1"`` to ``"SABA4"``, ``"SABAC1"`` to
        ``"SABAC4"`` (with the lazy corrector), ``"SABA(10,4)"``, ``"SABA(8,6,4)"``,
        ``"SABA(10,6,4)"`` (the default)
    janus_order : ``janus``'s order, 2, 4, 6 (the default) or 8
    coordinates : ``whfast``'s coordinates for an ``NBodyGravity`` scene with a dominant mass:
        ``"jacobi"`` (the default; every corrector and kernel) or
        ``"democratic_heliocentric"`` (heliocentric positions, barycentric velocities: no
        ordering of the bodies by distance needed, as for close encounters between planets;
        standard kernel, no corrector)

    ``pos``, ``vel``, ``mass``, ``charge`` and ``radius`` are writable views of the state. A
    step first checks them: a non-finite value written there (or a negative mass or radius)
    raises ValueError naming the field and particle, and nothing is changed. Step counts are
    ints in ``[0, 2**62]``; a step that would take ``t`` past the largest float is refused.
    """

    def __init__(self, dim=2, integrator="symplectic_euler", dt=1.0, tolerance=1e-9,
                 units=None, G=None, capacity=16, box=None, corrector=0, kernel="standard",
                 saba=wisdom_holman.DEFAULT_SABA, janus_order=6, coordinates="jacobi"):
        if isinstance(dim, bool) or dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        self._coordinates = _check_coordinates(coordinates)
        self._corrector = _check_corrector(corrector)
        self._kernel = _check_kernel(kernel)
        self._saba = _check_saba(saba)
        self._janus_order = _check_janus_order(janus_order)
        self._ias15_memory = None  # the predictor's coefficients, kept between calls
        self._janus_lattice = None  # (kx, kv), chosen at the first janus step
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
        self._box = check_box(self._code(box, "length", "box"))
        self.dim = int(dim)
        self._particles = Particles(self.dim, int(capacity))
        self._forces = []
        self._model = None
        self._model_key = None
        self._work = None  # the tree's workspace, kept while the particle count allows
        self._velocity_dependent = False  # of the packed terms, found when they are packed
        self._plan = None  # whfast's and saba's plan of the scene, and what it was made from
        self._plan_key = None
        self._plan_model = None
        # bumped by every add and remove of a force term: the packed model is keyed on it (a
        # key of the terms' id() would match a removed term's reused address)
        self._revision = 0
        self._collisions = None  # engine.Collisions, or None: nothing touches
        self._plastic, self._plastic_key = [], None
        self._contacts = ()
        #: the energy contacts took out (inelastic bounces, merges) since the simulation began:
        #: ``sim.energy() + sim.energy_ledger`` is what contacts leave unchanged
        self.energy_ledger = 0.0
        self.t = 0.0
        self.steps = 0
        #: force evaluations made so far: counted by rk45 (rejected attempts included) and
        #: ias15 (every predictor-corrector iteration); the table
        #: ``engine.integrators.FORCE_EVALUATIONS`` times the steps for the other methods
        self.force_evaluations = 0

    # -- configuration ---------------------------------------------------------------
    @property
    def integrator(self):
        return self._integrator

    @integrator.setter
    def integrator(self, name):
        self._integrator = _integrators.check_name(name)

    @property
    def contacts(self):
        """The contacts resolved by the last ``step``/``integrate`` call, in the order they
        happened: a tuple of ``engine.Contact`` (time, i, j, speed, action, energy,
        survivor)."""
        return self._contacts

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
    def corrector(self):
        """``whfast``'s symplectic corrector order (0: none)."""
        return self._corrector

    @corrector.setter
    def corrector(self, value):
        self._corrector = _check_corrector(value)

    @property
    def coordinates(self):
        """``whfast``'s coordinates: ``"jacobi"`` or ``"democratic_heliocentric"``."""
        return self._coordinates

    @coordinates.setter
    def coordinates(self, value):
        self._coordinates = _check_coordinates(value)

    @property
    def kernel(self):
        """``whfast``'s kernel: ``"standard"`` or ``"lazy"``."""
        return self._kernel

    @kernel.setter
    def kernel(self, value):
        self._kernel = _check_kernel(value)

    @property
    def janus_order(self):
        """``janus``'s order (2, 4, 6 or 8)."""
        return self._janus_order

    @janus_order.setter
    def janus_order(self, value):
        self._janus_order = _check_janus_order(value)

    @property
    def janus_lattice(self):
        """``janus``'s lattice exponents ``(kx, kv)``: positions are whole multiples of
        2**-kx and velocities of 2**-kv (None until the first janus step chooses them with
        ``engine.integrators.janus.lattice_exponents``; they are then kept, so that a run
        with ``-dt`` retraces it bit for bit). Set them, or set None to choose again."""
        return self._janus_lattice

    @janus_lattice.setter
    def janus_lattice(self, value):
        if value is None:
            self._janus_lattice = None
            return
        try:
            kx, kv = value
        except (TypeError, ValueError):
            raise ValueError(f"janus_lattice must be None or two ints (kx, kv), got {value!r}")
        for name, k in (("kx", kx), ("kv", kv)):
            if isinstance(k, bool) or not isinstance(k, numbers.Integral) or \
                    abs(k) > _janus.MAX_EXPONENT:
                raise ValueError(f"janus_lattice {name} must be an int in "
                                 f"[-{_janus.MAX_EXPONENT}, {_janus.MAX_EXPONENT}], got {k!r}")
        self._janus_lattice = (int(kx), int(kv))

    @property
    def saba(self):
        """The ``saba`` integrator's method (``engine.integrators.wisdom_holman.SABA_METHODS``)."""
        return self._saba

    @saba.setter
    def saba(self, value):
        self._saba = _check_saba(value)

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
    def box(self):
        """Side of the periodic space (0.0 in open space)."""
        return self._box

    @box.setter
    def box(self, value):
        box = check_box(self._code(value, "length", "box"))
        old = self._box
        self._box = box
        try:
            for term in self._forces:  # a term that cannot act in the new space refuses it
                term._check(self)
        except ValueError:
            self._box = old
            raise
        self._revision += 1

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

    @property
    def time(self):
        """The time as an astropy Quantity in the simulation's units (the float ``t`` without),
        so that ``sim.integrate(sim.time + 5 * u.yr)`` reads as it should; settable like ``t``."""
        return self._t if self._units is None else self._units.to_quantity(self._t, "time")

    @time.setter
    def time(self, value):
        self._t = finite_float("time", self._code(value, "time", "time"))

    @property
    def quantities(self):
        """Every read-out as an astropy Quantity in the simulation's units: ``time``, ``dt``,
        ``G``, ``box``, ``pos``, ``vel``, ``mass``, ``energy``, ``kinetic_energy``,
        ``potential_energy``, ``momentum``, ``angular_momentum``, ``center_of_mass``
        (``engine.units.Readouts``). A simulation without units has none to give."""
        if self._units is None:
            raise ValueError("the simulation has no units, so its read-outs are plain code-unit "
                             "floats; create it with Simulation(units=(length, time, mass)) "
                             "to read them as Quantities")
        return Readouts(self, self._units)

    # -- particles -------------------------------------------------------------------
    @property
    def n(self):
        """Number of particle slots used (active or not)."""
        return self._particles.n

    def __len__(self):
        return self._particles.n

    @property
    def capacity(self):
        """Particle slots allocated (grows by doubling as particles are added)."""
        return self._particles.capacity

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

    @property
    def pinned(self):
        """Read-only view of the pinned flags; change them with pin/unpin."""
        view = self._particles.pinned[: self.n]
        view.flags.writeable = False
        return view

    def add(self, mass=1.0, pos=None, vel=None, charge=0.0, radius=0.0, test=False, pinned=False):
        """Add one particle; return its index. Quantities are converted when units are set.

        ``pinned=True``: the particle stays where it is whatever acts on it (see ``pin``)."""
        return int(self.add_many(mass=[self._code(mass, "mass", "mass")],
                                 pos=None if pos is None else [self._code(pos, "length", "pos")],
                                 vel=None if vel is None else [self._code(vel, "velocity", "vel")],
                                 charge=[charge], radius=[self._code(radius, "length", "radius")],
                                 test=[test], pinned=[pinned], _single=True)[0])

    def add_many(self, mass, pos, vel=None, charge=0.0, radius=0.0, test=False, pinned=False,
                 _single=False):
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
        tst = _flags("test", test, k)
        pin = _flags("pinned", pinned, k)
        return self._particles.append(p, v, m, q, r, tst, pin)

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
        invalid = ~np.isfinite(arr)
        if minimum is not None:
            invalid |= arr < minimum
        if np.any(invalid):
            val = arr[invalid][0]
            rule = "finite" if minimum is None else f"finite and >= {minimum}"
            where = "" if single else f" (particle {int(np.flatnonzero(invalid)[0])} of the batch)"
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

    def pin(self, i):
        """Hold particle ``i`` where it is: its velocity becomes zero and no force moves it,
        while it still exerts its own forces (a rope's anchor, a cloth's corner).

        In the diagnostics a pinned particle is immovable, an external body like a
        ``PointMass``: it has no kinetic energy and is left out of the momentum, the angular
        momentum and the centre of mass; the potential energy keeps its interactions. So the
        momentum of the rest is not conserved while it pulls on them (the pin holds it)."""
        i = self._index(i)
        self._particles.pinned[i] = True
        self._particles.vel[:, i] = 0.0

    def unpin(self, i):
        """Let particle ``i`` move again (from rest)."""
        self._particles.pinned[self._index(i)] = False

    # -- forces ----------------------------------------------------------------------
    def _current_model(self):
        # the particle count too: "auto" terms choose their method from it
        key = (self._G, self._revision, self.n, *[f._version for f in self._forces])
        if key != self._model_key:
            self._model = pack(self._forces, self)
            # a term's velocity dependence follows its parameters, so it changes only with them
            self._velocity_dependent = any(f.velocity_dependent for f in self._forces)
            self._model_key = key
        return self._model

    def _tree_terms(self):
        """The declared terms that evaluate by the tree at this particle count."""
        return [f for f in self._forces if tree_terms.uses_tree(f, self.n)]

    def _workspace(self, state):
        """The workspace a step passes to the force kernels: for a scene with tree terms, the
        tree's (``engine.tree.layout``), made once and again only when the particle count
        grows past it; otherwise None (each call makes the small one it needs)."""
        if not self._tree_terms():
            return None
        from .tree import layout
        if self._work is None or not layout.fits(state.n, self._work):
            self._work = layout.workspace(max(state.n, 1))
        return self._work

    def accelerations(self):
        """The accelerations the declared terms give at the current state and time: a new
        ``(n, dim)`` array (code units); nothing is advanced. What a force model is checked
        with (against a direct sum, a closed form, another code)."""
        state, model = self.kernel_arguments()
        self._check_state(state)
        work = self._workspace(state)
        if work is None:
            work = _pair_workspace(state.n)
        acc = np.zeros((self.dim, state.n))
        _accelerations(self._t, state, model, acc, work)
        return acc.T.copy()

    def parameter(self, term, name):
        """The packed values of ``term``'s float parameter ``name`` (a copy, shaped as the
        term's ``LAYOUT`` declares: ``sim.parameter(star, "pos")`` is the attractor's
        position), as the compiled kernels see them at the next step."""
        model = self._current_model()
        cols, shape = self._term_slot(model, term, name)
        return model.params[cols].reshape(shape).copy()

    def kernel_arguments(self):
        """``(state, model)``: this simulation as the ``engine.state`` named tuples the compiled
        kernels take (views of its arrays, and its packed force terms), for compiled code of
        your own: ``engine.forces.dispatch.accelerations(sim.t, state, model, acc, work)``."""
        return self._particles.state(self._box), self._current_model()

    def kepler_plan(self):
        """whfast's or saba's plan for this simulation as it is now (the split of its force terms
        into Kepler drifts and kicks, ``engine.integrators.wisdom_holman.plan``), to pass as
        ``plan=`` to ``engine.integrators.advance`` with ``kernel_arguments()``."""
        if self._integrator not in ("whfast", "saba"):
            raise ValueError(f"kepler_plan: integrator is {self._integrator!r}; "
                             "a plan is made for 'whfast' and 'saba' only")
        return self._kepler_plan(*self.kernel_arguments())

    # -- time ------------------------------------------------------------------------
    def step(self, n=1):
        """Advance ``n`` steps in one compiled call (``n`` accepted steps for rk45).

        ``n`` is an int in ``[0, 2**62]`` (bools and floats are refused).
        """
        n = step_count("n", n)
        self._contacts = ()
        if n:
            self._run(self._dt, n, math.nan)

    def integrate(self, t_end):
        """Advance to exactly ``t_end`` (forwards or backwards).

        Fixed-step methods take whole steps of |dt| towards ``t_end`` and one shorter last
        step; rk45 shortens its last adaptive step. ``sim.t == t_end`` afterwards.
        ``t_end`` must be finite and (fixed-step methods) reachable in at most 2**62 steps.
        """
        t_end = finite_float("t_end", self._code(t_end, "time", "t_end"))
        self._contacts = ()
        remaining = t_end - self._t
        if remaining == 0.0:
            return
        if not math.isfinite(remaining):
            raise ValueError(f"t_end={t_end!r} is too far from t={self._t!r}: the interval "
                             "overflows a float")
        h = math.copysign(abs(self._dt), remaining)
        needed = abs(remaining) / abs(h)
        adaptive = self._integrator in _integrators.ADAPTIVE_INTEGRATORS
        if not adaptive and not needed <= _MAX_STEPS:
            raise ValueError(f"t_end={t_end!r} needs {needed:.3g} steps of dt={self._dt!r} from "
                             f"t={self._t!r}, more than the 2**62 one call can take; use a "
                             "larger dt or a nearer t_end")
        if adaptive:
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

    def _plastic_terms(self):
        """The declared springs that yield or break, with their positions among the terms
        (found again only when the terms change: ``step`` is called once a frame by games)."""
        if self._plastic_key != self._revision:
            self._plastic = [(s, f) for s, f in enumerate(self._forces)
                             if isinstance(f, Springs) and f.plastic]
            self._plastic_key = self._revision
        return self._plastic

    def _run(self, h, steps, t_end, keep_dt=False):
        plastic = self._plastic_terms()
        if self._collisions is not None or plastic:
            self._run_with_contact(h, steps, t_end, keep_dt, plastic)
        else:
            self._advance(h, steps, t_end, keep_dt)

    def _run_with_contact(self, h, steps, t_end, keep_dt, plastic):
        """``steps`` steps (or up to ``t_end``), each followed by its contacts
        (``engine.collisions.events``) and by the yielding and breaking of plastic springs
        (``engine.forces.spring_yield``): the integrator takes a step, then the contacts along
        the bodies' paths over it are found and resolved in time order, then the springs."""
        from numba import types
        from numba.typed import List

        from .collisions.settings import ACTIONS, RESOLVE_CODES, SEARCH_CODES, Contact

        settings = self._collisions
        if self._integrator == "janus":
            raise ValueError("janus cannot take collisions or yielding springs: it is exactly "
                             "reversible and a contact is not (set sim.collisions = None and "
                             "yield_strain = break_strain = None, or use another integrator); "
                             "nothing was changed")
        if settings is not None:
            from .collisions import events
            if settings.resolve_at == "end":
                from .collisions.end_of_step import collide_at_end as collide
            else:
                collide = events.collide
            points, normals = settings.wall_arrays(self.dim)
        if plastic:
            from .forces import spring_yield
        adaptive = self._integrator in _integrators.ADAPTIVE_INTEGRATORS
        record = List.empty_list(types.UniTuple(types.float64, 7))

        def publish():
            new = tuple(Contact(t, int(i), int(j), speed, ACTIONS[int(a)], energy,
                                int(keep) if keep >= 0 else None)
                        for t, i, j, speed, a, energy, keep in record)
            self._contacts += new
            self.energy_ledger += float(sum(c.energy for c in new))

        state, model = self.kernel_arguments()
        for _ in range(steps):
            if adaptive and not math.isnan(t_end) and self._t == t_end:
                break
            n = state.n
            p0 = state.pos[:, :n].copy()
            v0 = state.vel[:, :n].copy()
            t_before, steps_before = self._t, self.steps
            mark = len(record)
            merging = settings is not None and (settings.resolve == "merge" or
                                                settings.merge_below is not None)
            if merging:  # a merge changes these: kept to restore a step that fails
                kept = [getattr(state, f)[:n].copy() for f in ("mass", "charge", "radius",
                                                              "active")]
            # an adaptive method starts each step from the step size it chose last
            self._advance(math.copysign(abs(self._dt), h) if adaptive else h, 1, t_end,
                          keep_dt)
            state, model = self.kernel_arguments()
            taken = self._t - t_before
            status = 0
            if settings is not None:
                status, pair, t_hit, speed = collide(
                    t_before, taken, state, model, p0, v0, RESOLVE_CODES[settings.resolve],
                    settings.restitution, points, normals, SEARCH_CODES[settings.search],
                    record, -1.0 if settings.merge_below is None else settings.merge_below)
            if status == 0:
                for s, term in plastic:
                    f0, m = int(model.param_offsets[s]), len(term)
                    i0 = int(model.index_offsets[s])
                    self.energy_ledger += spring_yield.yield_and_break(
                        self._t, taken, state.pos, state.vel, state.active, state.box,
                        model.indices[i0:i0 + 2 * m], model.params, f0, m, term.yield_strain,
                        term.break_strain, term.flow_rate, record)
                    term._after_step(model.params[f0 + m:f0 + 2 * m], model.params[f0:f0 + m],
                                     model.params[f0 + 2 * m:f0 + 3 * m])
                continue
            state.pos[:, :n] = p0
            state.vel[:, :n] = v0
            if merging:
                for f, values in zip(("mass", "charge", "radius", "active"), kept):
                    getattr(state, f)[:n] = values
            self._t, self.steps = t_before, steps_before
            while len(record) > mark:  # the failed step's contacts did not happen
                record.pop()
            publish()
            if status == events.HALTED:
                i, j = divmod(int(pair), n)
                raise Collision(
                    f"particles {i} and {j} touched at t={t_hit!r} (normal speed {speed!r}) in "
                    f"step {steps_before} from t={t_before!r}, and collisions say "
                    f"resolve='halt'; the state is left at the start of that step",
                    pair=(i, j), time=t_hit, speed=speed, step=steps_before)
            raise SimulationError(
                f"more than {events.CONTACTS_PER_PARTICLE} contacts per particle in step "
                f"{steps_before} from t={t_before!r}: an inelastic collapse (restitution "
                f"{settings.restitution!r} < 1 can give endless contacts in a finite time); "
                "use a smaller dt or a restitution nearer 1; the state is left at the start of "
                "that step", step=steps_before, time=t_before, particle=None)
        publish()

    def _advance(self, h, steps, t_end, keep_dt=False):
        adaptive = self._integrator in _integrators.ADAPTIVE_INTEGRATORS
        if not adaptive and not math.isfinite(self._t + steps * h):
            raise ValueError(f"{steps} steps of {h!r} from t={self._t!r} take the time past the "
                             "largest float (t would not be finite); nothing was changed")
        state, model = self.kernel_arguments()
        self._check_state(state)
        tree_terms.check_integrator(self._forces, state.n, self._integrator)
        work = self._workspace(state)
        plan = None
        if self._integrator in _integrators.KEPLER_SPLITTING:
            plan = self._kepler_plan(state, model)
        vdep = self._velocity_dependent
        memory = self._ias15_state(state) if self._integrator == "ias15" else None
        lattice = self._janus_exponents(state) if self._integrator == "janus" else None
        counts = np.zeros(1, dtype=np.int64) if self._integrator == "rk45" else None
        before = _ias15.statistics(memory)["evaluations"] if memory is not None else 0
        if plan is not None:
            t, h_next, done, status = _integrators.advance_kepler_splitting(
                self._integrator, self._t, h, steps, state, plan, vdep, t_end, self._corrector,
                self._kernel, self._saba, direct=True)
        else:
            t, h_next, done, status = _integrators.advance(
                self._integrator, self._t, h, steps, state, model, vdep, t_end,
                self._tolerance, work=work, memory=memory, janus_order=self._janus_order,
                lattice=lattice, counts=counts, direct=True)
        if self._integrator == "rk45":
            self.force_evaluations += int(counts[0])
        elif memory is not None:
            self.force_evaluations += _ias15.statistics(memory)["evaluations"] - before
        else:
            self.force_evaluations += self._evaluations_per_step() * done
        failed_step = self.steps + done
        self._t = t
        self.steps += done
        if (adaptive and not keep_dt and status < 0
                and status != _integrators.common.TIME_OVERFLOW):
            self._dt = h_next
        if status != _integrators.common.OK:
            self._raise_for(status, failed_step, t, h_next, lattice)

    def _raise_for(self, status, failed_step, t, h_next, lattice):
        """The exception for an integrator's ``status`` (not OK) after a call of ``_run``."""
        if status >= 0:
            raise SimulationError(
                f"step {failed_step} from t={t!r} with {self._integrator} gave particle {status} a "
                "non-finite position or velocity (singular force, or dt too large for a stiff "
                "force); the last finite state is kept",
                step=failed_step, time=t, particle=int(status))
        if status == _janus.LATTICE_OVERFLOW:
            raise SimulationError(
                f"janus step {failed_step} from t={t!r} would take a position or velocity off its "
                f"lattice (|value| >= 2**53 lattice units of janus_lattice={lattice!r}): a close "
                "encounter or an escape; the state before that step is kept (set "
                "sim.janus_lattice = None to choose coarser spacings)",
                step=failed_step, time=t, particle=None)
        if status == _janus.BAD_LATTICE:
            raise ValueError(f"janus_lattice={lattice!r} does not fit this simulation (exponents "
                             f"out of range, or box={self._box!r} not a whole number of lattice "
                             "units); nothing was changed")
        if status == _integrators.common.TIME_OVERFLOW:
            raise SimulationError(
                f"{self._integrator} step {failed_step} from t={t!r} with step {h_next!r} would take the time "
                "past the largest float (t would not be finite); the last finite state is kept",
                step=failed_step, time=t, particle=None)
        if status == _integrators.common.STEP_COLLAPSED:
            raise SimulationError(
                f"{self._integrator} step size collapsed at step {failed_step}, t={t!r} (tolerance "
                f"{self._tolerance!r} cannot be met); the last accepted state is kept",
                step=failed_step, time=t, particle=None)

    def _kepler_plan(self, state, model):
        """whfast's and saba's plan (``wisdom_holman.plan``), made again only when something
        it depends on changed: the terms and their parameters, the particles' masses and
        flags (all of which the user may write between calls)."""
        n = state.n
        # the model by identity (a repacked one is a new object; nothing writes a simulation's
        # packed parameters in place), the particles' arrays by content (the user may)
        particles = (state.mass[:n].tobytes(), state.active[:n].tobytes(),
                     state.test[:n].tobytes(), state.pinned[:n].tobytes())
        key = (self._integrator, self._coordinates, self._revision, n, state.box, particles)
        if key != self._plan_key or self._plan_model is not model:
            self._plan = wisdom_holman.shared_plan(self._forces, state, model,
                                                   lambda terms: pack(terms, self),
                                                   self._integrator, self._coordinates,
                                                   particles)
            self._plan_key = key
            self._plan_model = model
        return self._plan

    def _evaluations_per_step(self):
        name = self._integrator
        if name == "whfast":
            return 2 if self._kernel == "lazy" else 1
        if name == "saba":
            _, kicks, cc = wisdom_holman.saba_scheme(self._saba)
            return kicks.shape[0] + (2 if cc else 0)
        if name == "janus":
            return _janus.FORCE_EVALUATIONS[self._janus_order]
        return _integrators.FORCE_EVALUATIONS[name]

    def _ias15_state(self, state):
        """IAS15's memory between calls (its predictor's coefficients): kept while the
        particle count stays; IAS15 itself starts cold when the positions or velocities were
        written since its last call."""
        shape = _ias15.memory_shape(self.dim, state.n)
        if self._ias15_memory is None or self._ias15_memory.shape != shape:
            self._ias15_memory = _ias15.new_memory(self.dim, state.n)
        return self._ias15_memory

    def _janus_exponents(self, state):
        if self._janus_lattice is None:
            self._janus_lattice = _janus.lattice_exponents(
                state.pos, state.vel, state.n, box=state.box, active=state.active,
                pinned=state.pinned)
        return self._janus_lattice

    def _check_state(self, state):
        """Refuse to step from a state the user made invalid by writing the arrays directly.

        ``sim.pos``, ``vel``, ``mass``, ``charge`` and ``radius`` are writable views: a
        non-finite value written there is bad input of that field (ValueError naming it, state
        unchanged), never reported as a numerical blow-up of the step. A pinned particle's
        velocity written there is set back to zero (nothing moves it).
        """
        code = direct.call(first_invalid, (state,))
        if not code:
            return
        field, i = INVALID_FIELDS[code >> 32], code & 0xFFFFFFFF
        if field in ("pos", "vel"):
            values = state.pos if field == "pos" else state.vel
            raise ValueError(f"particle {i} has a non-finite pos or vel: {field}[{i}] = "
                             f"{values[:, i]} was written with a non-finite value (bad input); "
                             "nothing was changed")
        value = float(getattr(state, field)[i])
        rule = "finite" if field == "charge" else "finite and >= 0.0"
        hint = (" (to hold a particle still, pin it: sim.pin(i))"
                if field == "mass" and value == math.inf else "")
        raise ValueError(f"{field}[{i}] must be {rule}, got {value!r} (written into sim.{field} "
                         f"directly: bad input, not a blow-up); nothing was changed{hint}")

    # -- diagnostics -----------------------------------------------------------------
    def _moving(self):
        """The particles the diagnostics count: active and not pinned."""
        p = self._particles
        return p.active & ~p.pinned

    def kinetic_energy(self):
        p = self._particles
        return diagnostics.kinetic_energy(p.vel, p.mass, self._moving(), p.n)

    def potential_energy_terms(self):
        """Potential energy of each declared term, in declaration order.

        A term that evaluates by the tree (``method="tree"``) sums its potential by the same
        tree and ``theta`` (so it carries the tree's error; a direct sum over 10^6 bodies
        would visit 10^12 pairs)."""
        state, model = self.kernel_arguments()
        out = np.zeros(len(self._forces))
        trees = self._tree_terms()
        if not trees:
            potential_terms(self._t, state, model, out)
            return out
        from .forces.registry import by_kind
        work = self._workspace(state)
        for s, term in enumerate(self._forces):
            f0, f1 = int(model.param_offsets[s]), int(model.param_offsets[s + 1])
            i0, i1 = int(model.index_offsets[s]), int(model.index_offsets[s + 1])
            module = by_kind(int(model.kinds[s])).module
            if any(term is tree for tree in trees):
                out[s] = module.tree_potential(state, model.params, f0, work)
            else:
                out[s] = module.potential(self._t, state, model.params, f0, f1, model.indices,
                                          i0, i1)
        return out

    def potential_energy(self):
        """Sum of the potentials of the declared conservative terms, added in declaration
        order (as ``Batch.potential_energy`` adds them, so the two agree to the bit)."""
        total = 0.0
        for u in self.potential_energy_terms().tolist():
            total += u
        return total

    def energy(self):
        return self.kinetic_energy() + self.potential_energy()

    def momentum(self):
        p = self._particles
        return diagnostics.momentum(p.vel, p.mass, self._moving(), p.n)

    def angular_momentum(self):
        """About the origin: a 3-vector in 3-D, the scalar L_z in 2-D."""
        p = self._particles
        L = diagnostics.angular_momentum(p.pos, p.vel, p.mass, self._moving(), p.n)
        return float(L[0]) if self.dim == 2 else L

    def center_of_mass(self):
        p = self._particles
        return diagnostics.center_of_mass(p.pos, p.vel, p.mass, self._moving(), p.n)

    def stable_dt(self):
        """The largest stable |dt| for this integrator at the current state (code units):
        the integrator's limit on omega h over the highest frequency of the declared springs
        (and of close gravitating pairs); ``inf`` if nothing limits the step, 0.0 for
        ``euler`` on any oscillation; ValueError for the adaptive ``rk45``. See
        ``engine.stability``."""
        from . import stability
        return stability.stable_dt(self)

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


def _flags(field, value, k):
    """``value`` as k booleans (one for all, or one per particle)."""
    try:
        flags = np.broadcast_to(np.asarray(value), (k,))
    except ValueError:
        raise ValueError(f"{field} must be True or False (or one per particle), got {value!r}") from None
    if flags.dtype != np.bool_:
        raise TypeError(f"{field} must be True or False, got {value!r}")
    return flags


__all__ = ["Simulation"]


def _check_corrector(value):
    if isinstance(value, bool) or value not in wisdom_holman.CORRECTORS:
        raise ValueError(f"corrector must be one of {wisdom_holman.CORRECTORS}, got {value!r}")
    return int(value)


def _check_coordinates(value):
    if not isinstance(value, str) or value not in wisdom_holman.COORDINATES:
        raise ValueError("coordinates must be one of "
                         f"{', '.join(map(repr, wisdom_holman.COORDINATES))}, got {value!r}")
    return value


def _check_kernel(value):
    if value not in wisdom_holman.KERNELS:
        raise ValueError(f"kernel must be one of {', '.join(map(repr, wisdom_holman.KERNELS))}, "
                         f"got {value!r}")
    return value


def _check_saba(value):
    if value not in wisdom_holman.SABA_METHODS:
        raise ValueError(f"saba must be one of {', '.join(wisdom_holman.SABA_METHODS)}, got "
                         f"{value!r}")
    return value


def _check_janus_order(value):
    if isinstance(value, bool) or value not in _janus.ORDERS:
        raise ValueError(f"janus_order must be one of {_janus.ORDERS}, got {value!r}")
    return int(value)
