"""What every force term shares: packing its parameters for the compiled dispatcher.

A force term is a Python object holding its parameters plus two numba kernels in its module:
``accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)`` adds its acceleration into
``acc[:, :state.n]`` (``state`` an ``engine.state.State``, ``work`` an
``engine.state.Workspace`` of scratch for the large-N pair kernels), and
``potential(t, state, params, f0, f1, indices, i0, i1)`` returns its potential energy (0.0 when the
term is not conservative). The term's float parameters are ``params[f0:f1]``, laid out as its
class's ``LAYOUT`` names them, and its integer ones (particle indices) ``indices[i0:i1]``. The
simulation concatenates all declared terms into one table so that a step calls one compiled
function and pays only for the declared terms.
"""
import functools

import numpy as np

from .._validate import index_array


def _sealing(init):
    """Wrap a force's ``__init__`` so the instance is sealed once construction is over."""
    @functools.wraps(init)
    def __init__(self, *args, **kwargs):
        depth = self.__dict__.get("_init_depth", 0)
        object.__setattr__(self, "_init_depth", depth + 1)
        try:
            init(self, *args, **kwargs)
        finally:
            object.__setattr__(self, "_init_depth", depth)
        if depth == 0:
            object.__setattr__(self, "_sealed", True)
    return __init__


class Force:
    """Base class of force terms. Subclasses set ``KIND`` and implement ``_pack``.

    Parameters named in ``_settable`` (name -> check(name, value)) may be assigned at any time
    (``drag.linear = 0.5``): the value is checked, the term re-checked against its simulation,
    and the next step uses it. Other public attributes are fixed once the term is made:
    assigning one raises AttributeError (an unchecked index array must never reach compiled
    code, and a silently ignored assignment would be worse). Properties with setters
    (``point_mass.pos = ...``) work as they define.

    Public array attributes (spring ``pairs``, wind ``triangles``, ``PointMass.particles``,
    per-spring ``k`` ...) are stored as read-only views (``writeable=False``): writing an index
    in place would reach the compiled kernels unchecked (an out-of-range index there reads or
    writes outside the particle arrays), and a changed value would be silently ignored by an
    already packed model. Every term is also re-checked (``_check``) whenever a simulation
    packs its model.
    """

    KIND = -1
    #: True if the term has a potential that ``sim.potential_energy()`` sums.
    conservative = False
    #: the packed float parameters in order, as ``(name, shape)``; a shape entry is an int,
    #: ``"dim"`` (the simulation's dimension), ``"slots"`` (its particle slots), ``"rows"``
    #: (``term._rows(sim)``: a Thrust's pushed particles) or ``"items"`` (``len(term)``: one
    #: per spring)
    LAYOUT = ()
    #: lower bounds of packed parameters, ``name -> (minimum, strict)``: what a value set per
    #: system (``Batch.set_parameter``) is checked against, as the term's own checks would
    BOUNDS = {}
    #: parameter name -> check(name, value) returning the value to store
    _settable = {}

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "__init__" in cls.__dict__:
            cls.__init__ = _sealing(cls.__dict__["__init__"])

    def __init__(self):
        self._version = 0
        self._sim = None

    # Subclasses override -------------------------------------------------------------
    def _pack(self, sim):
        """Return ``(params, indices)``: float64 and int64 1-D arrays of this term's parameters."""
        raise NotImplementedError

    def _check(self, sim):
        """Raise ValueError if this term cannot act in ``sim`` (dimension, indices)."""

    def _kind(self, sim):
        """The kind whose kernels act for this term in ``sim`` (a term with several methods,
        such as ``NBodyGravity(method="tree")``, has one kind a method)."""
        return self.KIND

    @property
    def velocity_dependent(self):
        """True if the acceleration depends on velocities (drag, damping)."""
        return False

    # Shared ---------------------------------------------------------------------------
    def layout(self, sim):
        """``{name: (offset, shape)}`` of each float parameter within this term's packed
        block, for ``sim`` (a Simulation or Batch): how callers read and write parameters by
        name (``Batch.set_parameter``, ``Simulation.parameter``)."""
        sizes = {"dim": sim.dim, "slots": sim.n}
        if any("rows" in spec for _, spec in self.LAYOUT):
            sizes["rows"] = self._rows(sim)
        out = {}
        offset = 0
        for name, spec in self.LAYOUT:
            shape = tuple(len(self) if d == "items" else sizes.get(d, d) for d in spec)
            out[name] = (offset, shape)
            offset += int(np.prod(shape, dtype=np.int64))
        return out

    def _attach(self, sim):
        self._check(sim)
        if self._sim is not None and self._sim is not sim:
            raise ValueError(f"{type(self).__name__} is already attached to another simulation")
        self._sim = sim

    def _touch(self):
        """Mark parameters changed so the next step re-reads them (no stale forces): the
        term's own version and its simulation's revision, which keys the packed model."""
        self._version += 1
        sim = self.__dict__.get("_sim")
        if sim is not None:
            sim._revision += 1

    def __setattr__(self, name, value):
        if name.startswith("_") or isinstance(getattr(type(self), name, None), property):
            object.__setattr__(self, name, value)
            return
        value = read_only(value)
        check = self._settable.get(name)
        if check is None:
            if self.__dict__.get("_sealed", False):
                raise AttributeError(
                    f"{type(self).__name__}.{name} cannot be changed once the term is made; "
                    f"remove it (sim.remove_force) and add a new {type(self).__name__}")
            object.__setattr__(self, name, value)
            return
        value = check(name, value)
        old = self.__dict__.get(name)
        object.__setattr__(self, name, value)
        sim = self.__dict__.get("_sim")
        if sim is not None:
            try:
                self._check(sim)
            except Exception:
                object.__setattr__(self, name, old)
                raise
        # the next step re-packs the parameters
        object.__setattr__(self, "_version", self.__dict__.get("_version", 0) + 1)
        if sim is not None:
            sim._revision += 1

    def __repr__(self):
        return f"{type(self).__name__}()"


