"""The reference's arithmetic, compiled: numpy's 2-vector dot as OpenBLAS rounds it here
(``dot_blas``) and Python's ``math.hypot`` bit for bit (``py_hypot``); why, in the
package's text ("Same numbers, same decisions")."""
import math
from fractions import Fraction

from numba.core import types
from numba.extending import intrinsic

from engine.cache import jit_disabled, numpy_dot_kind

from spacewar.game import core

jit = core.jit

NUMERIC = {"error_model": "numpy"}  # a zero division gives inf / nan as numpy would, no raise
DOT_FUSED = numpy_dot_kind() == "fused"  # how numpy's 2-vector dot rounds here (dot_blas)


# -- the reference's arithmetic ----------------------------------------------------------------
@intrinsic
def fma(typingctx, x, y, z):
    """``x y + z`` with one rounding (LLVM's ``llvm.fma.f64``)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        return builder.fma(args[0], args[1], args[2])
    return sig, codegen


if jit_disabled():  # the bots as plain Python (NUMBA_DISABLE_JIT=1, for tracing)
    def fma(x, y, z):  # noqa: F811 - an intrinsic cannot run in Python
        """``x y + z`` with one rounding: exact rationals, rounded once by int / int."""
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
            return x * y + z
        return float(Fraction(x) * Fraction(y) + Fraction(z))


@jit(inline="always", **NUMERIC)
def dot_blas(ax, ay, bx, by):
    """numpy's ``a @ b`` for 2-vectors as OpenBLAS's ddot computes it on this machine:
    ``fma(a1, b1, a0 b0)`` or ``a0 b0 + a1 b1`` (``DOT_FUSED``, a constant when compiled)."""
    if DOT_FUSED:
        return fma(ay, by, ax * bx)
    return ax * bx + ay * by


@jit(**NUMERIC)
def py_hypot(x, y):
    """Python's ``math.hypot(x, y)`` bit for bit: CPython's ``vector_norm`` for two numbers.

    With ``M = max(|x|, |y|) = m 2^e`` (frexp), the scaled ``x 2^-e`` are squared exactly
    (``hi + lo``, the low part by fma) and summed onto 1.0 with the rounding errors kept
    (``csum``, ``frac1``, ``frac2``); ``h = sqrt(sum)`` is then corrected once by
    ``(sum - h^2) / (2 h)`` (computed the same compensated way) and scaled back. Source:
    CPython 3.10+ ``Modules/mathmodule.c`` (R. Hettinger, after Borges, "An improved
    algorithm for hypot(a, b)", 2019). Subnormal inputs (never in this game) go to C's hypot.
    """
    ax = abs(x)
    ay = abs(y)
    if math.isinf(ax) or math.isinf(ay):
        return math.inf
    if math.isnan(ax) or math.isnan(ay):
        return math.nan
    big = ax if ax > ay else ay
    if big == 0.0:
        return big
    _, e = math.frexp(big)
    if e < -1021:
        return math.hypot(x, y)
    scale = math.ldexp(1.0, -e)
    csum = 1.0
    frac1 = 0.0
    frac2 = 0.0
    for v in (ax, ay):
        v = v * scale
        hi = v * v
        lo = fma(v, v, -hi)
        s = csum + hi  # fast two-sum: |csum| >= |hi|
        frac2 += (csum - s) + hi
        csum = s
        frac1 += lo
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    hi = -h * h
    lo = fma(-h, h, -hi)
    s = csum + hi
    frac2 += (csum - s) + hi
    csum = s
    frac1 += lo
    r = csum - 1.0 + (frac1 + frac2)
    h += r / (2.0 * h)
    return h / scale
