"""Integrators: one module per family, one call shape for all.

``advance(name, t, h, steps, state, model, vdep, t_end, tol)`` runs ``steps`` steps in compiled
code and returns ``(t, h_next, done, status)`` (see ``common``; ``state`` and ``model`` are the
named tuples of ``engine.state``).
"""
import numpy as np

from ..forces.pairwise import workspace
from . import dormand_prince, euler, runge_kutta, splitting

#: every integrator name, in the order of the documentation
INTEGRATORS = ("euler", "symplectic_euler", "leapfrog", "verlet", "rk4", "yoshida4", "pefrl", "rk45")

#: order of accuracy of each integrator (global error ~ dt^order)
ORDERS = {
    "euler": euler.ORDER, "rk4": runge_kutta.ORDER, "rk45": dormand_prince.ORDER,
    **{name: scheme[2] for name, scheme in splitting.SCHEMES.items()},
}

#: integrators that conserve a modified energy (bounded energy error) for conservative forces
SYMPLECTIC = ("symplectic_euler", "leapfrog", "verlet", "yoshida4", "pefrl")

#: force evaluations per step (inside one call, position-only forces; rk45: per attempt)
FORCE_EVALUATIONS = {
    "euler": euler.FORCE_EVALUATIONS, "rk4": runge_kutta.FORCE_EVALUATIONS, "rk45": 6,
    **{name: splitting.force_evaluations(name) for name in splitting.SCHEMES},
}

_COEFFICIENTS = {name: splitting.coefficients(name) for name in splitting.SCHEMES}


def check_name(name):
    if name not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {', '.join(INTEGRATORS)}; got {name!r}")
    return name


def advance(name, t, h, steps, state, model, vdep, t_end=np.nan, tol=1e-9, work=None):
    """Advance ``state`` by ``steps`` steps of integrator ``name``; see ``common``.

    ``state`` and ``model`` are the ``engine.state`` named tuples (``sim.kernel_arguments()``);
    ``work`` defaults to a fresh ``pairwise.workspace(state.n)``.
    """
    if work is None:
        work = workspace(state.n)
    if name in _COEFFICIENTS:
        return splitting.advance(t, h, steps, state, model, work, vdep, t_end, *_COEFFICIENTS[name])
    if name == "euler":
        return euler.advance(t, h, steps, state, model, work, vdep, t_end)
    if name == "rk4":
        return runge_kutta.advance(t, h, steps, state, model, work, vdep, t_end)
    return dormand_prince.advance(t, h, steps, state, model, work, vdep, t_end, tol)
