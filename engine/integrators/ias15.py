"""IAS15: the 15th-order Gauss-Radau predictor-corrector with adaptive steps (``ias15``).

References
----------
- E. Everhart, "An efficient integrator that uses Gauss-Radau spacings", in *Dynamics of
  Comets: Their Origin and Evolution*, IAU Colloq. 83, ASSL 115 (1985) 185: the method, the
  Gauss-Radau spacings and the predictor of the next step's coefficients.
- H. Rein, D. S. Spiegel, "IAS15: a fast, adaptive, high-order integrator for gravitational
  dynamics, accurate to machine precision over a billion orbits", MNRAS 446 (2015) 1424:
  convergence of the predictor-corrector to machine precision, compensated summation.
- D. Pham, H. Rein, D. S. Spiegel, "A new timestep criterion for N-body simulations", The
  Open Journal of Astrophysics 7 (2024) (arXiv:2401.02849): the step-size criterion used here.

The method
----------
Over one step of length ``dt`` write the time as ``t0 + s dt`` with ``s`` in [0, 1] and expand
every acceleration component as a polynomial of degree 7 in ``s``::

    a(s) = a0 + b0 s + b1 s^2 + ... + b6 s^7

Integrating it once and twice gives the velocity and position at any ``s``::

    v(s) = v0 + s dt (a0 + b0 s/2 + b1 s^2/3 + ... + b6 s^7/8)
    x(s) = x0 + s dt v0 + (s dt)^2 (a0/2 + b0 s/6 + b1 s^2/12 + ... + b6 s^7/72)

The seven unknown ``b`` per component are fixed by collocation at the seven interior
Gauss-Radau spacings ``h1..h7`` of [0, 1] (with ``h0 = 0`` the eight nodes of Radau quadrature),
which makes the end-of-step values accurate to order 15. The collocation is solved by
fixed-point iteration: predict positions (and, for velocity-dependent forces, velocities) at
node ``h_n`` from the current ``b``, evaluate the forces there, and refresh the Newton
divided-difference coefficients ``g`` of the acceleration,

    a(s) = a0 + g0 s + g1 s (s - h1) + g2 s (s - h1)(s - h2) + ... + g6 s (s - h1)...(s - h6),

from which the ``b`` follow by the fixed linear map ``b = C^T g`` (``C`` holds the power
coefficients of the products ``s (s - h1)...(s - hk)``; ``D = C^-1`` maps back). A sweep over
the seven nodes is one iteration; the iteration stops when the last correction of ``b6``,
relative to the largest acceleration, is below 1e-16, when that measure no longer decreases
(from the third iteration on: round-off reached), or after 12 iterations.

The ``b`` of an accepted step predict those of the next one (Everhart): re-expanding the
step's acceleration polynomial about its end, with the next step ``q`` times as long, gives
``e_j = q^(j+1) sum_{k>=j} binomial(k+1, j+1) b_k``, and the difference between the converged
and the predicted ``b`` of the step just taken is added as a correction. A step costs one
force evaluation at its start plus 7 per iteration; with the warm start it typically takes two
or three iterations (22.3 evaluations per step on the outer solar system at epsilon 1e-9, as
REBOUND's IAS15). The predictor lives in a caller-owned ``memory`` array, so it survives
between calls (``memory_shape``).

Positions and velocities are accumulated across steps with compensated (Kahan) summation, each
term of the update added separately from the smallest to the largest, and the ``b`` within a
step likewise: together with steps below the truncation error this makes the energy error a
random walk (Brouwer's law, error ~ sqrt(time)).

Step size (Pham, Rein & Spiegel 2024)
-------------------------------------
After a step, each moving particle's acceleration ``a``, jerk ``j`` and snap ``k`` at the end
of the step are read off the polynomial, and its timescale is

    tau_i^2 = 2 |a|^2 / (|j|^2 + |a| |k|)

(particles whose acceleration at the start of the step is zero or not normal are skipped, and
so are those whose acceleration at the start is below 1e-12 of the one at the end: zero but
for round-off, see ``_timescale2``). The
next step is ``dt_new = (7! epsilon)^(1/7) min_i tau_i``; if no particle gives a timescale the
step grows by 4. A step whose ``dt_new`` is less than a quarter of the step just tried is
rejected and retried with ``dt_new``; otherwise ``dt_new`` is used next, growing by at most a
factor 4 per step.

Here ``epsilon`` is the kernel's ``tol`` (default 1e-9, as in REBOUND); ``tol <= 0`` keeps the
step fixed at ``h`` (REBOUND's epsilon = 0).

Engine conventions: pinned particles do not move (they still exert and feel forces), nor do
inactive ones; with a periodic box the moving particles are wrapped at the end of each step
(the compensation term of a wrapped coordinate is dropped); ``t_end`` (not NaN) makes the last
step land exactly on it, and the step proposed before that shortening is returned as
``h_next`` (unless the landing step, if at least a quarter of it, asks for less). The time is
accumulated with compensated summation too (kept in ``memory`` between calls).

Failures return ``(t, h_next, done, status)`` as ``common`` describes, with the state of the
last accepted step: a non-finite acceleration at the start of a step gives the index of the
particle at once; a non-finite acceleration at a node or a non-finite result is, with fixed
steps, the particle's index, and with adaptive steps a rejection (a quarter of the step) until
the step collapses, then the index. A step collapses (``STEP_COLLAPSED``) when it is no longer
than 8 eps |t| (eps = 2.2e-16; or below 1e-291): the time could no longer advance by it.
"""
import math
from fractions import Fraction

