"""Conserved quantities: energy, linear and angular momentum (active particles only).

    K = sum 1/2 m_i |v_i|^2,   P = sum m_i v_i,   L = sum m_i p_i x v_i

The potential energy is the sum of the declared conservative force terms' potentials (see
``engine.forces``); non-conservative terms (drag, thrust, wind, blast) have none. In 2-D the
angular momentum is the scalar z component.
"""
import numpy as np
from .cache import jit


@jit(error_model="numpy")
def kinetic_energy(vel, mass, active, n):
    e = 0.0
    for i in range(n):
        if active[i]:
            v2 = 0.0
            for k in range(vel.shape[0]):
                v2 += vel[k, i] * vel[k, i]
            e += 0.5 * mass[i] * v2
    return e


@jit(error_model="numpy")
def momentum(vel, mass, active, n):
    p = np.zeros(vel.shape[0])
    for i in range(n):
        if active[i]:
            for k in range(vel.shape[0]):
                p[k] += mass[i] * vel[k, i]
    return p


@jit(error_model="numpy")
def angular_momentum(pos, vel, mass, active, n):
    """L about the origin: shape (3,) in 3-D; in 2-D a length-1 array holding L_z."""
    dim = pos.shape[0]
    out = np.zeros(3 if dim == 3 else 1)
    for i in range(n):
        if not active[i]:
            continue
        m = mass[i]
        if dim == 3:
            out[0] += m * (pos[1, i] * vel[2, i] - pos[2, i] * vel[1, i])
            out[1] += m * (pos[2, i] * vel[0, i] - pos[0, i] * vel[2, i])
            out[2] += m * (pos[0, i] * vel[1, i] - pos[1, i] * vel[0, i])
        else:
            out[0] += m * (pos[0, i] * vel[1, i] - pos[1, i] * vel[0, i])
    return out


@jit(error_model="numpy")
def center_of_mass(pos, vel, mass, active, n):
    """(position, velocity) of the centre of mass of the active particles."""
    dim = pos.shape[0]
    cp = np.zeros(dim)
    cv = np.zeros(dim)
    total = 0.0
    for i in range(n):
        if active[i]:
            total += mass[i]
            for k in range(dim):
                cp[k] += mass[i] * pos[k, i]
                cv[k] += mass[i] * vel[k, i]
    if total > 0.0:
        cp /= total
        cv /= total
    return cp, cv
