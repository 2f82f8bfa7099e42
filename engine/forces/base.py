"""What every force term shares: packing its parameters for the compiled dispatcher.

A force term is a Python object holding its parameters plus two numba kernels in its module:
``accumulate(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0, i1, acc)``
adds its acceleration into ``acc`` and ``potential(...)`` (the same arguments but ``acc``)
returns its potential energy (0.0 when the term is not conservative). The term's float
parameters are ``fp[f0:f1]`` and its integer ones ``ip[i0:i1]``. The simulation concatenates all declared terms into
one table so that a step calls one compiled function and pays only for the declared terms.
"""
import numpy as np


class Force:
    """Base class of force terms. Subclasses set ``KIND`` and implement ``_pack``."""

    KIND = -1
    #: True if the term has a potential that ``sim.potential_energy()`` sums.
    conservative = False

    def __init__(self):
        self._version = 0
        self._sim = None

    # Subclasses override -------------------------------------------------------------
    def _pack(self, sim):
        """Return ``(fp, ip)``: float64 and int64 1-D arrays of this term's parameters."""
        raise NotImplementedError

    def _check(self, sim):
        """Raise ValueError if this term cannot act in ``sim`` (dimension, indices)."""

    @property
    def velocity_dependent(self):
        """True if the acceleration depends on velocities (drag, damping)."""
        return False

    # Shared ---------------------------------------------------------------------------
    def _attach(self, sim):
        self._check(sim)
        if self._sim is not None and self._sim is not sim:
            raise ValueError(f"{type(self).__name__} is already attached to another simulation")
        self._sim = sim

    def _touch(self):
        """Mark parameters changed so the next step re-reads them (no stale forces)."""
        self._version += 1

    def __setattr__(self, name, value):
        # assigning a public parameter (drag.linear = 0.5) must act from the next step on
        object.__setattr__(self, name, value)
        if not name.startswith("_") and "_version" in self.__dict__:
            self._version += 1

    def __repr__(self):
        return f"{type(self).__name__}()"


def floats(*values):
    return np.array(values, dtype=np.float64)


def ints(*values):
    return np.array(values, dtype=np.int64)


EMPTY_INTS = np.zeros(0, dtype=np.int64)
EMPTY_FLOATS = np.zeros(0, dtype=np.float64)
