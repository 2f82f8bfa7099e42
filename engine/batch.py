"""Batch: M independent systems that share their force terms and slot count, advanced together.

    batch = Batch(systems=4096, dim=2, integrator="symplectic_euler", dt=1.0, capacity=66)
    batch.add_many(mass=masses, pos=positions)        # (M, k) and (M, k, dim), or one for all
    star = batch.add_force(forces.PointMass(mu=1e-3))
    batch.set_parameter(star, "pos", centres)         # (M, 2): one star position per system
    batch.step(100)                                   # one compiled call, systems over the cores
    batch.pos                                         # (M, N, dim) view of the state
    batch.energy()                                    # (M,)

Every system is advanced by the very kernel a ``Simulation`` runs (``step_system`` below, the
integrator's ``advance`` on one system's slice of the arrays), so system m of a batch is
bit-identical to the same system stepped alone in a ``Simulation``, and the result does not
depend on the number of threads (numba's ``prange`` spreads whole systems over them; nothing is
summed across systems). REBOUND has no batch of independent systems; Gymnasium's
``CartPoleVectorEnv`` (state with a leading environment axis, stepped by vectorised code) is
the model for the layout.

The state has a leading system axis: ``pos``/``vel`` are stored as ``(M, dim, capacity)``
(component-major per system, as in a ``Simulation``), the per-particle arrays as
``(M, capacity)``, and the float parameters of the force terms as one row per system
(``(M, F)``, laid out by the terms' ``LAYOUT`` names). A term's attribute (``drag.linear = 1``)
sets that parameter for every system; ``set_parameter`` sets it per system, and from then on
that parameter is per system (a later attribute change leaves it alone).

Compiled code of your own (a game's frame) takes ``batch.kernel_arguments()``: an
``engine.state.State`` whose arrays carry the system axis, and a ``Model`` whose ``params`` is
``(M, F)``; ``system_state(state, m)`` and ``system_model(model, m)`` give one system's
named tuples, and ``advance_system`` steps it with a splitting scheme.
"""
import numbers

import numpy as np
from numba import prange

from .cache import jit

from . import diagnostics
from . import integrators as _integrators
from ._validate import (finite_float, int_in_range, nonnegative_float, positive_float, real_array,
                        step_count)
from .collisions.settings import DeclaresCollisions
from .errors import Collision, SimulationError
from .forces.base import DeclaresTerms
from .forces.dispatch import pack, potential_terms
from .forces.pairwise import PARALLEL_MIN, float_count
from .integrators import dormand_prince, euler, runge_kutta, splitting
from .integrators.common import STEP_COLLAPSED, TIME_OVERFLOW
from .space import check_box
from .state import INVALID_FIELDS, Model, State, Workspace
from .state import first_invalid as first_invalid_in

#: integrator families of the compiled batch step
SPLITTING, EULER, RK4, RK45 = 0, 1, 2, 3

MAX_SYSTEMS = 2 ** 24


@jit(inline="always")
def system_state(state, m):
    """System m of a batch's state (views of its rows), as a one-system ``State``."""
    return State(state.pos[m], state.vel[m], state.mass[m], state.charge[m], state.radius[m],
                 state.active[m], state.test[m], state.pinned[m], state.n, state.box)


@jit(inline="always")
def system_model(model, m):
    """System m's force terms: the shared tables with its own row of float parameters."""
    return Model(model.kinds, model.params[m], model.param_offsets, model.indices,
                 model.index_offsets, model.accumulators, model.potentials)


@jit(error_model="numpy", inline="always")
def advance_system(m, t, h, steps, state, model, work, vdep, drifts, kicks):
    """``steps`` steps of a splitting scheme (``splitting.coefficients(name)``) on system m
    of a batch: the per-system kernel for compiled callers. Returns ``(t, h, done, status)``
    as every integrator does (``engine.integrators.common``)."""
    return splitting.advance(t, h, steps, system_state(state, m), system_model(model, m), work,
                             vdep, np.nan, drifts, kicks)


