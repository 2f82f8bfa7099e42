"""Integrators: one module per family, one call shape for all.

``advance(name, t, h, steps, state, model, vdep, t_end, tol)`` runs ``steps`` steps in compiled
code and returns ``(t, h_next, done, status)`` (see ``common``; ``state`` and ``model`` are the
named tuples of ``engine.state``).
"""
import numpy as np

from ..forces.pairwise import workspace
from . import dormand_prince, euler, runge_kutta, splitting, wisdom_holman

#: the integrators that work on any scene (and in ``engine.Batch``)
GENERAL = ("euler", "symplectic_euler", "leapfrog", "verlet", "rk4", "yoshida4", "pefrl", "rk45")
#: every integrator name, in the order of the documentation
INTEGRATORS = GENERAL + ("whfast",)
#: the integrators that choose their own steps (``dt`` is only the first)
ADAPTIVE_INTEGRATORS = ("rk45",)
#: integrators built on a dominant mass (Kepler drifts); a scene without one is refused
KEPLER_SPLITTING = ("whfast",)

#: order of accuracy of each integrator (global error ~ dt^order)
ORDERS = {
    "euler": euler.ORDER, "rk4": runge_kutta.ORDER, "rk45": dormand_prince.ORDER,
    **{name: scheme[2] for name, scheme in splitting.SCHEMES.items()},
    "whfast": wisdom_holman.ORDER,
}

#: integrators that conserve a modified energy (bounded energy error) for conservative forces
SYMPLECTIC = ("symplectic_euler", "leapfrog", "verlet", "yoshida4", "pefrl", "whfast")

#: force evaluations per step (inside one call, position-only forces; rk45: per attempt)
FORCE_EVALUATIONS = {
    "euler": euler.FORCE_EVALUATIONS, "rk4": runge_kutta.FORCE_EVALUATIONS, "rk45": 6,
    **{name: splitting.force_evaluations(name) for name in splitting.SCHEMES},
    "whfast": 1,  # the standard kernel without corrector (the lazy kernel: 2)
}

_COEFFICIENTS = {name: splitting.coefficients(name) for name in splitting.SCHEMES}


def check_name(name):
    if name not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {', '.join(INTEGRATORS)}; got {name!r}")
    return name


def advance(name, t, h, steps, state, model, vdep, t_end=np.nan, tol=1e-9, work=None,
            plan=None, corrector=0, kernel="standard"):
    """Advance ``state`` by ``steps`` steps of integrator ``name``; see ``common``.

    ``state`` and ``model`` are the ``engine.state`` named tuples (``sim.kernel_arguments()``);
    ``work`` defaults to a fresh ``pairwise.workspace(state.n)``. ``whfast`` also takes the
    ``wisdom_holman.Plan`` of the scene, its ``corrector`` order and its ``kernel``.
    """
    if work is None:
        work = workspace(state.n)
    if name == "whfast":
        return wisdom_holman.advance(t, h, steps, state, plan.kick_model, work, vdep, t_end,
                                     *plan.arguments(), plan.kick_com,
                                     wisdom_holman.KERNELS[kernel],
                                     wisdom_holman.corrector_table(corrector))
    if name in _COEFFICIENTS:
        return splitting.advance(t, h, steps, state, model, work, vdep, t_end, *_COEFFICIENTS[name])
    if name == "euler":
        return euler.advance(t, h, steps, state, model, work, vdep, t_end)
    if name == "rk4":
        return runge_kutta.advance(t, h, steps, state, model, work, vdep, t_end)
    return dormand_prince.advance(t, h, steps, state, model, work, vdep, t_end, tol)
