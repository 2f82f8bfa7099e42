"""One periodic space: the torus [-L/2, L/2)^dim, its wrap and its nearest image.

A simulation or batch declares its space once (``Simulation(box=L)``); every part of the engine
that needs it uses these two functions: the drift wraps positions after moving them, and every
pair force (gravity, Coulomb) and the game's collisions take separations by the nearest image.
jax-md's ``space.periodic(side)`` (one displacement and one shift function shared by every
energy; Schoenholz & Cubuk, NeurIPS 2020) is the model.

    wrap(x, L)           = x - L floor(x (1/L) + 1/2)     in [-L/2, L/2) (a point exactly on
                                                          the edge may round to +L/2 when L
                                                          is not a power of two)
    nearest_image(d, L)  = the same map applied to a separation d = x_j - x_i

With ``L = 0`` (open space) both return their argument unchanged. ``wrap`` and
``nearest_image`` take floats or numpy arrays from Python; compiled code inlines ``image`` (any
float precision) or ``wrap_scalar`` (float64), the same formula.
"""
import numpy as np
from .cache import jit

from ._validate import nonnegative_float, optional


def wrap(x, side):
    """``x`` (a float or an array) mapped onto [-side/2, side/2); unchanged when ``side`` is 0.

    For Python callers (bots, drawing); compiled callers inline ``image``/``wrap_scalar``,
    the same formula, bit for bit (a test holds them to it)."""
    if side > 0.0:
        return x - side * np.floor(x * (1.0 / side) + 0.5)
    return x


def nearest_image(d, side):
    """The separation ``d`` (a float or an array, d = x_j - x_i) by its shortest periodic
    image: ``wrap`` applied to a difference."""
    return wrap(d, side)


@jit(error_model="numpy", inline="always")
def period_shift(x, side, half):
    """The whole periods ``side * floor(x * (1 / side) + 1/2)`` that ``wrap`` takes off ``x``
    (``side`` > 0; ``half`` is 1/2 in the precision of ``x``). A multiplication by the
    reciprocal, which a loop computes once, rather than a division per coordinate: four
    times cheaper in the vectorised drift, and exact for a side that is a power of two."""
    return side * np.floor(x * ((half + half) / side) + half)


@jit(error_model="numpy", inline="always")
def image(x, side, half):
    """``wrap`` for one number, inlined into compiled callers (the drift, the pair loops).

    ``half`` is 1/2 in the precision of ``x`` (a float32 pair loop stays in float32)."""
    if side > 0.0:
        return x - period_shift(x, side, half)
    return x


@jit(error_model="numpy", inline="always")
def wrap_scalar(x, side):
    """``wrap`` for one float64, inlined into compiled callers."""
    return image(x, side, 0.5)


def check_box(box):
    """The side of a periodic space as a float: ``None`` or 0 means open space (0.0), so
    ``Simulation(box=sim.box)`` copies any simulation's space."""
    value = optional(nonnegative_float)("box", box)
    return 0.0 if value is None else value


__all__ = ["wrap", "nearest_image", "image", "period_shift", "wrap_scalar", "check_box"]
