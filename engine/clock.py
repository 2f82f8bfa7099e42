"""Fixed-step simulation clock: turns wall-clock time into whole physics steps.

The game renders at whatever rate the display and GPU allow, but the physics
must advance in whole, fixed steps of ``dt`` so that it stays stable and
reproducible.  This module implements the "accumulator" pattern described by
Glenn Fiedler in "Fix Your Timestep!" (Gaffer On Games, 2004,
https://gafferongames.com/post/fix_your_timestep/):

* every frame, the elapsed wall time (scaled by ``time_scale``) is added to an
  accumulator;
* as many whole steps of ``dt`` as fit in the accumulator are taken, and
  their time is removed from it;
* what is left over (less than one step) is kept for the next frame and also
  gives ``alpha = |accumulator| / dt``, the fraction by which the renderer
  blends the previous and the current physics state;
* the number of steps per frame is capped (``max_steps_per_frame``) so a slow
  frame cannot trigger ever longer frames (the "spiral of death"); the excess
  backlog is dropped and counted in ``dropped``.

Beyond the article, the clock supports slow motion, fast forward, pause and
reverse (negative ``time_scale``), and never reads wall time unless asked to:
``tick(wall_elapsed)`` with an explicit value is a pure function of its inputs,
so replays and tests are deterministic.  Only ``tick()`` with no argument reads
the ``clock`` callable (``time.perf_counter`` by default).

Inputs are checked by the engine's shared helpers (``engine._validate``), so a bad
value raises what it raises anywhere in the engine: TypeError for text, booleans or None
given as a number, ValueError for a non-finite or out-of-range number, both naming the
field and the value.  ``interpolate`` works on anything that supports ``+``, ``-`` and
multiplication by a float, e.g. numpy arrays.
"""

from __future__ import annotations

import math
import time
from fractions import Fraction
from typing import Any, Callable, Optional

from ._validate import finite_float, nonnegative_float, positive_float, step_count

__all__ = ["FixedStepClock", "STEP_TOLERANCE"]

#: Relative tolerance (a fraction of ``dt``) within which an accumulator that is
#: just short of a whole step still counts as that step.  See
#: ``FixedStepClock.tick`` for why it exists and why this value is safe.
STEP_TOLERANCE = 1e-9

_STEP_TOLERANCE_Q = Fraction(STEP_TOLERANCE)