import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic
from numba.np.arrayobj import populate_array

from ..cache import jit

from ..forces.dispatch import accelerations
from . import fused_gravity
from ..state import with_motion
from ..space import wrap_scalar
from .common import OK, STEP_COLLAPSED, TIME_OVERFLOW, fill_active_mask

NAME = "ias15"
ORDER = 15

# -- the Gauss-Radau constants -------------------------------------------------------------------
#: Interior Gauss-Radau spacings on [0, 1] (Everhart 1985, table; as quoted by Rein & Spiegel
#: 2015): with 0 the eight nodes of Radau quadrature, i.e. the roots of
#: (P_7(x) + P_8(x)) / (1 + x) on [-1, 1] mapped by s = (1 + x) / 2 (checked in the tests).
SPACINGS = ("0.0562625605369221464656521910318", "0.180240691736892364987579942780",
            "0.352624717113169637373907769648", "0.547153626330555383001448554766",
            "0.734210177215410531523210605558", "0.885320946839095768090359771030",
            "0.977520613561287501891174488626")


def _exact_tables():
    """The node differences, the power coefficients of the Newton basis and their inverse,
    derived exactly (rational arithmetic on the 30-digit spacings) and then rounded once."""
    s = [Fraction(0)] + [Fraction(v) for v in SPACINGS]
    diff = [[s[i] - s[j] if j < i else Fraction(0) for j in range(8)] for i in range(8)]
    # row k: coefficients of s^1..s^7 in w_k(s) = s (s - h1) ... (s - hk), k = 0..6
    power = [[Fraction(0)] * 7 for _ in range(7)]
    poly = [Fraction(1)]  # coefficients of prod_{m<=k} (s - h_m), lowest power first
    for k in range(7):
        if k > 0:
            nxt = [Fraction(0)] * (len(poly) + 1)
            for p, coef in enumerate(poly):
                nxt[p + 1] += coef
                nxt[p] -= s[k] * coef
            poly = nxt
        for p, coef in enumerate(poly):
            power[k][p] = coef  # times s gives s^(p+1): column p
    # inverse of the (lower triangular, unit diagonal) matrix ``power``, exactly
    inverse = [[Fraction(int(i == j)) for j in range(7)] for i in range(7)]
    for i in range(7):
        for j in range(i):
            inverse[i][j] = -sum(power[i][m] * inverse[m][j] for m in range(j, i))
    return s, diff, power, inverse


def _as_array(rows):
    return np.array([[float(v) for v in row] for row in rows], dtype=np.float64)


_S, _DIFF, _POWER, _INVERSE = _exact_tables()
#: the eight nodes 0, h1, ..., h7
_H = np.array([float(v) for v in _S])
#: _RINV[n, j] = 1 / (h_n - h_j) (j < n), exact and rounded once: the divided differences at
#: node n multiply by these (a division costs several multiplications, and an iteration takes
#: 28 per coordinate)
_RINV = _as_array([[1 / v if v else 0 for v in row] for row in _DIFF])
#: b_j = sum_k _C[k, j] g_k  (Everhart's c table, with the unit diagonal)
_C = _as_array(_POWER)
#: g_k = sum_j _D[j, k] b_j  (Everhart's d table, with the unit diagonal); _D = _C^-1
_D = _as_array(_INVERSE)
#: binomial(k + 1, j + 1): re-expansion of the step's polynomial about its end (predictor)
_BINOM = np.array([[float(math.comb(k + 1, j + 1)) if k >= j else 0.0 for k in range(7)]
                   for j in range(7)])
#: divisors of b_j in the position (j + 2)(j + 3) and velocity (j + 2) updates
_XDIV = np.array([float((j + 2) * (j + 3)) for j in range(7)])
_VDIV = np.array([float(j + 2) for j in range(7)])
#: their reciprocals, for the predictions at the nodes (the end-of-step sums divide)
_XINV = 1.0 / _XDIV
_VINV = 1.0 / _VDIV

_MAX_ITERATIONS = 12
_CONVERGED = 1e-16
_SAFETY = 0.25          # reject below a quarter of the step tried; grow by at most 1 / _SAFETY
_NO_PREDICTION = 20.0   # beyond this ratio of steps the predictor is dropped (b = 0)
_FACTORIAL7 = 5040.0
_EPS = 2.220446049250313e-16
_MIN_NORMAL = 2.2250738585072014e-308
#: (1e-12)^2: a particle whose acceleration at the start of a step is below 1e-12 of the one at
#: its end started the step at a zero of its acceleration (``_timescale2``)
_ZERO_START2 = 1e-24

# -- the caller-owned memory ---------------------------------------------------------------------
#: header entries of ``memory`` (then the blocks listed in ``memory_shape``)
MEMORY_VALID = 0        # 1.0: the blocks hold the state of a previous call; 0.0: cold start
MEMORY_DT_LAST = 1      # length of the last accepted step (0: none yet)
MEMORY_DT_PREDICTED = 2  # step length the current b, e were predicted for
MEMORY_E_VALID = 3      # 1.0 when e holds a prediction (after the first accepted step)
MEMORY_T = 4            # the time returned by the last call ...
MEMORY_T_COMPENSATION = 5  # ... and its compensated-summation term (time = t - this)
MEMORY_EVALUATIONS = 6  # force evaluations, cumulative over calls
MEMORY_REJECTED = 7     # rejected step attempts, cumulative
MEMORY_CAPPED = 8       # steps whose predictor-corrector stopped at the 12-iteration cap
MEMORY_ITERATIONS = 9   # predictor-corrector iterations of accepted steps, cumulative
HEADER = 10
_BLOCKS = 32  # b, e, b_done, e_done (7 each), x and v compensation, x and v at the last return


