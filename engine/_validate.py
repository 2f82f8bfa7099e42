"""Input checks shared by the engine's public API: clear messages, raised before any change."""
import math
import numbers

import numpy as np


def finite_float(name, value):
    """Return ``value`` as a finite float or raise naming ``name`` and the value."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise TypeError(f"{name} must be a real number, got {value!r}") from None
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return value


def nonnegative_float(name, value):
    value = finite_float(name, value)
    if value < 0.0:
        raise ValueError(f"{name} must be >= 0, got {value!r}")
    return value


def positive_float(name, value):
    value = finite_float(name, value)
    if value <= 0.0:
        raise ValueError(f"{name} must be > 0, got {value!r}")
    return value


def vector(name, value, dim=None):
    """A finite float vector of length ``dim`` (2 or 3 when ``dim`` is None)."""
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a vector of numbers, got {value!r}") from None
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D vector, got shape {arr.shape} ({value!r})")
    allowed = (2, 3) if dim is None else (dim,)
    if arr.shape[0] not in allowed:
        raise ValueError(f"{name} must have length {' or '.join(map(str, allowed))}, "
                         f"got length {arr.shape[0]} ({value!r})")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return arr


def per_item(name, value, count, *, minimum=None, strictly=False):
    """Broadcast a scalar or length-``count`` array of finite floats, checking a lower bound."""
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number or an array of numbers, got {value!r}") from None
    if arr.ndim == 0:
        arr = np.full(count, float(arr))
    elif arr.shape != (count,):
        raise ValueError(f"{name} must be a scalar or have length {count}, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if minimum is not None:
        bad = arr <= minimum if strictly else arr < minimum
        if np.any(bad):
            op = ">" if strictly else ">="
            raise ValueError(f"{name} must be {op} {minimum}, got {arr[bad][0]!r} "
                             f"(item {int(np.flatnonzero(bad)[0])})")
    return arr


def optional(check):
    """``check`` that lets None through (an optional parameter)."""
    def validate(name, value):
        return None if value is None else check(name, value)
    return validate


def one_of(*choices):
    """A check that the value is one of ``choices``."""
    def validate(name, value):
        if not isinstance(value, str) or value not in choices:
            raise ValueError(f"{name} must be one of {', '.join(choices)}; got {value!r}")
        return value
    return validate
