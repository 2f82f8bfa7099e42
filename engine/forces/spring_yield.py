"""Springs that yield and break: what happens to a ``Springs`` term's rest lengths after each
step (the plastic deformation the lecture names, and fracture).

The strain of a spring is measured against its *current* rest length l:
epsilon = (r - l) / l, r its length now. After every step, for each intact spring with
l > 0:

- past the break strain (|epsilon| > epsilon_b) the spring breaks: its stiffness and damping
  become 0 for good; its elastic energy k (r - l)^2 / 2 leaves the system (into the ledger,
  ``sim.energy_ledger``) and the break is recorded in ``sim.contacts`` (action "break");
- past the yield strain (|epsilon| > epsilon_y) the rest length flows towards the current
  length, dl/dt = lambda (r - l), taken exactly over the step with r held at the step's end
  (l <- r + (l - r) exp(-lambda dt)), and no further than the yield strain itself (the flow
  stops where |epsilon| = epsilon_y): a rate per unit time, so results do not depend on dt
  beyond the step's own error. The elastic energy the flow releases,
  k ((r - l_old)^2 - (r - l_new)^2) / 2, goes into the ledger.

Stretch and compression alike. Because the strain is taken against the current rest length,
a spring loaded slowly flows and does not break (the flow keeps its strain at the yield
strain); one loaded faster than it can flow breaks: a rate-dependent (viscoplastic) model, as
a sail torn by a gust and not by a steady wind.
"""
import math

from ..cache import jit
from ._kernels import delta, delta_periodic

#: the contact record's action code for a break (``engine.collisions.settings.ACTIONS``)
BREAK = 3.0


@jit(error_model="numpy")
def yield_and_break(t, h, pos, vel, active, box, pairs, params, f0, m, yield_strain,
                    break_strain, flow_rate, events):
    """One step's yielding and breaking of the m springs packed at ``params[f0:]`` (k, rest
    length, damping blocks of m), in place. Appends one (time, a, b, stretching speed, BREAK,
    energy, -1) record per break to ``events``; returns the energy yielding released."""
    dim = pos.shape[0]
    released = 0.0
    for s in range(m):
        a = pairs[2 * s]
        b = pairs[2 * s + 1]
        k = params[f0 + s]
        rest = params[f0 + m + s]
        if k == 0.0 or rest <= 0.0 or not (active[a] and active[b]):
            continue
        dx, dy, dz = delta_periodic(pos, a, b, dim, box)
        r = math.sqrt(dx * dx + dy * dy + dz * dz)
        strain = (r - rest) / rest
        if abs(strain) > break_strain[s]:
            dvx, dvy, dvz = delta(vel, a, b, dim)
            speed = (dvx * dx + dvy * dy + dvz * dz) / r if r > 0.0 else 0.0
            energy = 0.5 * k * (r - rest) * (r - rest)
            params[f0 + s] = 0.0
            params[f0 + 2 * m + s] = 0.0
            events.append((t, float(min(a, b)), float(max(a, b)), speed, BREAK, energy, -1.0))
        elif abs(strain) > yield_strain[s]:
            flowed = r + (rest - r) * math.exp(-flow_rate[s] * abs(h))
            if strain > 0.0:
                new = min(flowed, r / (1.0 + yield_strain[s]))
            else:
                new = max(flowed, r / (1.0 - yield_strain[s])) if yield_strain[s] < 1.0 \
                    else flowed
            released += 0.5 * k * ((r - rest) * (r - rest) - (r - new) * (r - new))
            params[f0 + m + s] = new
    return released
