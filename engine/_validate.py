"""Input checks shared by the engine's public API: clear messages, raised before any change."""
import math
import numbers

import numpy as np

#: Largest step count a single compiled call takes (``step(n)``, the steps ``integrate`` needs):
#: well inside the int64 the kernels count in, so ``steps + n`` and ``(step + 1) * h`` never
#: overflow the counter.
MAX_STEPS = 2 ** 62

_TEXT = (str, bytes, bytearray)
_BOOLS = (bool, np.bool_)


def _not_a_number(value):
    """True for values that convert to a float but are not numbers: text and booleans."""
    if isinstance(value, _TEXT + _BOOLS):
        return True
    return isinstance(value, np.ndarray) and value.dtype.kind not in "iuf"


def _items(value, raw):
    """The Python objects of a nested list (numpy's inferred dtype hides bools among numbers)."""
    out = np.empty(raw.shape, dtype=object)
    try:
        out[...] = value
    except (TypeError, ValueError):
        return raw.astype(object)
    return out


def finite_float(name, value):
    """Return ``value`` as a finite float or raise naming ``name`` and the value.

    Text (``'1'``) and booleans are refused (TypeError): they convert to a float, but a string
    or ``True`` given as a number is a bug, not a value.
    """
    if _not_a_number(value):
        raise TypeError(f"{name} must be a real number, got {value!r} ({type(value).__name__})")
    if not isinstance(value, numbers.Real):
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


def real_array(name, value, what="numbers"):
    """``value`` as a new float64 array; text, booleans and complex numbers are a TypeError.

    ``np.array('1', dtype=float)`` and ``np.array(True, dtype=float)`` succeed, so the dtype
    numpy infers is checked first: only integers and floats (or objects that are real numbers)
    pass.
    """
    raw, kind = _numbers(name, value, what, "iuf", numbers.Real)
    try:
        return np.array(raw, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise TypeError(f"{name} must be {what}, got {value!r}") from None


def _numbers(name, value, what, kinds, number_type):
    """``(raw, kind)``: ``value`` as an array whose dtype kind is in ``kinds``, or an object
    array (kind "O") of ``number_type`` items; text and booleans are a TypeError."""
    if isinstance(value, _TEXT):
        raise TypeError(f"{name} must be {what}, got {value!r} (str)")
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be {what}, got {value!r}") from None
    kind = raw.dtype.kind
    if isinstance(value, (list, tuple)) and kind in kinds:
        kind = "O"  # numpy reads (True, 0.0) as numbers: look at the items themselves
        raw = _items(value, raw)
    if kind == "O":
        for item in raw.reshape(-1):
            if isinstance(item, _BOOLS) or not isinstance(item, number_type):
                raise TypeError(f"{name} must be {what}, got {item!r} ({type(item).__name__}) "
                                f"in {value!r}")
    elif kind not in kinds:
        shown = raw.reshape(-1)[0].item() if raw.size else value
        raise TypeError(f"{name} must be {what}, got {shown!r} ({type(shown).__name__}) "
                        f"in {value!r}")
    return raw, kind


def _is_empty(value):
    try:
        return np.size(value) == 0
    except (TypeError, ValueError):  # ragged: not empty, and _numbers will say what is wrong
        return False


def index_array(name, value, width=None):
    """``value`` as a new int64 array of particle indices (shape (M, width), or 1-D).

    Only integers pass: floats (``0.0``), booleans and text are a TypeError even when they
    would convert, and an index too large for int64 is a ValueError.
    """
    shape = f"(M, {width})" if width else "a list of"
    what = f"{shape} integer particle indices"
    if isinstance(value, (list, tuple, np.ndarray)) and _is_empty(value):
        return np.zeros((0, width) if width else 0, dtype=np.int64)
    raw, kind = _numbers(name, value, what, "iu", numbers.Integral)
    if kind == "O":
        for item in raw.reshape(-1):
            if not -2 ** 63 <= item < 2 ** 63:
                raise ValueError(f"{name} holds the index {item!r}, far out of any range")
    if kind == "u" and raw.size and int(raw.max()) >= 2 ** 63:
        raise ValueError(f"{name} holds the index {int(raw.max())!r}, far out of any range")
    return np.array(raw, dtype=np.int64)


def int_in_range(name, value, minimum, maximum):
    """An int in ``[minimum, maximum]``: bools, floats, text and None are a TypeError, an int
    out of range a ValueError (a count of systems, a capacity)."""
    if isinstance(value, _BOOLS) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an int in [{minimum}, {maximum}], got {value!r} "
                        f"({type(value).__name__})")
    if not minimum <= value <= maximum:
        raise ValueError(f"{name} must be an int in [{minimum}, {maximum}], got {value!r}")
    return int(value)


def step_count(name, value, minimum=0):
    """An int step count in ``[minimum, MAX_STEPS]``.

    Bools, floats, text and None are a TypeError (not a count at all, like text given as a
    number to :func:`finite_float`); a count out of range is a ValueError.
    """
    if type(value) is int and minimum <= value <= MAX_STEPS:
        return value  # the common call, without the abstract-class check below
    if isinstance(value, _BOOLS) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an int >= {minimum}, got {value!r} "
                        f"({type(value).__name__})")
    value = int(value)
    if value < minimum:
        raise ValueError(f"{name} must be an int >= {minimum}, got {value!r}")
    if value > MAX_STEPS:
        raise ValueError(f"{name} must be at most 2**62 = {MAX_STEPS} steps per call, got {value!r}")
    return value


def finite_array(name, value, what="a number or an array of numbers"):
    """``value`` as a new float64 array (any shape) of finite numbers.

    Text, booleans and complex numbers are a TypeError (see :func:`real_array`); nan or inf
    anywhere is a ValueError.
    """
    arr = real_array(name, value, what)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return arr


def vector(name, value, dim=None):
    """A finite float vector of length ``dim`` (2 or 3 when ``dim`` is None)."""
    arr = real_array(name, value, "a vector of numbers")
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
    arr = real_array(name, value, "a number or an array of numbers")
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
