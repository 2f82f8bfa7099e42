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
