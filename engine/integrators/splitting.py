"""Symplectic splitting methods: sequences of drifts (p += c h v) and kicks (v += d h a).

One compiled executor runs any sequence of stages ``(drift c_k, then kick d_k)``:

- ``symplectic_euler``: kick 1, drift 1 (the lecture's worked table; velocity first).
- ``leapfrog``: drift 1/2, kick 1, drift 1/2 (drift-kick-drift, REBOUND's leapfrog).
- ``verlet``: kick 1/2, drift 1, kick 1/2 (velocity Verlet, kick-drift-kick).
- ``yoshida4``: the triple jump of ``verlet`` with w1 = 1/(2 - 2^(1/3)), w0 = 1 - 2 w1
  (Yoshida 1990; Forest & Ruth 1990), the adjacent half kicks merged.
- ``pefrl``: position-extended Forest-Ruth-like, xi, lambda, chi from Omelyan, Mryglod & Folk,
  Comput. Phys. Commun. 146 (2002) 188, eq. (20).

The acceleration is recomputed only when positions moved since the last evaluation (or, for
velocity-dependent forces, when velocities moved): so ``verlet`` costs one evaluation per step
inside a ``step(n)`` call, like ``leapfrog``. Each call starts with a fresh evaluation, so a
force changed between calls acts at once. Forces are evaluated at the time the positions
have reached (matters only for time-dependent terms such as a blast).

A few bodies under gravity alone take the fused executor of ``fused_gravity`` instead: the
same operations, bit for bit, without the general machinery's cost per step.
"""
import numpy as np
from ..cache import jit

from ..forces.dispatch import accelerations
from . import fused_gravity
from .common import OK, all_finite, copy_state, drift, fill_active_mask, first_nonfinite, kick

_W1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
_W0 = 1.0 - 2.0 * _W1
_XI = 0.1786178958448091
_LAMBDA = -0.2123418310626054
_CHI = -0.06626458266981849

#: name -> (drift coefficients, kick coefficients, order); stage k drifts then kicks.
SCHEMES = {
    "symplectic_euler": ((0.0, 1.0), (1.0, 0.0), 1),
    "leapfrog": ((0.5, 0.5), (1.0, 0.0), 2),
    "verlet": ((0.0, 1.0), (0.5, 0.5), 2),
    "yoshida4": ((0.0, _W1, _W0, _W1),
                 (0.5 * _W1, 0.5 * (_W1 + _W0), 0.5 * (_W0 + _W1), 0.5 * _W1), 4),
    "pefrl": ((_XI, _CHI, 1.0 - 2.0 * (_CHI + _XI), _CHI, _XI),
              (0.5 * (1.0 - 2.0 * _LAMBDA), _LAMBDA, _LAMBDA, 0.5 * (1.0 - 2.0 * _LAMBDA), 0.0),
              4),
}


def coefficients(name):
    """The (drift, kick) coefficient arrays of a named scheme."""
    c, d, _ = SCHEMES[name]
    return np.array(c, dtype=np.float64), np.array(d, dtype=np.float64)


def force_evaluations(name):
    """Force evaluations per step inside one call, with position-only forces.

    A scheme that starts with a kick and ends with a kick (verlet, yoshida4) reuses the last
    evaluation of a step as the first of the next (first same as last).
    """
    c, d, _ = SCHEMES[name]
    kicks = sum(1 for x in d if x)
    starts_with_kick = c[0] == 0.0 and d[0] != 0.0
    ends_with_kick = d[-1] != 0.0
    return kicks - (1 if starts_with_kick and ends_with_kick else 0)


@jit(inline="always")
def scratch_rows(dim):
    """Rows of the scratch ``advance_general_in`` needs for a system of dimension ``dim``: the
    accelerations, the saved positions and velocities (dim rows each) and the motion mask."""
    return 3 * dim + 1


