"""Integrators: one module per family, one call shape for all.

``advance(name, t, h, steps, state, model, vdep, t_end, tol)`` runs ``steps`` steps in compiled
code and returns ``(t, h_next, done, status)`` (see ``common``; ``state`` and ``model`` are the
named tuples of ``engine.state``).
"""
import numpy as np

from ..forces import gravity
from ..forces.pairwise import workspace
from . import direct as _direct
from . import dormand_prince, euler, ias15, janus, runge_kutta, splitting, wisdom_holman

#: the integrators that work on any scene (and in ``engine.Batch``)
GENERAL = ("euler", "symplectic_euler", "leapfrog", "verlet", "rk4", "yoshida4", "pefrl", "rk45")
#: every integrator name, in the order of the documentation
INTEGRATORS = GENERAL + ("whfast", "saba", "ias15", "janus")
#: the integrators that choose their own steps (``dt`` is only the first)
ADAPTIVE_INTEGRATORS = ("rk45", "ias15")
#: integrators built on a dominant mass (Kepler drifts); a scene without one is refused
KEPLER_SPLITTING = ("whfast", "saba")
#: the integrators that take any scene (``engine.Batch`` runs the ``GENERAL`` ones)
ANY_SCENE = tuple(name for name in INTEGRATORS if name not in KEPLER_SPLITTING)

#: order of accuracy of each integrator (global error ~ dt^order)
ORDERS = {
    "euler": euler.ORDER, "rk4": runge_kutta.ORDER, "rk45": dormand_prince.ORDER,
    **{name: scheme[2] for name, scheme in splitting.SCHEMES.items()},
    "whfast": wisdom_holman.ORDER,
    "saba": 4,  # the default SABA(10,6,4): error O(eps h^10 + eps^2 h^6 + eps^3 h^4)
    "ias15": ias15.ORDER,
    "janus": 6,  # the default janus_order
}

#: integrators that conserve a modified energy (bounded energy error) for conservative forces
SYMPLECTIC = ("symplectic_euler", "leapfrog", "verlet", "yoshida4", "pefrl", "whfast", "saba",
              "janus")

#: force evaluations per step (inside one call, position-only forces; rk45: per attempt)
FORCE_EVALUATIONS = {
    "euler": euler.FORCE_EVALUATIONS, "rk4": runge_kutta.FORCE_EVALUATIONS, "rk45": 6,
    **{name: splitting.force_evaluations(name) for name in splitting.SCHEMES},
    "whfast": 1,  # the standard kernel without corrector (the lazy kernel: 2)
    "saba": 8,  # the default SABA(10,6,4); SABAn: n, SABACn: n + 2
    "ias15": 22,  # typical at epsilon 1e-9: 1 + 7 per predictor-corrector iteration
    "janus": janus.FORCE_EVALUATIONS[6],  # the default janus_order; 1, 5, 9, 15 for 2-8
}

_COEFFICIENTS = {name: splitting.coefficients(name) for name in splitting.SCHEMES}


def check_name(name):
    if name not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {', '.join(INTEGRATORS)}; got {name!r}")
    return name


def _dispatch_call(dispatcher, args):
    return dispatcher(*args)


def advance_kepler_splitting(name, t, h, steps, state, plan, vdep, t_end=np.nan, corrector=0,
                             kernel="standard", saba=wisdom_holman.DEFAULT_SABA, work=None,
                             direct=False):
    """``advance`` for ``whfast`` and ``saba`` (``plan``: the scene's ``wisdom_holman.Plan``),
    with no other integrator's arguments to pass: a ``Simulation`` stepping in short calls
    takes this path."""
    if work is None:
        work = workspace(state.n)
    run = _direct.call if direct else _dispatch_call
    return run(wisdom_holman.advance,
               (float(t), float(h), int(steps), state, plan.kick_model, work, bool(vdep),
                float(t_end)) + plan.kernel_tail(name, corrector, kernel, saba))


def advance(name, t, h, steps, state, model, vdep, t_end=np.nan, tol=1e-9, work=None,
            plan=None, corrector=0, kernel="standard", saba=wisdom_holman.DEFAULT_SABA,
            memory=None, janus_order=6, lattice=None, counts=None, direct=False):
    """Advance ``state`` by ``steps`` steps of integrator ``name``; see ``common``.

    ``state`` and ``model`` are the ``engine.state`` named tuples (``sim.kernel_arguments()``);
    ``work`` defaults to a fresh ``pairwise.workspace(state.n)``. ``whfast`` and ``saba`` also
    take the ``wisdom_holman.Plan`` of the scene; ``whfast`` its ``corrector`` order and its
    ``kernel``, ``saba`` the name of its method; ``ias15`` its ``memory``
    (``ias15.new_memory``, kept between calls); ``janus`` its order and ``lattice`` exponents
    ``(kx, kv)`` (``janus.lattice_exponents``). ``direct``: the arguments are a
    ``Simulation``'s own, of fixed types, so whfast, saba and ias15 skip numba's type
    dispatch (``engine.integrators.direct``).
    """
    if name in ("whfast", "saba"):
        return advance_kepler_splitting(name, t, h, steps, state, plan, vdep, t_end, corrector,
                                        kernel, saba, work, direct)
    if work is None:
        work = workspace(state.n)
    run = _direct.call if direct else _dispatch_call
    if name in _COEFFICIENTS:
        # only a scene of one gravity term can take the fused executor: any other compiles
        # and runs the general one alone
        kinds = model.kinds
        fusable = kinds.shape[0] == 1 and kinds[0] == gravity.KIND
        executor = splitting.advance if fusable else splitting.advance_general
        return executor(t, h, steps, state, model, work, vdep, t_end, *_COEFFICIENTS[name])
    if name == "euler":
        return euler.advance(t, h, steps, state, model, work, vdep, t_end)
    if name == "ias15":
        if memory is None:
            memory = ias15.new_memory(state.pos.shape[0], state.n)
        return run(ias15.advance, (float(t), float(h), int(steps), state, model, work,
                                   bool(vdep), float(t_end), float(tol), memory))
    if name == "janus":
        kx, kv = (janus.lattice_exponents(state.pos, state.vel, state.n, box=state.box,
                                          active=state.active, pinned=state.pinned)
                  if lattice is None else lattice)
        return janus.advance(t, h, steps, state, model, work, vdep, t_end, janus_order, kx, kv)
    if name == "rk4":
        return runge_kutta.advance(t, h, steps, state, model, work, vdep, t_end)
    if counts is None:
        counts = np.zeros(1, dtype=np.int64)
    return dormand_prince.advance_counted(t, h, steps, state, model, work, vdep, t_end, tol,
                                          counts)
