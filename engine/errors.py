"""Exceptions raised by the engine."""


class SimulationError(RuntimeError):
    """A step produced a non-finite state (or an adaptive step size collapsed).

    The simulation keeps the last finite state: positions, velocities and time are those
    from before the failing step. Attributes name where it happened:

    - ``step``: global index of the failing step (``sim.steps`` counted from 0),
    - ``time``: simulation time of the last finite state,
    - ``particle``: index of the first particle found non-finite (``None`` if unknown).
    """

    def __init__(self, message, *, step=None, time=None, particle=None):
        super().__init__(message)
        self.step = step
        self.time = time
        self.particle = particle


class Collision(SimulationError):
    """Two particles touched in a simulation whose collisions say ``resolve="halt"``.

    A ``SimulationError`` (a step that could not be completed as asked), with the state left
    as it was at the start of the step in which they touched; the contacts of the call before
    that step stay in ``sim.contacts``. Besides ``step``, ``time`` (the time of contact, inside
    that step) and ``particle`` (the pair's lower index), it carries:

    - ``pair``: the two indices ``(i, j)``, ``i < j``;
    - ``speed``: the normal component of their relative velocity as they touched.
    """

    def __init__(self, message, *, pair, time, speed, step=None):
        super().__init__(message, step=step, time=time, particle=pair[0])
        self.pair = pair
        self.speed = speed