def memory_shape(dim, n):
    """Shape of the ``memory`` array for ``n`` particles in ``dim`` dimensions: a 1-D float64
    array of ``HEADER + 32 dim n`` entries, laid out as ``HEADER`` scalars (``MEMORY_*``),
    then b, e, the last accepted step's b and e (each ``(7, dim, n)``), the compensation terms
    of positions and velocities, and the positions and velocities at the last return (each
    ``(dim, n)``). A zeroed array is a cold start."""
    return (HEADER + _BLOCKS * int(dim) * int(n),)


def new_memory(dim, n):
    """A fresh (cold-start) ``memory`` array."""
    return np.zeros(memory_shape(dim, n))


#: force evaluations per predictor-corrector iteration (plus one at the start of each step)
EVALUATIONS_PER_ITERATION = 7


def statistics(memory):
    """The cumulative counters kept in ``memory``: force evaluations, predictor-corrector
    iterations of accepted steps, rejected step attempts, and steps whose iteration stopped at
    the cap of 12 (a sign of steps too long for the problem)."""
    return {"evaluations": int(memory[MEMORY_EVALUATIONS]),
            "iterations": int(memory[MEMORY_ITERATIONS]),
            "rejected": int(memory[MEMORY_REJECTED]),
            "capped": int(memory[MEMORY_CAPPED])}


@jit(error_model="numpy", inline="always")
def _views(memory, dim, n):
    """The blocks of ``memory``: b, e, b_done, e_done as ``(7, dim n)`` (each row the components
    in (k, i) order, so the loops over components are plain vector loops), the compensation
    terms as ``(dim n,)``, the state at the last return as ``(dim, n)``."""
    m = dim * n
    o = HEADER
    b = _matrix(memory, o, 7, m)
    o += 7 * m
    e = _matrix(memory, o, 7, m)
    o += 7 * m
    b_done = _matrix(memory, o, 7, m)
    o += 7 * m
    e_done = _matrix(memory, o, 7, m)
    o += 7 * m
    csx = memory[o:o + m]
    o += m
    csv = memory[o:o + m]
    o += m
    x_end = _matrix(memory, o, dim, n)
    o += m
    v_end = _matrix(memory, o, dim, n)
    return b, e, b_done, e_done, csx, csv, x_end, v_end


# -- arrays without reference counting ------------------------------------------------------------
#: every kernel of this module is compiled without reference counting (``_nrt=False``): with
#: it, ``advance``, which allocates its scratch, paid reference-count updates for each of its
#: thirty arrays on every path (750 calls in its code: seconds of compiling), and the steps
#: could not run in it (each array passed to an inlined helper at a node paid atomic
#: updates). These make and free its arrays instead.
_MATRIX = types.Array(types.float64, 2, "C")


@intrinsic
def _scratch(typingctx, rows, columns):
    """A ``(rows, columns)`` float64 array from numba's allocator (``NRT_Allocate``), without
    a reference count, to be freed with ``_release``. MemoryError if none is left."""
    def codegen(context, builder, signature, args):
        rows, columns = args
        itemsize = context.get_constant(types.intp, 8)
        count = builder.mul(rows, columns)
        one = context.get_constant(types.intp, 1)
        count = builder.select(builder.icmp_signed("<", count, one), one, count)
        allocate = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(cgutils.voidptr_t, [cgutils.intp_t]),
            "NRT_Allocate")
        data = builder.call(allocate, [builder.mul(count, itemsize)])
        with builder.if_then(cgutils.is_null(builder, data), likely=False):
            context.call_conv.return_user_exc(builder, MemoryError,
                                              ("ias15: no memory for the scratch arrays",))
        array = context.make_array(_MATRIX)(context, builder)
        populate_array(array, data=builder.bitcast(data, array.data.type),
                       shape=[rows, columns], strides=[builder.mul(columns, itemsize), itemsize],
                       itemsize=itemsize, meminfo=None)
        return array._getvalue()
    return _MATRIX(types.intp, types.intp), codegen


@intrinsic
def _matrix(typingctx, vector, start, rows, columns):
    """``vector[start:start + rows columns].reshape((rows, columns))`` for a C-contiguous
    float64 vector, without ``reshape``'s checks (the callers size their views; a reshape
    compiles to a call, a check and an error path, and there were nine)."""
    if not (isinstance(vector, types.Array) and vector.ndim == 1 and vector.layout == "C"
            and vector.dtype == types.float64):
        return None

    def codegen(context, builder, signature, args):
        vector, start, rows, columns = args
        itemsize = context.get_constant(types.intp, 8)
        data = context.make_array(signature.args[0])(context, builder, vector).data
        view = context.make_array(_MATRIX)(context, builder)
        populate_array(view, data=builder.gep(data, [start], inbounds=True),
                       shape=[rows, columns], strides=[builder.mul(columns, itemsize), itemsize],
                       itemsize=itemsize, meminfo=None)
        return view._getvalue()
    return _MATRIX(vector, types.intp, types.intp, types.intp), codegen