@jit(error_model="numpy")
def advance(t, h, steps, state, model, work, vdep, t_end, drifts, kicks):
    """``steps`` steps of the scheme (drift ``drifts[k] h``, then kick ``kicks[k] h``)."""
    if fused_gravity.applies(state, model):
        f0 = model.param_offsets[0]
        return fused_gravity.advance(t, h, steps, state.pos, state.vel, state.mass, state.active,
                                     state.n, model.params[f0], model.params[f0 + 1], drifts, kicks)
    return advance_general(t, h, steps, state, model, work, vdep, t_end, drifts, kicks)


@jit(error_model="numpy")
def advance_general(t, h, steps, state, model, work, vdep, t_end, drifts, kicks):
    """``advance`` by the general executor alone: what a scene the fused executor cannot take
    runs (chosen in Python by ``engine.integrators.advance``, so that such a scene never
    compiles the fused executor)."""
    scratch = np.empty((scratch_rows(state.pos.shape[0]), state.n))
    # the force table called, not inlined: inlined into this loop it made a step of the Kepler
    # problem about 4x slower (475 against 122 ns, symplectic Euler, same bits)
    return _advance_general(t, h, steps, state, model, work, vdep, drifts, kicks, scratch,
                            accelerations)


@jit(error_model="numpy", _nrt=False, inline="always")
def advance_general_in(t, h, steps, state, model, work, vdep, drifts, kicks, scratch, accelerate):
    """``advance`` by the general executor alone (the fused path gives the same bits for the
    scenes it takes), in caller-owned ``scratch`` of at least ``scratch_rows(dim)`` rows and
    ``n`` columns, with the caller's force function ``accelerate(t, state, model, acc, work)``
    (``engine.forces.dispatch.accelerations_inline``, or one that names the terms its caller
    always declares, so that their kernels are inlined). Compiled without reference counting
    (``_nrt=False``, as the force kernels are: it allocates nothing) and inlined into its
    caller: a compiled caller stepping many small systems (the game's matches) allocates
    nothing per system and pays no call per system."""
    return _advance_general(t, h, steps, state, model, work, vdep, drifts, kicks, scratch,
                            accelerate)


@jit(error_model="numpy", inline="always")
def _advance_general(t, h, steps, state, model, work, vdep, drifts, kicks, scratch, accelerate):
    """The general executor, the forces of every declared term from ``accelerate`` (called,
    or inlined into the loop by a caller that passes an inlined function: the same
    arithmetic either way)."""
    pos = state.pos
    vel = state.vel
    active = state.active
    n = state.n
    box = state.box
    # Hot-loop rules for numba: every helper is inlined and no array variable is rebound or
    # sliced inside the loop, since each of those costs atomic reference-count updates that
    # would outweigh the physics of a small system many times over.
    dim = pos.shape[0]
    acc = scratch[0:dim]
    save_pos = scratch[dim:2 * dim]
    save_vel = scratch[2 * dim:3 * dim]
    mask = scratch[3 * dim]
    fill_active_mask(mask, active, state.pinned, n)
    fresh = False  # does acc hold the forces of the current state?
    t0 = t
    for step in range(steps):
        copy_state(pos, vel, save_pos, save_vel, n)
        t_pos = t
        for s in range(drifts.shape[0]):
            if drifts[s] != 0.0:
                drift(pos, vel, mask, n, drifts[s] * h, box)
                t_pos += drifts[s] * h
                fresh = False
            if kicks[s] != 0.0:
                if not fresh:
                    accelerate(t_pos, state, model, acc, work)
                    fresh = True
                kick(vel, acc, mask, n, kicks[s] * h)
                if vdep:
                    fresh = False
        if not all_finite(pos, vel, n):
            status = first_nonfinite(pos, vel, active, n)
            if status >= 0:
                copy_state(save_pos, save_vel, pos, vel, n)
                return t, h, step, status
        t = t0 + (step + 1) * h
    return t, h, steps, OK