class FixedStepClock:
    """Accumulator clock that converts elapsed wall time into fixed steps.

    Parameters
    ----------
    dt:
        Simulation step in seconds; a positive, finite number.
    time_scale:
        Simulated seconds per wall second: 1 real time, 0.5 slow motion,
        4 fast forward, 0 frozen, negative runs the simulation backwards
        (``tick`` then returns negative step counts).
    max_steps_per_frame:
        Largest number of steps a single ``tick`` may return (in absolute
        value); an int >= 1.  Backlog beyond it is dropped (see ``dropped``).
    clock:
        Zero-argument callable returning seconds, read only by ``tick()``
        without an argument.  Defaults to ``time.perf_counter``.

    State
    -----
    ``steps``: net signed number of steps returned so far.
    ``sim_time``: ``steps * dt``, the simulated time reached by the physics.
    ``alpha``: ``|accumulator| / dt`` in [0, 1), the render blend factor.
    ``dropped`` / ``dropped_steps``: simulated seconds / whole steps thrown
    away by the cap (always counted as positive magnitudes).
    ``ticks``: number of ``tick`` calls.  ``last_steps``: result of the last.
    """

    def __init__(
        self,
        dt: float,
        time_scale: float = 1.0,
        max_steps_per_frame: int = 8,
        clock: Optional[Callable[[], float]] = None,
    ) -> None:
        dt_f = positive_float("dt", dt)
        max_steps = step_count("max_steps_per_frame", max_steps_per_frame, minimum=1)
        if clock is None:
            clock = time.perf_counter
        if not callable(clock):
            raise TypeError(f"clock must be callable, got {clock!r} ({type(clock).__name__})")

        self._dt = dt_f
        # Exact rational copy of the float dt (every float is a dyadic
        # rational, so Fraction(float) loses nothing).
        self._dt_q = Fraction(dt_f)
        self._time_scale = finite_float("time_scale", time_scale)
        self._max_steps = max_steps
        self._clock = clock
        self._paused = False

        # Signed simulated time not yet turned into steps, kept as an exact
        # rational (see ``tick``).  Invariant: |accumulator| < dt.
        self._accumulator = Fraction(0)
        self._steps = 0
        self._dropped_q = Fraction(0)
        self.dropped_steps = 0
        self.ticks = 0
        self.last_steps = 0
        # Wall-clock reading at the previous clock-driven tick; None until a
        # clock-driven tick establishes it.
        self._last_wall: Optional[float] = None

    # ------------------------------------------------------------------
    # Configuration
    # ------------------------------------------------------------------
    @property
    def dt(self) -> float:
        """The fixed simulation step in seconds (read-only).

        Changing dt mid-run would change the meaning of the accumulator and of
        ``sim_time = steps * dt``; make a new clock instead.
        """
        return self._dt

    @property
    def max_steps_per_frame(self) -> int:
        """Cap on ``|steps|`` returned by one ``tick`` (read-only)."""
        return self._max_steps

    @property
    def time_scale(self) -> float:
        """Simulated seconds per wall second (negative = backwards)."""
        return self._time_scale

    @time_scale.setter
    def time_scale(self, value: float) -> None:
        # The accumulator is left alone: it holds simulated time already owed,
        # which does not change because the rate of future time changes.
        self._time_scale = finite_float("time_scale", value)

    # ------------------------------------------------------------------
    # Pause / resume
    # ------------------------------------------------------------------
    @property
    def paused(self) -> bool:
        """True between ``pause()`` and ``resume()``.

        ``time_scale == 0`` also freezes the simulation but is a separate
        setting, so ``resume()`` never has to guess which scale to restore.
        """
        return self._paused

    def pause(self) -> None:
        """Stop accumulating time: ``tick`` returns 0 until ``resume()``.

        The accumulator (and therefore ``alpha``) is kept, so the rendered
        frame does not jump when pausing.
        """
        self._paused = True

    def resume(self) -> None:
        """Undo ``pause()``.

        If the wall clock is in use, its reference is re-read here so that the
        time spent paused is never fed to the simulation, even if the game
        stopped calling ``tick`` while paused.
        """
        if self._paused and self._last_wall is not None:
            self._last_wall = float(self._clock())
        self._paused = False

    # ------------------------------------------------------------------
    # Read-only statistics
    # ------------------------------------------------------------------
    @property
    def steps(self) -> int:
        """Net signed number of steps returned by all ticks so far."""
        return self._steps

    @property
    def sim_time(self) -> float:
        """Simulated time reached by the physics: ``steps * dt`` (signed).

        Computed from the integer step count, not summed per step, so it
        carries a single rounding however long the game runs.
        """
        return float(self._steps * self._dt_q)

    @property
    def accumulator(self) -> float:
        """Signed simulated time owed but not yet stepped; ``|acc| < dt``."""
        return float(self._accumulator)

    @property
    def alpha(self) -> float:
        """Render interpolation fraction ``|accumulator| / dt`` in [0, 1).

        Use it as ``prev + alpha * (curr - prev)`` (see ``interpolate``), where
        ``curr`` is the state after the last step and ``prev`` the one before.
        The renderer then shows the simulation up to one step behind real
        time, which is the price of never extrapolating (Fiedler's article).
        When running backwards the roles are the same: ``prev`` is the state
        before the last (backward) step.
        """
        return float(abs(self._accumulator) / self._dt_q)

    @property
    def dropped(self) -> float:
        """Total simulated seconds discarded by the per-frame step cap."""
        return float(self._dropped_q)

    # ------------------------------------------------------------------
    # The loop
    # ------------------------------------------------------------------
    def _read_wall_elapsed(self) -> float:
        """Wall seconds since the previous clock-driven tick (0 on the first)."""
        now = self._clock()
        now_f = finite_float("clock()", now)
        last, self._last_wall = self._last_wall, now_f
        if last is None:
            return 0.0
        elapsed = now_f - last
        if elapsed < 0.0:
            raise ValueError(
                f"wall_elapsed must be >= 0, but clock() went backwards by "
                f"{-elapsed!r} s ({last!r} -> {now!r})"
            )
        return elapsed

    def tick(self, wall_elapsed: Optional[float] = None) -> int:
        """Feed elapsed wall time; return the signed number of steps to take.

        Formula, with ``acc`` the accumulator::

            acc += time_scale * wall_elapsed          (0 while paused)
            n    = trunc(acc / dt)   (toward zero, with tolerance; see below)
            if |n| > max_steps_per_frame:
                dropped += (|n| - max_steps_per_frame) * dt
                n = sign(n) * max_steps_per_frame
            acc -= trunc(acc / dt) * dt               (remainder, |acc| < dt)

        so the returned ``n`` is negative when running backwards, and after the
        call ``sim_time + acc`` equals all scaled wall time fed so far, minus
        dropped time.  The fractional remainder survives a capped frame so
        ``alpha`` stays continuous.

        ``wall_elapsed`` is the wall time since the previous tick, in seconds,
        finite and >= 0.  If it is None, the ``clock`` callable is read and the
        time since the previous clock-driven tick is used; the first such tick
        only starts the measurement and returns 0.  An explicit value never
        reads the clock, and it restarts the clock measurement, so time is
        never counted twice when the two styles are mixed.

        Floating-point care: the accumulator is kept as an exact rational
        (``fractions.Fraction``).  Each float input is converted exactly, so
        the sums and subtractions themselves never round and the accumulator
        cannot drift over hours of play.  Exactness alone is not enough,
        because the inputs are already rounded: 144 frames of the float
        ``1/144`` add up to 3 * 2**-56 s *less* than 60 steps of the float
        ``1/60``, and a strict floor would lose a step.  So a remainder within
        ``STEP_TOLERANCE * dt`` (1e-9 of a step, ~17 fs at 60 Hz) of a whole
        step counts as that step, and the tiny overshoot is discarded instead
        of being carried as a debt (a carried debt would add up and could
        cost a step after a long session).  The tolerance is ~10**7 times the
        relative rounding error of a float, and far below any real frame-time
        jitter, so it only ever catches round-off.  Integer arithmetic on a
        rational representation was chosen over a float accumulator with a
        tolerance because it makes the tolerance the *only* approximation.
        """
        if wall_elapsed is None:
            elapsed = self._read_wall_elapsed()
        else:
            elapsed = nonnegative_float("wall_elapsed", wall_elapsed)
            # An explicit elapsed time covers the interval since the previous
            # tick, so a later clock-driven tick must not count it again.
            self._last_wall = None

        self.ticks += 1
        if self._paused or self._time_scale == 0.0 or elapsed == 0.0:
            self.last_steps = 0
            return 0

        acc = self._accumulator + Fraction(self._time_scale) * Fraction(elapsed)
        # Whole steps toward zero, counting "just short" as a whole step.
        ratio = abs(acc) / self._dt_q
        whole = math.floor(ratio + _STEP_TOLERANCE_Q)
        sign = 1 if acc >= 0 else -1
        remainder = acc - sign * whole * self._dt_q
        if whole and remainder * sign < 0:
            # Overshoot of at most tolerance*dt from snapping: forget it.
            remainder = Fraction(0)
        self._accumulator = remainder

        taken = min(whole, self._max_steps)
        if whole > taken:
            # Spiral-of-death guard: a long frame (debugger, loading, tab in
            # background) would otherwise demand more steps than we can run
            # in one frame, making the next frame longer still.
            excess = whole - taken
            self.dropped_steps += excess
            self._dropped_q += excess * self._dt_q

        n = sign * taken
        self._steps += n
        self.last_steps = n
        return n

    def run(self, sim: Any, wall_elapsed: Optional[float] = None) -> int:
        """Tick, then advance ``sim`` by the returned number of steps.

        ``sim`` is duck-typed like the engine's Simulation: it has a ``dt``
        attribute (its step, negative to integrate backwards) and a
        ``step(n)`` method advancing ``n >= 1`` steps in one call.  For the
        call, ``sim.dt`` is set to ``+dt`` (forward) or ``-dt`` (reverse) and
        afterwards restored to the value it had, even if ``step`` raises.
        ``abs(sim.dt)`` must equal this clock's ``dt`` (relative tolerance
        ``STEP_TOLERANCE``), else the clock's ``sim_time`` would not match the
        simulation's; a mismatch raises ValueError before any time is
        consumed.  Returns the signed step count (0: ``sim`` is not touched).
        """
        sim_dt = finite_float("sim.dt", sim.dt)
        if not math.isclose(abs(sim_dt), self._dt, rel_tol=STEP_TOLERANCE, abs_tol=0.0):
            raise ValueError(
                f"sim.dt must be +/-{self._dt!r} to match the clock, got {sim.dt!r}"
            )
        n = self.tick(wall_elapsed)
        if n == 0:
            return 0
        original_dt = sim.dt
        sim.dt = abs(sim_dt) if n > 0 else -abs(sim_dt)
        try:
            sim.step(abs(n))
        finally:
            sim.dt = original_dt
        return n

    def interpolate(self, prev: Any, curr: Any) -> Any:
        """Blend two physics states for rendering: ``prev + alpha*(curr - prev)``.

        ``prev`` is the state before the last step and ``curr`` the state after
        it.  Works on floats and on numpy arrays (anything with ``+``, ``-``
        and multiplication by a float), without importing numpy here.
        """
        return prev + self.alpha * (curr - prev)

    def __repr__(self) -> str:
        return (
            f"FixedStepClock(dt={self._dt!r}, time_scale={self._time_scale!r}, "
            f"max_steps_per_frame={self._max_steps!r}, steps={self._steps}, "
            f"alpha={self.alpha:.6f}, paused={self._paused})"
        )