@intrinsic
def _release(typingctx, array):
    """Free an array from ``_scratch``."""
    def codegen(context, builder, signature, args):
        data = context.make_array(signature.args[0])(context, builder, args[0]).data
        free = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [cgutils.voidptr_t]), "NRT_Free")
        builder.call(free, [builder.bitcast(data, cgutils.voidptr_t)])
        return context.get_dummy_value()
    return types.void(array), codegen


# -- small pieces ---------------------------------------------------------------------------------
@jit(error_model="numpy", fastmath=False)
def root7(a):
    """a^(1/7) for a > 0 by Newton's method from above (fixed iteration count, so the result
    depends only on IEEE arithmetic, not on the platform's pow); NaN for a <= 0 or non-finite."""
    if a == math.inf:
        return math.inf
    if not (a > 0.0 and math.isfinite(a)):
        return math.nan
    m, ex = math.frexp(a)
    q = ex // 7
    y = math.ldexp(m, ex - 7 * q)  # in [0.5, 64)
    x = 1.0 + (y - 1.0) / 7.0      # the tangent at 1 lies above the concave root
    for _ in range(40):
        x6 = x * x * x
        x6 = x6 * x6
        x = (6.0 * x + y / x6) / 7.0
    return math.ldexp(x, q)


@jit(error_model="numpy", inline="always")
def _kahan(total, comp, term):
    """Compensated sum: returns (total', comp') with total' - comp' = total - comp + term."""
    y = term - comp
    s = total + y
    return s, (s - total) - y


@jit(error_model="numpy", inline="always")
def _first_bad(a, mask, n):
    for i in range(n):
        if mask[i] != 0.0:
            for k in range(a.shape[0]):
                if not math.isfinite(a[k, i]):
                    return i
    return -1


@jit(error_model="numpy", _nrt=False, fastmath={"contract"}, no_cpython_wrapper=True,
     no_cfunc_wrapper=True)
def _predict(b_done, e_done, b, e, ratio, cold):
    """Everhart's predictor: the b, e for a step ``ratio`` times the last accepted one;
    ``cold`` (no step accepted yet): the same acceleration polynomial b over a step
    ``ratio`` times as long (same start), e untouched.

    One pass over the components, the sums over the coefficients inside it (the same
    operations in the same order as a loop over the components per coefficient, which
    compiled to 28 vector loops: 4800 lines of IR, a second of compiling, and 490 ns a call
    for the outer solar system against 310 ns now)."""
    m = b.shape[1]
    if not (abs(ratio) <= _NO_PREDICTION):
        for j in range(7):
            for c in range(m):
                b[j, c] = 0.0
        if not cold:
            for j in range(7):
                for c in range(m):
                    e[j, c] = 0.0
        return
    if cold:
        for c in range(m):
            f = 1.0
            for j in range(7):
                f *= ratio
                b[j, c] *= f
        return
    for c in range(m):
        qj = 1.0
        for j in range(7):
            qj *= ratio
            s = 0.0
            for k in range(6, j - 1, -1):
                s += _BINOM[j, k] * b_done[k, c]
            ej = qj * s
            e[j, c] = ej
            b[j, c] = ej + (b_done[j, c] - e_done[j, c])


@jit(error_model="numpy", inline="always")
def _forces(t, state, model, acc, work, fused):
    """The accelerations of every declared term; for ``fused`` scenes (one open-space gravity
    term on a few bodies, ``fused_gravity.applies``) the pair loop inline, each pair once
    (a_i += G m_j d / (r^2 + eps^2)^(3/2), a_j -= G m_i d / ...), without the force table's
    call: twenty-odd evaluations a step make that call a large part of a small system's step.
    Body i's sums stay in registers over its pairs (the compiler cannot keep them there
    itself: as far as it knows, a_j might be a_i); every acceleration sums its terms in pair
    order."""
    if not fused:
        accelerations(t, state, model, acc, work)
        return
    pos = state.pos
    mass = state.mass
    active = state.active
    n = state.n
    dim = pos.shape[0]
    f0 = model.param_offsets[0]
    G = model.params[f0]
    eps2 = model.params[f0 + 1]
    for i in range(n):
        # zeroed body by body, as the loop below reads them: zeroed a row at a time, the
        # stores became vector stores, and the scalar loads of the pair loop waited on them
        # (80 -> 66 ns for the outer solar system's 15 pairs, measured in a loop of calls)
        for k in range(dim):
            acc[k, i] = 0.0
    for i in range(n):
        if not active[i]:
            continue
        xi = pos[0, i]
        yi = pos[1, i]
        zi = pos[2, i] if dim == 3 else 0.0
        mi = mass[i]
        ax = acc[0, i]
        ay = acc[1, i]
        az = acc[2, i] if dim == 3 else 0.0
        for j in range(i + 1, n):
            if not active[j]:
                continue
            dx = pos[0, j] - xi
            dy = pos[1, j] - yi
            dz = pos[2, j] - zi if dim == 3 else 0.0
            r2 = dx * dx + dy * dy + dz * dz + eps2
            f = G / (r2 * math.sqrt(r2))
            fi = f * mass[j]
            fj = f * mi
            ax += fi * dx
            ay += fi * dy
            acc[0, j] -= fj * dx
            acc[1, j] -= fj * dy
            if dim == 3:
                az += fi * dz
                acc[2, j] -= fj * dz
        acc[0, i] = ax
        acc[1, i] = ay
        if dim == 3:
            acc[2, i] = az