@jit(error_model="numpy")
def step_system(m, family, t, h, steps, state, model, work, vdep, tol, drifts, kicks):
    """System m advanced by the integrator ``family`` (SPLITTING with its coefficients,
    EULER, RK4 or RK45 with tolerance ``tol``): exactly what ``Simulation.step`` runs."""
    s = system_state(state, m)
    model_m = system_model(model, m)
    if family == SPLITTING:
        return splitting.advance(t, h, steps, s, model_m, work, vdep, np.nan, drifts, kicks)
    if family == EULER:
        return euler.advance(t, h, steps, s, model_m, work, vdep, np.nan)
    if family == RK4:
        return runge_kutta.advance(t, h, steps, s, model_m, work, vdep, np.nan)
    return dormand_prince.advance(t, h, steps, s, model_m, work, vdep, np.nan, tol)


@jit(error_model="numpy", inline="always")
def system_workspace(n):
    """The scratch a ``Simulation`` of n slots would get, kept on this thread."""
    if n >= PARALLEL_MIN:
        return Workspace(np.empty(float_count(n)), np.empty(n, dtype=np.int64), False)
    return Workspace(np.empty(0), np.empty(0, dtype=np.int64), False)


#: systems are handed to the threads in this many chunks at most (one scratch space each)
CHUNKS = 256


