"""A batch's steps with contacts: every system steps and resolves its contacts on its own,
whole systems spread over the threads as ``engine.batch.advance_all`` spreads them.

Each step of a system is the integrator's one step followed by that step's contacts
(``events.collide``), exactly as ``Simulation`` takes them, so a system of a batch gives the
same contacts and the same bits as a ``Simulation`` of it. A system whose step halts on a
contact (``resolve="halt"``) or runs into too many contacts is put back to the start of that
step and stops; the others go on.
"""
import numpy as np
from numba import prange

from ..batch import CHUNKS, step_system, system_model, system_state, system_workspace
from ..cache import jit
from .end_of_step import collide_at_end
from .events import DONE, HALTED, MERGE, collide

#: a system's status when a contact halted it, or when one step held too many contacts (the
#: integrators' own codes are -1 for success and >= 0 or other negatives for failures)
HALT_STATUS = -100
TOO_MANY_STATUS = -101


@jit(error_model="numpy")
def _keep(s, n, p0, v0, kept, merging):
    """Copy system state s's positions and velocities (and, when merges may change them,
    masses, charges, radii and flags) into the chunk's buffers. Compiled on its own, as is
    ``_restore``: written inline in the parallel loop, the restoring writes were seen not to
    reach the state (numba 0.68's parallel pass)."""
    for axis in range(p0.shape[0]):
        for k in range(n):
            p0[axis, k] = s.pos[axis, k]
            v0[axis, k] = s.vel[axis, k]
    if merging:
        for k in range(n):
            kept[0, k] = s.mass[k]
            kept[1, k] = s.charge[k]
            kept[2, k] = s.radius[k]
            kept[3, k] = 1.0 if s.active[k] else 0.0


@jit(error_model="numpy")
def _restore(s, n, p0, v0, kept, merged):
    """System state s back to the start of its step (``_keep``'s buffers)."""
    for axis in range(p0.shape[0]):
        for k in range(n):
            s.pos[axis, k] = p0[axis, k]
            s.vel[axis, k] = v0[axis, k]
    if merged:
        for k in range(n):
            s.mass[k] = kept[0, k]
            s.charge[k] = kept[1, k]
            s.radius[k] = kept[2, k]
            s.active[k] = kept[3, k] != 0.0


@jit(parallel=True, error_model="numpy")
def advance_all_colliding(family, t, h, steps, state, model, vdep, tol, drifts, kicks, done,
                          status, resolve, restitution, points, normals, search, records,
                          halts, merge_below, at_end):
    """Every system by ``steps`` steps, each followed by its contacts; ``records[m]`` gets
    system m's contact records, ``halts[m]`` (pair code i * n + j, time, speed) the contact
    that halted it; ``at_end``: contacts resolved at the end of the step
    (``engine.collisions.end_of_step``), else at the moment of contact. ``t``, ``h``,
    ``done`` and ``status`` as ``engine.batch.advance_all``."""
    systems = state.pos.shape[0]
    chunks = min(systems, CHUNKS)
    n = state.n
    dim = state.pos.shape[1]
    for c in prange(chunks):
        work = system_workspace(n)
        p0 = np.empty((dim, n))
        v0 = np.empty((dim, n))
        kept = np.empty((4, n))
        for m in range(c * systems // chunks, (c + 1) * systems // chunks):
            s = system_state(state, m)
            model_m = system_model(model, m)
            record = records[m]
            tm, hm, dm, sm = t[m], h[m], 0, -1
            for _ in range(steps):
                _keep(s, n, p0, v0, kept, resolve == MERGE or merge_below > 0.0)
                t_before = tm
                tm, hm, one, sm = step_system(m, family, tm, hm, 1, state, model, work, vdep,
                                              tol, drifts, kicks)
                if sm != -1:
                    break
                mark = len(record)
                if at_end:
                    code, pair, t_hit, speed = collide_at_end(
                        t_before, tm - t_before, s, model_m, p0, v0, resolve, restitution,
                        points, normals, search, record, merge_below)
                else:
                    code, pair, t_hit, speed = collide(
                        t_before, tm - t_before, s, model_m, p0, v0, resolve, restitution,
                        points, normals, search, record, merge_below)
                if code != DONE:
                    _restore(s, n, p0, v0, kept, resolve == MERGE or merge_below > 0.0)
                    while len(record) > mark:
                        record.pop()
                    tm = t_before
                    sm = HALT_STATUS if code == HALTED else TOO_MANY_STATUS
                    halts[m, 0] = float(pair)
                    halts[m, 1] = t_hit
                    halts[m, 2] = speed
                    break
                dm += one
            t[m] = tm
            h[m] = hm
            done[m] = dm
            status[m] = sm