@jit(error_model="numpy", inline="always")
def _horner(b, weights, s, w, m):
    """w = sum_j weights[j] b_j s^j for every component (Horner in s, one vector loop per
    coefficient): the velocity polynomial at a node (``_VINV``). The loop over the
    coefficients runs to ``b.shape[0]`` (7), a bound the compiler does not see: with the
    constant it unrolled the loop into seven vector loops. (Written out per component as in
    ``_positions_at``, the multiply-adds fuse differently: other round-off.)"""
    top = b.shape[0] - 1
    for c in range(m):
        w[c] = b[top, c] * weights[top]
    for j in range(top - 1, -1, -1):
        f = weights[j]
        for c in range(m):
            w[c] = w[c] * s + b[j, c] * f


@jit(error_model="numpy", fastmath={"reassoc"})
def _moving_finite(acc, mask, m):
    """True if the acceleration of every moving component is finite: x * 0 is 0 for finite x
    and NaN for inf or NaN, and a sum of zeros never overflows. Compiled on its own with
    reassociation allowed (and only that: no assumption about NaN or infinity), so the sum
    runs four components an instruction; a branch per component, as before, cost about 0.6 us
    of a 5.2 us step of the outer solar system (22 nodes a step)."""
    s = 0.0
    for c in range(m):
        s += (acc[c] if mask[c] != 0.0 else 0.0) * 0.0
    return s == 0.0


@jit(error_model="numpy", inline="always")
def _positions_at(b, s, sdt, x0, v0, a0, csx, sx, m):
    """The positions at node ``s`` (``sdt`` = s dt) from the current b: ``_horner`` with
    ``_XINV`` and the position update in one pass over the components, the polynomial
    written out, without the scratch row in between (the same operations in the same order;
    the compiler fuses some multiply-adds differently, so the round-off differs: final states
    of the outer solar system, the Pythagorean and a Kepler problem within 5e-15 of the
    previous form's, with the same steps). With ``_moving_finite`` a step of the outer solar
    system went from 5.2 to 4.8 us (5.2 to 4.9 us without this)."""
    for c in range(m):
        p = b[6, c] * _XINV[6]
        p = p * s + b[5, c] * _XINV[5]
        p = p * s + b[4, c] * _XINV[4]
        p = p * s + b[3, c] * _XINV[3]
        p = p * s + b[2, c] * _XINV[2]
        p = p * s + b[1, c] * _XINV[1]
        p = p * s + b[0, c] * _XINV[0]
        sx[c] = x0[c] + (sdt * (v0[c] + sdt * (p * s + 0.5 * a0[c])) - csx[c])


@jit(error_model="numpy", _nrt=False, fastmath={"contract"}, no_cpython_wrapper=True,
     no_cfunc_wrapper=True)
