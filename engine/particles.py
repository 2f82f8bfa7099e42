"""Structure-of-arrays particle storage.

Every per-particle quantity is its own contiguous array. Positions and velocities are stored
component-major, shape ``(dim, capacity)``, so a force kernel reads all x, then all y, as
contiguous runs (what SIMD wants); the public ``(N, dim)`` arrays are transposed views of the
same memory, so writing ``sim.pos[i] = ...`` writes the engine's state.

Particles are appended into spare capacity (the arrays double when full) and deactivated by a
flag, so torpedoes can appear and vanish between steps without rebuilding anything. Inactive
particles feel no force, exert none, do not move, and are left out of the diagnostics.
"""
import numpy as np

from .state import State


class Particles:
    """The particle arrays of one simulation (``n`` used slots out of ``capacity``)."""

    def __init__(self, dim, capacity=16):
        self.dim = dim
        self.n = 0
        self._allocate(max(int(capacity), 1))

    def _allocate(self, capacity):
        self._state = None  # the kept State holds the old arrays
        old_n = self.n
        fresh = {
            "pos": np.zeros((self.dim, capacity)),
            "vel": np.zeros((self.dim, capacity)),
            "mass": np.zeros(capacity),
            "charge": np.zeros(capacity),
            "radius": np.zeros(capacity),
            "active": np.zeros(capacity, dtype=np.bool_),
            "test": np.zeros(capacity, dtype=np.bool_),
            "pinned": np.zeros(capacity, dtype=np.bool_),
        }
        for name, arr in fresh.items():
            if old_n:
                old = getattr(self, name)
                arr[..., :old_n] = old[..., :old_n]
            setattr(self, name, arr)
        self.capacity = capacity

    def reserve(self, count):
        """Make room for ``count`` more particles (amortised doubling)."""
        need = self.n + count
        if need > self.capacity:
            self._allocate(max(need, 2 * self.capacity))

    def append(self, pos, vel, mass, charge, radius, test, pinned):
        """Append validated arrays of ``k`` particles; return their indices."""
        k = mass.shape[0]
        self.reserve(k)
        s = slice(self.n, self.n + k)
        self.pos[:, s] = pos.T
        self.vel[:, s] = vel.T
        self.mass[s] = mass
        self.charge[s] = charge
        self.radius[s] = radius
        self.test[s] = test
        self.pinned[s] = pinned
        self.vel[:, s][:, pinned] = 0.0
        self.active[s] = True
        self.n += k
        return np.arange(s.start, s.stop)

    def state(self, box):
        """The arrays as the ``engine.state.State`` the kernels take (views of this storage),
        made again only when the arrays, the count or ``box`` changed (a simulation stepping
        in short calls, a game frame, asks for it on every call)."""
        state = self._state
        if state is None or state.box != box or state.n != self.n:
            state = self._state = State(self.pos, self.vel, self.mass, self.charge,
                                        self.radius, self.active, self.test, self.pinned,
                                        int(self.n), float(box))
        return state
