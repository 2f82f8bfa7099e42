"""Small numba helpers the force kernels share."""
from ..cache import jit

from ..space import wrap_scalar as nearest_image


@jit(error_model="numpy", inline="always")
def add_force(acc, i, dim, f0, f1, f2, m):
    """acc_i += f / m_i, skipping an exact zero force so a massless particle with no force
    stays finite (a massless particle *with* a force becomes infinite and the step fails)."""
    if f0 == 0.0 and f1 == 0.0 and f2 == 0.0:
        return
    acc[0, i] += f0 / m
    acc[1, i] += f1 / m
    if dim == 3:
        acc[2, i] += f2 / m


@jit(error_model="numpy", inline="always")
def delta(pos, i, j, dim):
    """The separation p_j - p_i as three floats (z = 0 in 2-D)."""
    dx = pos[0, j] - pos[0, i]
    dy = pos[1, j] - pos[1, i]
    dz = pos[2, j] - pos[2, i] if dim == 3 else 0.0
    return dx, dy, dz


@jit(error_model="numpy", inline="always")
def delta_periodic(pos, i, j, dim, box):
    """p_j - p_i, by the nearest periodic image when ``box`` > 0."""
    dx, dy, dz = delta(pos, i, j, dim)
    return nearest_image(dx, box), nearest_image(dy, box), nearest_image(dz, box)


@jit(error_model="numpy", inline="always")
def pair_box(params, f0, state):
    """The periodic side a pair term (gravity, Coulomb) uses: its own deprecated ``box`` at
    ``params[f0 + 2]`` when set, else the space's."""
    own = params[f0 + 2]
    return own if own > 0.0 else state.box