def _advance(t, dt, state, model, work, vdep, fused, mask, a0, v0, x0, u0, b, csx, csv, g, csb,
             acc, sx, sv, w, change, nx, ncx, nv, ncv):
    """One step attempt of ``advance``: the predictor-corrector, then the positions and
    velocities at the end of the step (``nx``, ``nv``, with their compensation terms ``ncx``,
    ``ncv``). Returns (status, iterations, evaluations): status -1, or the first moving
    particle with a non-finite acceleration at a node or a non-finite end value.

    Compiled on its own and called once per step attempt: ``advance`` keeps the control
    flow, this function the work (compiled into ``advance``, it made one function too large
    for numba's inlining and SSA passes, which grow faster than its size).

    Every per-component array is flat, the components in (k, i) order (``_views``): ``acc``,
    ``sx`` and ``sv`` are flat views of the ``(dim, n)`` arrays the forces write and read,
    ``mask`` is the moving flag per component, ``x0`` and ``u0`` receive the positions and
    velocities at the start of the step, ``w`` and ``change`` are scratch. Each stage is one
    loop over all the components (a vector loop: four components an instruction), with the
    operations of each component in the order of a loop per component. A node's work is
    then about 20 such loops over 3n components instead of 3n scalar passes; with the
    fused force below, a step of the outer solar system (6 bodies, 22 force evaluations)
    went from 11-12 us to 8 us on the development machine (same results to the bit before
    multiply-adds were contracted, ``fastmath={"contract"}``, which changes round-off
    only).

    Particles that do not move have a0 = v0 = b = csx = csv = 0 here (``_park``), so the
    branch-free loops below leave them exactly where they are; their accelerations at the
    nodes are replaced by a0 (0) before they enter the divided differences."""
    pos = state.pos
    vel = state.vel
    n = state.n
    dim = pos.shape[0]
    m = dim * n
    acc2d = _matrix(acc, 0, dim, n)
    sub = with_motion(state, _matrix(sx, 0, dim, n), _matrix(sv, 0, dim, n))
    for k in range(dim):
        for i in range(n):
            x0[k * n + i] = pos[k, i]
            u0[k * n + i] = vel[k, i]
    for c in range(m):
        sx[c] = x0[c]
        sv[c] = u0[c]
    # g from b: g_j = sum_{l>=j} D[l, j] b_l; the b's compensation terms start at 0. Here and
    # at the end of the step the sums over the coefficients run inside one pass over the
    # components (as in ``_predict``: the same operations in the same order, straight-line
    # code in one loop instead of 28 and 7 loops)
    for c in range(m):
        for j in range(7):
            gj = b[j, c]
            for l in range(j + 1, 7):
                gj += _D[l, j] * b[l, c]
            g[j, c] = gj
            csb[j, c] = 0.0
    error = 1e300
    error_last = 2.0
    iterations = 0
    evaluations = 0
    while True:
        # converged; no longer improving (round-off reached); or the cap
        if (error < _CONVERGED or (iterations > 2 and error_last <= error)
                or iterations >= _MAX_ITERATIONS):
            break
        error_last = error
        iterations += 1
        for node in range(1, 8):
            s = _H[node]
            sdt = s * dt
            # positions (and velocities) at the node from the current b
            _positions_at(b, s, sdt, x0, v0, a0, csx, sx, m)
            if vdep:
                _horner(b, _VINV, s, w, m)
                for c in range(m):
                    sv[c] = u0[c] + (sdt * (w[c] * s + a0[c]) - csv[c])
            _forces(t + sdt, sub, model, acc2d, work, fused)
            evaluations += 1
            last = node - 1  # the coefficient g_last this node determines
            # the Newton divided differences give g_last from the node's acceleration ...
            r = _RINV[node, 0]
            for c in range(m):
                a = acc[c] if mask[c] != 0.0 else 0.0
                w[c] = (a - a0[c]) * r
            for j in range(1, node):
                r = _RINV[node, j]
                for c in range(m):
                    w[c] = (w[c] - g[j - 1, c]) * r
            for c in range(m):
                change[c] = w[c] - g[last, c]
                g[last, c] = w[c]
            # ... and b += C^T (change of g), compensated
            for j in range(last + 1):
                f = _C[last, j]
                for c in range(m):
                    y = f * change[c] - csb[j, c]
                    total = b[j, c] + y
                    csb[j, c] = (total - b[j, c]) - y
                    b[j, c] = total
            if not _moving_finite(acc, mask, m):
                for i in range(n):
                    if mask[i] != 0.0:
                        for k in range(dim):
                            if not math.isfinite(acc2d[k, i]):
                                return i, iterations, evaluations
            if node == 7:
                max_a = 0.0
                max_db = 0.0
                for c in range(m):
                    if mask[c] != 0.0:
                        max_a = max(max_a, abs(acc[c]))
                    max_db = max(max_db, abs(change[c]))
                if max_db == 0.0:
                    error = 0.0
                elif max_a > 0.0:
                    error = max_db / max_a
                else:
                    error = math.inf
    # end-of-step values, each term into the compensated sums, smallest first (a particle
    # that does not move has every term 0, and its values are not used)
    for c in range(m):
        x = x0[c]
        cx = csx[c]
        v = u0[c]
        cv = csv[c]
        for j in range(6, -1, -1):
            x, cx = _kahan(x, cx, b[j, c] / _XDIV[j] * dt * dt)
            v, cv = _kahan(v, cv, b[j, c] / _VDIV[j] * dt)
        x, cx = _kahan(x, cx, a0[c] / 2.0 * dt * dt)
        x, cx = _kahan(x, cx, u0[c] * dt)
        v, cv = _kahan(v, cv, a0[c] * dt)
        nx[c] = x
        ncx[c] = cx
        nv[c] = v
        ncv[c] = cv
    for c in range(m):
        if mask[c] != 0.0 and not (math.isfinite(nx[c]) and math.isfinite(nv[c])):
            return c % n, iterations, evaluations
    return -1, iterations, evaluations


@jit(error_model="numpy", inline="always")
def _park(mask, n, a0, v0, vel, b, e, b_done, e_done, csx, csv):
    """Zero what moves a particle that must not move (pinned or inactive), so the loops can
    run over every component without a branch; v0 is the velocity of the moving ones
    (flat arrays and ``mask`` per component, as in ``_advance``)."""
    for k in range(vel.shape[0]):
        for i in range(n):
            c = k * n + i
            moving = mask[c] != 0.0
            v0[c] = vel[k, i] if moving else 0.0
            if not moving:
                a0[c] = 0.0
                csx[c] = 0.0
                csv[c] = 0.0
                for j in range(7):
                    b[j, c] = 0.0
                    e[j, c] = 0.0
                    b_done[j, c] = 0.0
                    e_done[j, c] = 0.0


@jit(error_model="numpy", _nrt=False, fastmath={"contract"}, no_cpython_wrapper=True,
     no_cfunc_wrapper=True)
def _start(t, state, model, work, fused, mask, a0, v0, b, e, b_done, e_done, csx, csv):
    """The start of a step: the accelerations a0 (``_forces``: compiled here on its own, the
    force code at the nodes is inlined into ``_advance``) and, if every moving particle's is
    finite, the particles that do not move parked (``_park``). Returns the first moving
    particle with a non-finite acceleration, or -1."""
    n = state.n
    a02d = _matrix(a0, 0, state.pos.shape[0], n)
    _forces(t, state, model, a02d, work, fused)
    bad = _first_bad(a02d, mask, n)
    if bad < 0:
        _park(mask, n, a0, v0, state.vel, b, e, b_done, e_done, csx, csv)
    return bad


@jit(error_model="numpy", _nrt=False, fastmath={"contract"}, no_cpython_wrapper=True,
     no_cfunc_wrapper=True)
