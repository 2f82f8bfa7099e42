"""One validation for every edge of the engine: the same bad value raises the same exception
type, with a message naming the field and showing the value, whichever public entry point
receives it (Simulation, Batch, FixedStepClock, engine.analytic).

The rule (engine._validate): text, booleans and None given as a number are a TypeError;
a number that is not finite or out of the field's range is a ValueError.
"""
import math
import re

import pytest

from engine import Batch, Simulation, analytic
from engine.clock import FixedStepClock

R0, V0 = [1.0, 0.0], [0.0, 1.0]

# What each field accepts among finite numbers.
def ANY(v):
    return True


def NONZERO(v):
    return v != 0


def POSITIVE(v):
    return v > 0


def NONNEGATIVE(v):
    return v >= 0


def MATCHES_CLOCK(v):  # run(sim) needs sim.dt = +/- the clock's dt
    return abs(v) == 0.25


def _tick(value):
    FixedStepClock(0.25).tick(value)


class _SimWithDt:
    def __init__(self, dt):
        self.dt = dt

    def step(self, n):
        pass


def _run_with_sim_dt(value):
    FixedStepClock(0.25).run(_SimWithDt(value), 0.5)


def _set_time_scale(value):
    FixedStepClock(0.25).time_scale = value


def _set_sim_dt(value):
    Simulation(dt=0.1).dt = value


# (label, field named in the message, what the field accepts, call with the value);
# tick(None) is not in the list of None cases: None there means "read the wall clock".
REAL_FIELDS = [
    ("Simulation(dt=)", "dt", NONZERO, lambda v: Simulation(dt=v)),
    ("Simulation.dt =", "dt", NONZERO, _set_sim_dt),
    ("Simulation(tolerance=)", "tolerance", POSITIVE, lambda v: Simulation(tolerance=v)),
    ("Batch(dt=)", "dt", NONZERO, lambda v: Batch(systems=1, dt=v)),
    ("FixedStepClock(dt=)", "dt", POSITIVE, lambda v: FixedStepClock(dt=v)),
    ("FixedStepClock(time_scale=)", "time_scale", ANY,
     lambda v: FixedStepClock(dt=0.25, time_scale=v)),
    ("FixedStepClock.time_scale =", "time_scale", ANY, _set_time_scale),
    ("FixedStepClock.tick()", "wall_elapsed", NONNEGATIVE, _tick),
    ("FixedStepClock.run(sim)", "sim.dt", MATCHES_CLOCK, _run_with_sim_dt),
    ("kepler(mu=)", "mu", POSITIVE, lambda v: analytic.kepler(R0, V0, mu=v, t=1.0)),
    ("kepler(t=)", "t", ANY, lambda v: analytic.kepler(R0, V0, mu=1.0, t=v)),
    ("orbital_elements(mu=)", "mu", POSITIVE, lambda v: analytic.orbital_elements(R0, V0, v)),
    ("ballistic(t=)", "t", ANY, lambda v: analytic.ballistic(0.0, 1.0, -1.0, t=v)),
    ("ballistic(g=)", "g", ANY, lambda v: analytic.ballistic(0.0, 1.0, v, t=1.0)),
    ("ballistic(p0=)", "p0", ANY, lambda v: analytic.ballistic(v, 1.0, -1.0, t=1.0)),
    ("harmonic_oscillator(omega=)", "omega", POSITIVE,
     lambda v: analytic.harmonic_oscillator(1.0, 0.0, omega=v, t=1.0)),
    ("harmonic_oscillator(t=)", "t", ANY,
     lambda v: analytic.harmonic_oscillator(1.0, 0.0, omega=1.0, t=v)),
    ("harmonic_oscillator(zeta=)", "zeta", NONNEGATIVE,
     lambda v: analytic.harmonic_oscillator(1.0, 0.0, omega=1.0, t=1.0, zeta=v)),
    ("harmonic_oscillator(x0=)", "x0", ANY,
     lambda v: analytic.harmonic_oscillator(v, 0.0, omega=1.0, t=1.0)),
]

BAD_REALS = ["x", True, None, math.nan, math.inf, -math.inf, -1, 0]


def _expected_real(value, accepts):
    """The exception ``value`` must raise for a field accepting ``accepts``; None if valid."""
    if value is None or isinstance(value, (str, bool)):
        return TypeError
    if not math.isfinite(value):
        return ValueError
    return None if accepts(value) else ValueError


def _assert_names(message, field, value):
    assert re.search(rf"(?<![\w.]){re.escape(field)}\b", message), (field, message)
    shown = repr(value)
    assert re.search(rf"\bgot {re.escape(shown)}", message), (shown, message)


def _raised(call, value):
    try:
        call(value)
    except Exception as exc:  # noqa: BLE001 - the type is what is under test
        return exc
    return None


@pytest.mark.parametrize("value", BAD_REALS, ids=repr)
def test_same_bad_number_same_error_everywhere(value):
    seen = {}
    for label, field, accepts, call in REAL_FIELDS:
        if value is None and call is _tick:
            continue
        expected = _expected_real(value, accepts)
        exc = _raised(call, value)
        if expected is None:
            assert exc is None, f"{label} refused the valid {value!r}: {exc!r}"
            continue
        assert exc is not None, f"{label} accepted {value!r}"
        seen[label] = type(exc)
        assert type(exc) is expected, f"{label}: {type(exc).__name__}: {exc}"
        _assert_names(str(exc), field, value)
    assert len(set(seen.values())) == 1, seen


# Step counts: an int in a range; bool, float, text and None are not counts (TypeError).
COUNT_FIELDS = [
    ("Simulation.step()", "n", 0, lambda v: Simulation(dt=0.1).step(v)),
    ("Batch.step()", "n", 0, lambda v: Batch(systems=1, dt=0.1).step(v)),
    ("FixedStepClock(max_steps_per_frame=)", "max_steps_per_frame", 1,
     lambda v: FixedStepClock(dt=0.25, max_steps_per_frame=v)),
]

BAD_COUNTS = ["x", True, None, 1.5, 2.0, math.nan, -1, 0, 2 ** 63]


@pytest.mark.parametrize("value", BAD_COUNTS, ids=repr)
def test_same_bad_step_count_same_error_everywhere(value):
    seen = {}
    for label, field, minimum, call in COUNT_FIELDS:
        if isinstance(value, int) and not isinstance(value, bool):
            expected = ValueError if not minimum <= value <= 2 ** 62 else None
        else:
            expected = TypeError
        exc = _raised(call, value)
        if expected is None:
            assert exc is None, f"{label} refused the valid {value!r}: {exc!r}"
            continue
        assert exc is not None, f"{label} accepted {value!r}"
        seen[label] = type(exc)
        assert type(exc) is expected, f"{label}: {type(exc).__name__}: {exc}"
        _assert_names(str(exc), field, value)
    assert len(set(seen.values())) == 1, seen