@jit(parallel=True, error_model="numpy")
def advance_all(family, t, h, steps, state, model, vdep, tol, drifts, kicks, done, status):
    """Every system by ``steps`` steps, whole systems spread over the threads in chunks (each
    chunk with its own scratch space; which thread runs a chunk changes no result).

    ``t`` and ``h`` (one per system) are updated in place; ``done[m]`` and ``status[m]`` get
    each system's completed steps and failure code (-1 for success; ``integrators.common``)."""
    systems = state.pos.shape[0]
    chunks = min(systems, CHUNKS)
    for c in prange(chunks):
        work = system_workspace(state.n)
        for m in range(c * systems // chunks, (c + 1) * systems // chunks):
            tm, hm, dm, sm = step_system(m, family, t[m], h[m], steps, state, model, work, vdep,
                                         tol, drifts, kicks)
            t[m] = tm
            h[m] = hm
            done[m] = dm
            status[m] = sm


@jit(parallel=True, error_model="numpy")
def first_invalid(state, found):
    """``engine.state.first_invalid`` of every system into ``found`` (0 where valid), which
    also sets pinned particles' velocities back to zero."""
    for m in prange(state.pos.shape[0]):
        found[m] = first_invalid_in(system_state(state, m))


@jit(parallel=True, error_model="numpy")
def energies(t, state, model, moving, terms, kinetic, potential):
    """Kinetic and potential energy of every system (the diagnostics of a ``Simulation``)."""
    for m in prange(state.pos.shape[0]):
        s = system_state(state, m)
        out = np.zeros(terms)
        potential_terms(t[m], s, system_model(model, m), out)
        kinetic[m] = diagnostics.kinetic_energy(s.vel, s.mass, moving[m], s.n)
        total = 0.0
        for u in out:  # in declaration order, as Simulation.potential_energy adds them
            total += u
        potential[m] = total


@jit(parallel=True, error_model="numpy")
def momenta(state, moving, out):
    """Linear momentum of every system (``diagnostics.momentum`` per system)."""
    for m in prange(state.pos.shape[0]):
        out[m] = diagnostics.momentum(state.vel[m], state.mass[m], moving[m], state.n)


class Batch(DeclaresTerms, DeclaresCollisions):
    """M independent systems with the same force terms and particle slots (see the module).

    Parameters mirror ``Simulation``'s: ``systems`` (M >= 1), ``dim``, ``integrator``, ``dt``,
    ``tolerance`` (rk45), ``G``, ``capacity`` (initial slots per system), ``box`` (side of the
    periodic space). Quantities are plain floats in code units. ``t`` and ``steps`` are one per
    system (rk45 adapts each system's step on its own).
    """

    def __init__(self, systems, dim=2, integrator="symplectic_euler", dt=1.0, tolerance=1e-9,
                 G=None, capacity=16, box=None):
        systems = int_in_range("systems", systems, 1, MAX_SYSTEMS)
        if isinstance(dim, bool) or dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        capacity = int_in_range("capacity", capacity, 0, 2 ** 31)
        self._integrator = _integrators.check_name(integrator)
        if self._integrator not in _integrators.GENERAL:
            raise ValueError(f"integrator {integrator!r} is not available in a Batch (one of "
                             f"{', '.join(_integrators.GENERAL)}); step separate Simulations "
                             "with it")
        dt = finite_float("dt", dt)
        if dt == 0.0:
            raise ValueError("dt must be non-zero (negative runs backwards), got 0.0")
        self._tolerance = positive_float("tolerance", tolerance)
        self._G = 1.0 if G is None else nonnegative_float("G", G)
        self._box = check_box(box)
        self.dim = int(dim)
        self.systems = int(systems)
        self.n = 0
        self._allocate(max(int(capacity), 1))
        self._t = np.zeros(self.systems)
        self._h = np.full(self.systems, dt)
        self._steps = np.zeros(self.systems, dtype=np.int64)
        self._forces = []
        self._revision = 0
        self._model_key = None
        self._model = None
        self._layouts = {}
        self._layout_terms = []
        self._per_system = []  # (term, name) pairs set per system
        self._collisions = None  # engine.Collisions, or None
        self._contacts = tuple(() for _ in range(self.systems))
        #: (M,) the energy contacts took out of each system (``Simulation.energy_ledger``)
        self.energy_ledger = np.zeros(self.systems)

    # -- storage ---------------------------------------------------------------------
    def _allocate(self, capacity):
        M, dim, old = self.systems, self.dim, self.n
        fresh = {"_pos": np.zeros((M, dim, capacity)), "_vel": np.zeros((M, dim, capacity)),
                 "_mass": np.zeros((M, capacity)), "_charge": np.zeros((M, capacity)),
                 "_radius": np.zeros((M, capacity)),
                 "_active": np.zeros((M, capacity), dtype=np.bool_),
                 "_test": np.zeros((M, capacity), dtype=np.bool_),
                 "_pinned": np.zeros((M, capacity), dtype=np.bool_)}
        for name, arr in fresh.items():
            if old:
                arr[..., :old] = getattr(self, name)[..., :old]
            setattr(self, name, arr)
        self.capacity = capacity

    # -- configuration ---------------------------------------------------------------
    @property
    def integrator(self):
        return self._integrator

    @property
    def dt(self):
        """The step of system 0 (rk45 adapts each system's own; see ``dts``)."""
        return float(self._h[0])

    @property
    def dts(self):
        return self._h.copy()

    @property
    def G(self):
        return self._G

    @property
    def box(self):
        return self._box

    @property
    def t(self):
        """Time of each system, (M,) (a copy)."""
        return self._t.copy()

    @property
    def steps(self):
        return self._steps.copy()

    def __len__(self):
        return self.n

    # -- particles -------------------------------------------------------------------
    @property
    def pos(self):
        """Positions, (M, N, dim): a writable view of the state."""
        return self._pos[:, :, : self.n].transpose(0, 2, 1)

    @property
    def vel(self):
        """Velocities, (M, N, dim): a writable view of the state."""
        return self._vel[:, :, : self.n].transpose(0, 2, 1)

    @property
    def mass(self):
        """Masses, (M, N): writable (a mass may differ per system)."""
        return self._mass[:, : self.n]

    @property
    def charge(self):
        return self._charge[:, : self.n]

    @property
    def radius(self):
        return self._radius[:, : self.n]

    @property
    def active(self):
        """(M, N) active flags (writable: deactivating a particle in one system only)."""
        return self._active[:, : self.n]

    @property
    def test(self):
        view = self._test[:, : self.n]
        view.flags.writeable = False
        return view

    @property
    def pinned(self):
        view = self._pinned[:, : self.n]
        view.flags.writeable = False
        return view

    def add_many(self, mass, pos, vel=None, charge=0.0, radius=0.0, test=False, pinned=False):
        """Add k particle slots to every system; return their indices, (k,).

        ``pos``/``vel``: (M, k, dim), or (k, dim) for the same in every system; ``mass``,
        ``charge``, ``radius``: a scalar, (k,) or (M, k); ``test``, ``pinned``: a bool, (k,)
        or (M, k). Everything is checked before anything is added.
        """
        p = self._rows("pos", pos)
        k = p.shape[1]
        v = np.zeros_like(p) if vel is None else self._rows("vel", vel)
        if v.shape != p.shape:
            raise ValueError(f"vel has shape {v.shape[1:]} per system but pos has {p.shape[1:]}")
        m = self._columns("mass", mass, k, minimum=0.0)
        q = self._columns("charge", charge, k)
        r = self._columns("radius", radius, k, minimum=0.0)
        tst = self._flags("test", test, k)
        pin = self._flags("pinned", pinned, k)
        if self.n + k > self.capacity:
            self._allocate(max(self.n + k, 2 * self.capacity))
        s = slice(self.n, self.n + k)
        self._pos[:, :, s] = p.transpose(0, 2, 1)
        self._vel[:, :, s] = np.where(pin[:, :, None], 0.0, v).transpose(0, 2, 1)
        self._mass[:, s] = m
        self._charge[:, s] = q
        self._radius[:, s] = r
        self._test[:, s] = tst
        self._pinned[:, s] = pin
        self._active[:, s] = True
        self.n += k
        self._revision += 1  # per-slot parameters (a Thrust's) are laid out for the new count
        return np.arange(s.start, s.stop)

    def _rows(self, field, value):
        arr = real_array(field, value, "numbers")
        if arr.ndim == 2:
            arr = np.broadcast_to(arr, (self.systems,) + arr.shape)
        if arr.ndim != 3 or arr.shape[0] != self.systems or arr.shape[2] != self.dim:
            raise ValueError(f"{field} must have shape (systems={self.systems}, k, dim={self.dim}) "
                             f"or (k, {self.dim}), got shape {arr.shape}")
        if not np.all(np.isfinite(arr)):
            status = np.argwhere(~np.isfinite(arr))[0]
            raise ValueError(f"{field} must be finite, got {arr[tuple(status)]!r} at system "
                             f"{status[0]}, particle {status[1]} of the call")
        return arr

    def _columns(self, field, value, k, minimum=None):
        arr = real_array(field, value, "a number")
        try:
            arr = np.broadcast_to(arr, (self.systems, k))
        except ValueError:
            raise ValueError(f"{field} must be a scalar, (k,) = ({k},) or (systems, k) = "
                             f"({self.systems}, {k}), got shape {arr.shape}") from None
        status = ~np.isfinite(arr)
        if minimum is not None:
            status |= arr < minimum
        if status.any():
            sys_, i = np.argwhere(status)[0]
            rule = "finite" if minimum is None else f"finite and >= {minimum}"
            raise ValueError(f"{field} must be {rule}, got {float(arr[sys_, i])!r} (system {sys_}, "
                             f"particle {i} of the call)")
        return arr

    def _flags(self, field, value, k):
        arr = np.asarray(value)
        if arr.dtype != np.bool_:
            raise TypeError(f"{field} must be True or False (or one per particle), got {value!r}")
        try:
            return np.broadcast_to(arr, (self.systems, k))
        except ValueError:
            raise ValueError(f"{field} must be a bool, (k,) or (systems, k), got shape "
                             f"{arr.shape}") from None

    def pin(self, i, system=None):
        """Hold particle ``i`` still (in every system, or in ``system``): see ``Simulation.pin``."""
        rows = self._system_rows(system)
        i = self._index(i)
        self._pinned[rows, i] = True
        self._vel[rows, :, i] = 0.0

    def unpin(self, i, system=None):
        rows = self._system_rows(system)
        self._pinned[rows, self._index(i)] = False

    def _index(self, i):
        if isinstance(i, bool) or not isinstance(i, numbers.Integral) or not 0 <= i < self.n:
            raise ValueError(f"particle index must be an int in [0, {self.n}), got {i!r}")
        return int(i)

    def _system_rows(self, system):
        if system is None:
            return slice(None)
        if isinstance(system, bool) or not isinstance(system, numbers.Integral) \
                or not 0 <= system < self.systems:
            raise ValueError(f"system must be an int in [0, {self.systems}), got {system!r}")
        return int(system)

    # -- forces ----------------------------------------------------------------------
    _owner = "batch"

    def add_force(self, force):
        """Declare a force term for every system (``Simulation.add_force``); springs that
        yield or break are refused (a batch does not run their after-step pass yet)."""
        from .forces.springs import Springs

        if isinstance(force, Springs) and force.plastic:
            raise ValueError(f"{force!r} yields or breaks (yield_strain or break_strain set): "
                             "a Batch does not take plastic springs yet; use a Simulation "
                             "per system")
        return super().add_force(force)

    def _forgotten(self, force):
        self._per_system = [(t, name) for t, name in self._per_system if t is not force]

    def _slot(self, term, name):
        """The ``slice`` of ``name`` in a system's parameter row, and its shape."""
        return self._term_slot(self._current_model(), term, name)

    def parameter(self, term, name):
        """The packed values of ``term``'s parameter ``name`` in every system, (M, *shape)
        (a copy; names are the term's ``LAYOUT``, e.g. ``"pos"`` of a PointMass)."""
        cols, shape = self._slot(term, name)
        return self._model.params[:, cols].reshape((self.systems,) + shape).copy()

    def set_parameter(self, term, name, values):
        """Set ``term``'s parameter ``name`` per system: ``values`` of shape (M, *shape), or
        *shape for all. From then on the parameter is per system: the term's own attribute
        no longer overwrites it. Values are the packed ones (``softening_squared`` is the
        square of the softening length) and must be finite."""
        cols, shape = self._slot(term, name)
        arr = real_array(name, values, "numbers")
        try:
            arr = np.broadcast_to(arr, (self.systems,) + shape)
        except ValueError:
            raise ValueError(f"{name} must have shape (systems={self.systems}, *{shape}) or "
                             f"{shape}, got shape {arr.shape}") from None
        flat = arr.reshape(self.systems, -1)
        invalid = ~np.isfinite(flat)
        minimum, strict = type(term).BOUNDS.get(name, (None, False))
        if minimum is not None:
            invalid |= (flat <= minimum) if strict else (flat < minimum)
        if invalid.any():
            m, j = (int(x) for x in np.argwhere(invalid)[0])
            rule = "finite" if minimum is None else f"finite and {'>' if strict else '>='} {minimum}"
            raise ValueError(f"{type(term).__name__}.{name} must be {rule}, got "
                             f"{float(flat[m, j])!r} (system {m}); nothing was changed")
        self._model.params[:, cols] = flat
        self._mark_per_system(term, name)

    def parameter_columns(self, term, name):
        """``(start, stop)``: the columns of ``name`` in ``kernel_arguments()[1].params`` rows, for
        compiled code that writes the parameter itself every step (a ship's thrust); the
        parameter becomes per system, as with ``set_parameter``."""
        cols, _ = self._slot(term, name)
        self._mark_per_system(term, name)
        return cols.start, cols.stop

    def _mark_per_system(self, term, name):
        if not any(t is term and n == name for t, n in self._per_system):
            self._per_system.append((term, name))

    def _current_model(self):
        key = (self._G, self._revision) + tuple(f._version for f in self._forces)
        if key == self._model_key:
            return self._model
        model = pack(self._forces, self)
        layouts = [term.layout(self) for term in self._forces]
        for term, layout, f0, f1 in zip(self._forces, layouts, model.param_offsets[:-1], model.param_offsets[1:]):
            declared = sum(int(np.prod(shape, dtype=np.int64)) for _, shape in layout.values())
            if declared != f1 - f0:
                raise RuntimeError(f"{type(term).__name__}.LAYOUT declares {declared} floats but "
                                   f"the term packs {f1 - f0}: the declaration is wrong")
        rows = np.repeat(model.params[None, :], self.systems, axis=0)
        for term, name in self._per_system:  # per-system values survive a re-pack
            k = next(i for i, f in enumerate(self._forces) if f is term)
            start, shape = layouts[k][name]
            size = int(np.prod(shape, dtype=np.int64))
            old_start, old_shape = self._old_slot(term, name)
            new0 = int(model.param_offsets[k]) + start
            old = self._model.params[:, old_start:old_start + int(np.prod(old_shape, dtype=np.int64))]
            if old_shape == shape:
                rows[:, new0:new0 + size] = old
            elif old_shape[1:] == shape[1:]:
                # one row per slot (a Thrust's force) and slots were added: the rows kept, the
                # new slots' rows as the term packs them
                kept = min(old_shape[0], shape[0]) * int(np.prod(shape[1:], dtype=np.int64))
                rows[:, new0:new0 + kept] = old[:, :kept]
            else:  # pragma: no cover - no declared layout changes any other way
                raise ValueError(f"{type(term).__name__}.{name} was set per system with shape "
                                 f"{old_shape}, and it now has shape {shape}")
        self._model = model._replace(params=rows)
        self._layouts = {k: layout for k, layout in enumerate(layouts)}
        self._layout_terms = list(self._forces)
        self._model_key = key
        return self._model

    def _old_slot(self, term, name):
        """Where ``term.name`` sat in the previous packing (absolute column, shape)."""
        for k, f in enumerate(self._layout_terms):
            if f is term:
                start, shape = self._layouts[k][name]
                return int(self._model.param_offsets[k]) + start, shape
        raise ValueError(f"{term!r} was not packed before")

    @property
    def revision(self):
        """A counter bumped by every change that re-packs the terms (a term or slots added or
        removed, a term's parameter changed): ``kernel_arguments()`` and
        ``parameter_columns()`` hold while it stays the same."""
        return self._revision

    def kernel_arguments(self):
        """``(state, model)`` with the system axis: ``State`` arrays of shape (M, dim, capacity)
        and (M, capacity), ``Model.params`` of shape (M, F); for compiled code of your own."""
        state = State(self._pos, self._vel, self._mass, self._charge, self._radius, self._active,
                      self._test, self._pinned, self.n, self._box)
        return state, self._current_model()

    # -- contact -----------------------------------------------------------------------
    @property
    def contacts(self):
        """The last ``step`` call's contacts: one tuple of ``engine.Contact`` per system."""
        return self._contacts

    def _step_colliding(self, n, state, model, vdep, family, drifts, kicks, done, status):
        """``advance_all`` with every step followed by its contacts
        (``engine.collisions.batch_steps``); the contacts and the ledger published."""
        from numba import types
        from numba.typed import List

        from .collisions import batch_steps
        from .collisions.settings import ACTIONS, RESOLVE_CODES, SEARCH_CODES, Contact

        settings = self._collisions
        points, normals = settings.wall_arrays(self.dim)
        record_type = types.UniTuple(types.float64, 7)
        records = List.empty_list(types.ListType(record_type))
        for _ in range(self.systems):
            records.append(List.empty_list(record_type))
        halts = np.zeros((self.systems, 3))
        batch_steps.advance_all_colliding(
            family, self._t, self._h, n, state, model, vdep, self._tolerance, drifts, kicks,
            done, status, RESOLVE_CODES[settings.resolve], settings.restitution, points,
            normals, SEARCH_CODES[settings.search], records, halts,
            -1.0 if settings.merge_below is None else settings.merge_below,
            settings.resolve_at == "end")
        contacts = []
        for m, record in enumerate(records):
            mine = tuple(Contact(t, int(i), int(j), speed, ACTIONS[int(a)], energy,
                                 int(keep) if keep >= 0 else None)
                         for t, i, j, speed, a, energy, keep in record)
            self.energy_ledger[m] += sum(c.energy for c in mine)
            contacts.append(mine)
        self._contacts = tuple(contacts)
        return halts

    # -- time ------------------------------------------------------------------------
    def step(self, n=1):
        """Advance every system by ``n`` steps in one compiled call (rk45: ``n`` accepted
        steps each). A system that blows up keeps its last finite state and the call raises
        ``SimulationError`` naming it; the other systems have taken their steps."""
        n = step_count("n", n)
        if not n:
            return
        state, model = self.kernel_arguments()
        self._check_state(state)
        if self._integrator != "rk45" and not np.all(np.isfinite(self._t + n * self._h)):
            raise ValueError(f"{n} steps of {self._h[0]!r} take the time past the largest float; "
                             "nothing was changed")
        vdep = any(f.velocity_dependent for f in self._forces)
        family, drifts, kicks = _family(self._integrator)
        done = np.zeros(self.systems, dtype=np.int64)
        status = np.full(self.systems, -1, dtype=np.int64)
        h_before = self._h.copy()
        halts = None
        self._contacts = tuple(() for _ in range(self.systems))
        if self._collisions is not None:
            halts = self._step_colliding(n, state, model, vdep, family, drifts, kicks, done,
                                         status)
        else:
            advance_all(family, self._t, self._h, n, state, model, vdep, self._tolerance,
                        drifts, kicks, done, status)
        if family != RK45:
            self._h[:] = h_before
        else:  # as a Simulation does: a failed system keeps the step it had
            keep = (status >= 0) | (status == TIME_OVERFLOW)
            self._h[keep] = h_before[keep]
        self._steps += done
        failed = np.flatnonzero(status != -1)
        if failed.size:
            m = int(failed[0])
            code = int(status[m])
            if halts is not None:
                self._raise_contact(m, code, halts, failed)
            what = {STEP_COLLAPSED: "the rk45 step size collapsed",
                    TIME_OVERFLOW: "the next rk45 step would take the time past the largest float"}
            reason = what.get(code, f"particle {code} got a non-finite position or velocity")
            raise SimulationError(
                f"system {m} of {self.systems} failed at its step {int(self._steps[m])} from "
                f"t={float(self._t[m])!r} with {self._integrator}: {reason}; its last finite "
                f"state is kept ({failed.size} system(s) failed: {failed[:8].tolist()})",
                step=int(self._steps[m]), time=float(self._t[m]),
                particle=code if code >= 0 else None)

    def _raise_contact(self, m, code, halts, failed):
        """The exception for system m stopped by a contact (``batch_steps`` status codes)."""
        from .collisions.batch_steps import HALT_STATUS, TOO_MANY_STATUS
        from .collisions.events import CONTACTS_PER_PARTICLE

        t_m, steps_m = float(self._t[m]), int(self._steps[m])
        if code == HALT_STATUS:
            i, j = divmod(int(halts[m, 0]), self.n)
            raise Collision(
                f"system {m} of {self.systems}: particles {i} and {j} touched at "
                f"t={float(halts[m, 1])!r} (normal speed {float(halts[m, 2])!r}) in its step "
                f"{steps_m} from t={t_m!r}, and collisions say resolve='halt'; that system is "
                f"left at the start of that step ({failed.size} system(s) stopped: "
                f"{failed[:8].tolist()})", pair=(i, j), time=float(halts[m, 1]),
                speed=float(halts[m, 2]), step=steps_m)
        if code == TOO_MANY_STATUS:
            raise SimulationError(
                f"system {m} of {self.systems}: more than {CONTACTS_PER_PARTICLE} contacts per "
                f"particle in its step {steps_m} from t={t_m!r} (an inelastic collapse); that "
                "system is left at the start of that step", step=steps_m, time=t_m,
                particle=None)

    def _check_state(self, state):
        """Refuse bad input written into the arrays (ValueError naming the field, system and
        particle; nothing changed); set pinned particles' velocities back to zero."""
        found = np.zeros(self.systems, dtype=np.int64)
        first_invalid(state, found)
        bad_systems = np.flatnonzero(found)
        if bad_systems.size:
            m = int(bad_systems[0])
            field = INVALID_FIELDS[int(found[m] >> 32)]
            i = int(found[m] & 0xFFFFFFFF)
            value = {"pos": self._pos[m, :, i], "vel": self._vel[m, :, i]}.get(field)
            value = value.tolist() if value is not None else float(getattr(self, "_" + field)[m, i])
            rule = " and >= 0" if field in ("mass", "radius") else ""
            raise ValueError(f"{field} of system {m}, particle {i} must be finite{rule}, got "
                             f"{value!r} (written directly: bad input); nothing was changed")

    # -- diagnostics -----------------------------------------------------------------
    def _moving(self):
        return self._active & ~self._pinned

    def _energies(self):
        state, model = self.kernel_arguments()
        kinetic = np.zeros(self.systems)
        potential = np.zeros(self.systems)
        energies(self._t, state, model, self._moving(), len(self._forces), kinetic, potential)
        return kinetic, potential

    def kinetic_energy(self):
        """(M,) kinetic energy of each system's moving particles."""
        return self._energies()[0]

    def potential_energy(self):
        """(M,) sum of each system's conservative potentials."""
        return self._energies()[1]

    def energy(self):
        """(M,) total energy of each system."""
        kinetic, potential = self._energies()
        return kinetic + potential

    def momentum(self):
        """(M, dim) linear momentum of each system's moving particles."""
        state, _ = self.kernel_arguments()
        out = np.zeros((self.systems, self.dim))
        momenta(state, self._moving(), out)
        return out

    def __repr__(self):
        return (f"Batch(systems={self.systems}, dim={self.dim}, integrator={self._integrator!r}, "
                f"n={self.n}, forces={self._forces!r})")


def _family(name):
    """The compiled family of an integrator name, with splitting coefficients (or empty)."""
    if name in splitting.SCHEMES:
        drifts, kicks = splitting.coefficients(name)
        return SPLITTING, drifts, kicks
    empty = np.zeros(0)
    return {"euler": EULER, "rk4": RK4, "rk45": RK45}[name], empty, empty


__all__ = ["Batch", "advance_system", "step_system", "system_state", "system_model",
           "SPLITTING", "EULER", "RK4", "RK45"]