def _timescale2(a0, b, mask, n):
    """min over moving particles of tau_i^2 / dt^2 (Pham, Rein & Spiegel 2024), or inf
    (flat arrays, ``mask`` per component)."""
    dim = a0.shape[0] // max(n, 1)
    best = math.inf
    for i in range(n):
        if mask[i] == 0.0:
            continue
        start = 0.0
        acc2 = 0.0
        jerk2 = 0.0
        snap2 = 0.0
        for k in range(dim):
            c = k * n + i
            a = a0[c]
            start += a * a
            jerk = 0.0
            snap = 0.0
            for j in range(7):
                a += b[j, c]
                jerk += (j + 1) * b[j, c]
                snap += (j + 1) * j * b[j, c]
            acc2 += a * a
            jerk2 += jerk * jerk
            snap2 += snap * snap
        if not (start >= _MIN_NORMAL and start < math.inf):
            continue  # no acceleration (or an unusable one) at the start of the step
        if start < _ZERO_START2 * acc2:
            # an acceleration at the start that is zero but for round-off (a body at the
            # centre of a symmetric configuration, the figure-eight's at t = 0, whose forces
            # cancel to within the rounding of a fused multiply-add): skipped as an exact zero
            # is. Counted, it gives tau = sqrt(2) |a_end| / |jerk| = sqrt(2) dt whatever the
            # step, every attempt asks for a quarter of itself, and the step collapses
            continue
        tau2 = 2.0 * acc2 / (jerk2 + math.sqrt(snap2 * acc2))
        if tau2 >= _MIN_NORMAL and tau2 < best:
            best = tau2
    return best


@jit(error_model="numpy", inline="always")
def _collapsed(h, t):
    """A step too short for the time to advance by it reliably (or no longer a normal float)."""
    return not (abs(h) > 8.0 * _EPS * abs(t) and abs(h) >= _MIN_NORMAL * 2.0 ** 52)


@jit(error_model="numpy", _nrt=False, fastmath={"contract"}, no_cpython_wrapper=True,
     no_cfunc_wrapper=True)
def _keep(b, e, b_done, e_done, e_valid):
    """b and e of the step just accepted into b_done and e_done; b for e when no prediction
    was made for it (no correction to carry). One pass over the components."""
    for c in range(b.shape[1]):
        for j in range(7):
            b_done[j, c] = b[j, c]
            e_done[j, c] = e[j, c] if e_valid else b[j, c]


@jit(error_model="numpy", _nrt=False, fastmath={"contract"}, no_cpython_wrapper=True,
     no_cfunc_wrapper=True)
def _changed(pos, vel, x_end, v_end, n):
    for k in range(pos.shape[0]):
        for i in range(n):
            if pos[k, i] != x_end[k, i] or vel[k, i] != v_end[k, i]:
                return True
    return False


@jit(error_model="numpy", _nrt=False, fastmath={"contract"}, no_cpython_wrapper=True,
     no_cfunc_wrapper=True)
def _store(memory, valid, dt_last, dt_pred, e_valid, t, tc, evaluations, rejected, capped,
          iterations, pos, vel, x_end, v_end, n):
    memory[MEMORY_VALID] = 1.0 if valid else 0.0
    memory[MEMORY_DT_LAST] = dt_last
    memory[MEMORY_DT_PREDICTED] = dt_pred
    memory[MEMORY_E_VALID] = 1.0 if e_valid else 0.0
    memory[MEMORY_T] = t
    memory[MEMORY_T_COMPENSATION] = tc
    memory[MEMORY_EVALUATIONS] += evaluations
    memory[MEMORY_REJECTED] += rejected
    memory[MEMORY_CAPPED] += capped
    memory[MEMORY_ITERATIONS] += iterations
    for k in range(pos.shape[0]):
        for i in range(n):
            x_end[k, i] = pos[k, i]
            v_end[k, i] = vel[k, i]