class DeclaresTerms:
    """What a Simulation and a Batch share about their force terms: declaring and removing
    them, each change bumping the revision that keys the packed model."""

    #: how the owner names itself in messages ("simulation", "batch")
    _owner = "simulation"

    @property
    def forces(self):
        return tuple(self._forces)

    def add_force(self, force):
        """Declare a force term; it acts from the next step. Returns the term."""
        if not isinstance(force, Force):
            raise TypeError(f"force must be an engine.forces term, got {force!r}")
        if any(f is force for f in self._forces):
            raise ValueError(f"{force!r} is already declared in this {self._owner}")
        force._attach(self)
        self._forces.append(force)
        self._revision += 1
        return force

    def remove_force(self, force):
        """Remove a declared term; it stops acting from the next step."""
        for k, f in enumerate(self._forces):
            if f is force:
                del self._forces[k]
                force._sim = None
                self._forgotten(force)
                self._revision += 1
                return
        raise ValueError(f"{force!r} is not declared in this {self._owner}")

    def _forgotten(self, force):
        """Called when ``force`` is removed (a batch drops its per-system values)."""

    def _term_slot(self, model, term, name):
        """``(slice, shape)`` of ``term``'s parameter ``name`` in the packed parameters."""
        for k, f in enumerate(self._forces):
            if f is term:
                layout = term.layout(self)
                if name not in layout:
                    raise ValueError(f"{type(term).__name__} has no parameter {name!r}; its "
                                     f"parameters are {', '.join(layout)}")
                start, shape = layout[name]
                start += int(model.param_offsets[k])
                size = int(np.prod(shape, dtype=np.int64))
                return slice(start, start + size), shape
        raise ValueError(f"{term!r} is not declared in this {self._owner}")


def particle_list(name, particles):
    """Optional particle indices of a term: EMPTY_INTS for None (every particle), else a
    non-empty 1-D int array without repeats."""
    if particles is None:
        return EMPTY_INTS
    indices = index_array(name, particles).reshape(-1)
    if indices.size == 0:
        raise ValueError(f"{name} must list at least one index (None means all)")
    if np.unique(indices).size != indices.size:
        raise ValueError(f"{name} must not repeat an index, got {indices.tolist()}")
    return indices


def check_particles(name, indices, sim):
    """Raise ValueError if an index of ``indices`` is out of ``sim``'s range."""
    if indices.shape[0] == 0 or (indices.min() >= 0 and indices.max() < sim.n):
        return  # the common case, checked without a temporary mask
    bad = (indices < 0) | (indices >= sim.n)
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name}[{k}] = {indices[k]} is out of range "
                         f"(the simulation has {sim.n} particles)")


def read_only(value):
    """A read-only view of an array (the caller's own array keeps its flags)."""
    if isinstance(value, np.ndarray):
        value = value.view()
        value.flags.writeable = False
    return value


def floats(*values):
    return np.array(values, dtype=np.float64)


def ints(*values):
    return np.array(values, dtype=np.int64)


EMPTY_INTS = np.zeros(0, dtype=np.int64)
EMPTY_FLOATS = np.zeros(0, dtype=np.float64)
EMPTY_INTS.flags.writeable = False
EMPTY_FLOATS.flags.writeable = False