# -- the kernel -----------------------------------------------------------------------------------
@jit(error_model="numpy", _nrt=False, fastmath={"contract"}, no_cfunc_wrapper=True)
def advance(t, h, steps, state, model, work, vdep, t_end, tol, memory):
    """Up to ``steps`` accepted IAS15 steps from time ``t`` with first step ``h``.

    ``tol`` is IAS15's epsilon (> 0: adaptive steps; <= 0: every step is ``h``), ``memory``
    the caller's array of ``memory_shape(dim, n)`` (zeroed: cold start), updated in place.
    Returns ``(t, h_next, done, status)`` (``common``)."""
    pos = state.pos
    vel = state.vel
    n = state.n
    dim = pos.shape[0]
    if memory.shape[0] != HEADER + _BLOCKS * dim * n:
        raise ValueError("ias15: memory has the wrong size for this state (see memory_shape)")
    # every scratch array, in one allocation freed at the one exit below (nothing in between
    # raises). Per-component arrays are flat, the components in (k, i) order; ``mask`` is
    # the moving flag per component.
    m = dim * n
    scratch = _scratch(28, m)
    mask = scratch[0]
    fill_active_mask(mask, state.active, state.pinned, n)
    for c in range(n, m):
        mask[c] = mask[c - n]
    a0 = scratch[1]
    acc = scratch[2]
    sx = scratch[3]
    sv = scratch[4]
    nx = scratch[5]
    nv = scratch[6]
    ncx = scratch[7]
    ncv = scratch[8]
    v0 = scratch[9]
    x0 = scratch[10]
    u0 = scratch[11]
    w = scratch[12]
    change = scratch[13]
    g = scratch[14:21]
    csb = scratch[21:28]
    b, e, b_done, e_done, csx, csv, x_end, v_end = _views(memory, dim, n)
    fused = fused_gravity.applies(state, model)

    # warm start only if the state is the one this memory left behind
    warm = memory[MEMORY_VALID] == 1.0 and not _changed(pos, vel, x_end, v_end, n)
    if warm:
        dt_last = memory[MEMORY_DT_LAST]
        dt_pred = memory[MEMORY_DT_PREDICTED]
        e_valid = memory[MEMORY_E_VALID] == 1.0
        tc = memory[MEMORY_T_COMPENSATION] if memory[MEMORY_T] == t else 0.0
    else:
        for x in range(HEADER, memory.shape[0]):
            memory[x] = 0.0
        dt_last = 0.0
        dt_pred = 0.0
        e_valid = False
        tc = 0.0

    adaptive = tol > 0.0
    growth = root7(tol * _FACTORIAL7) if adaptive else 1.0
    has_end = not math.isnan(t_end)

    evaluations = 0
    rejected = 0
    capped = 0
    iterations_total = 0
    done = 0
    need_a0 = True
    # one way out of the loop, its condition (``going``), and of the kernel, through
    # ``_store``: each exit of a compiled loop repeats the clean-up of every variable that
    # dies there. ``valid`` says whether the memory is left usable.
    valid = True
    status = OK
    going = h != 0.0 and math.isfinite(h)
    if not going:
        valid = warm
        status = STEP_COLLAPSED
    while going and done < steps:
        dt = h
        last = False
        if has_end:
            remaining = (t_end - t) + tc
            if t == t_end or remaining == 0.0:
                t = t_end
                tc = 0.0
                going = False
                continue
            if (h > 0.0) != (remaining > 0.0):
                h = -h  # towards t_end
                dt = h
            if abs(dt) >= abs(remaining):
                dt = remaining
                last = True
        if not math.isfinite(t + dt):
            valid = False
            status = TIME_OVERFLOW
            going = False
            continue
        # the predictor for this step length
        if dt != dt_pred:
            if dt_last != 0.0:
                _predict(b_done, e_done, b, e, dt / dt_last, False)
                e_valid = True
            elif dt_pred != 0.0:
                # cold start: the rejected attempt's b, rescaled
                _predict(b_done, e_done, b, e, dt / dt_pred, True)
            dt_pred = dt
        if need_a0:
            bad = _start(t - tc, state, model, work, fused, mask, a0, v0, b, e, b_done, e_done,
                         csx, csv)
            evaluations += 1
            if bad >= 0:  # nothing a shorter step can cure
                valid = False
                status = bad
                going = False
                continue
            need_a0 = False

        attempt, iterations, count = _advance(t - tc, dt, state, model, work, vdep, fused, mask,
                                              a0, v0, x0, u0, b, csx, csv, g, csb, acc, sx, sv,
                                              w, change, nx, ncx, nv, ncv)
        evaluations += count
        if attempt >= 0 and not adaptive:
            valid = False
            status = attempt
            going = False
            continue
        retry = OK  # or the status to return should the step retried collapse
        if attempt >= 0:
            # a non-finite node or result: retry with a quarter of the step
            h = dt * _SAFETY
            if dt_last == 0.0:
                for j in range(7):  # nothing finite to rescale
                    for c in range(m):
                        b[j, c] = 0.0
                dt_pred = 0.0
            retry = attempt
        elif adaptive:
            tau2 = _timescale2(a0, b, mask, n)
            if tau2 < math.inf:
                dt_new = math.sqrt(tau2) * dt * growth
            else:
                dt_new = dt / _SAFETY
            if abs(dt_new) < _SAFETY * abs(dt):
                h = dt_new
                retry = STEP_COLLAPSED
            elif last:
                # the proposal before the step was shortened stands, unless a substantial
                # landing step found a shorter timescale
                if abs(dt) >= _SAFETY * abs(h) and abs(dt_new) < abs(h):
                    h = dt_new
            else:
                if abs(dt_new) > abs(dt) / _SAFETY:
                    dt_new = dt / _SAFETY
                h = dt_new
        if retry != OK:
            rejected += 1
            if _collapsed(h, t):
                valid = False
                status = retry
                going = False
            continue
        if iterations >= _MAX_ITERATIONS:
            capped += 1
        iterations_total += iterations

        # accept
        box = state.box
        for k in range(dim):
            for i in range(n):
                c = k * n + i
                if mask[c] != 0.0:
                    x = nx[c]
                    cx = ncx[c]
                    if box > 0.0:
                        wrapped = wrap_scalar(x, box)
                        if wrapped != x:
                            x = wrapped
                            cx = 0.0  # the compensation belonged to the unwrapped value
                    pos[k, i] = x
                    vel[k, i] = nv[c]
                    csx[c] = cx
                    csv[c] = ncv[c]
        if last:
            t = t_end
            tc = 0.0
        else:
            t, tc = _kahan(t, tc, dt)
        _keep(b, e, b_done, e_done, e_valid)
        dt_last = dt
        _predict(b_done, e_done, b, e, h / dt, False)
        e_valid = True
        dt_pred = h
        need_a0 = True
        done += 1
        going = not last
    _store(memory, valid, dt_last, dt_pred, e_valid, t, tc, evaluations, rejected, capped,
           iterations_total, pos, vel, x_end, v_end, n)
    _release(scratch)
    return t, h, done, status
