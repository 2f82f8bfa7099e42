"""The largest stable step: the network's highest frequency and each integrator's limit.

An explicit integrator is stable on an undamped oscillator x'' = -omega^2 x only while
z = omega h stays below a limit of its own; a network of springs, linearised about its current
state, is a set of such oscillators, its normal modes, and the one that counts is the fastest
(the lecture's "large k means instability, unfeasibly small dt"; Baraff & Witkin, "Large
steps in cloth simulation", SIGGRAPH 1998, on why explicit cloth needs small steps). So

    stable_dt = z_max(integrator) / omega_max,        omega_max^2 = lambda_max(M^-1/2 K M^-1/2)

**The stiffness operator.** K is the Hessian of the spring potential U = sum 1/2 k (r - l)^2
at the current positions. For one spring with d = p_b - p_a, r = |d|, u = d / r, its block is

    H = k u u^T + k (1 - l / r) (I - u u^T)

(the axial stiffness k, plus the geometric term of a stretched spring: tension T = k (r - l)
over length r across the spring, as a taut string; negative for a compressed spring), and K
has +H on the (a, a) and (b, b) blocks and -H on (a, b) and (b, a). A zero-rest-length spring
is linear: H = k I. Pinned and inactive particles do not move: their rows and columns are
removed (a spring to a pinned particle still stiffens the free end). Mass weighting
M^-1/2 K M^-1/2 makes the operator symmetric with eigenvalues omega_j^2 (the squared normal-mode
frequencies of the linearised motion).

**Power iteration** (von Mises 1929; Golub & Van Loan, Matrix Computations): from a
fixed pseudo-random start (numpy's generator with a constant seed, so the answer is the same on
every call), x <- A x / |A x|, with the Rayleigh quotient rho_k = x^T A x, which rises towards
lambda_max from below. The stopping rule compares rho_k with rho_{k/2}: a 2-D lattice's many
modes close below the top make the quotient converge like lambda (1 - c / k), and then
rho_k - rho_{k/2} estimates what is still missing; the iteration stops once that is below
``TOLERANCE`` rho_k (after at least ``MIN_ITERATIONS``, at most ``MAX_ITERATIONS``) and uses
rho_k + (rho_k - rho_{k/2}). The result is lambda_max to about ``TOLERANCE`` (relative), from
either side: where the top two modes are closer than that (a cloth pinned at two corners has
such a pair, 0.3e-4 to 4e-4 apart) the iteration settles on a mix of them. Against numpy's
dense eigenvalues, omega_max came out within 5e-5 for cloths of 6 x 6 to 16 x 16, in 80 to
420 iterations of one pass over the springs each. If the quotient settles on a negative value (strongly compressed springs can make
the largest eigenvalue in magnitude negative), the iteration runs again on A + |rho| I, whose
top eigenvalue is lambda_max + |rho|.

**Gravity near close pairs** is an estimate, not an eigenvalue: the Hessian of one pair's
potential -G m_i m_j / s, s = sqrt(r^2 + eps^2), acting on their separation has eigenvalues
G M / s^3 (twice, across) and G M (eps^2 - 2 r^2) / s^5 (along), M = m_i + m_j; the larger in
magnitude, G M max(1, |eps^2 - 2 r^2| / s^2) / s^3, which is 2 G M / r^3 without softening, is
taken for the closest pair. A pinned or test body counts only as a source of the other's
acceleration. ``PointMass`` (a fixed attractor, mu = G M) gives mu max(...) / s^3 per
particle. The spring and gravity parts are added (Weyl's inequality: the top eigenvalue of a
sum of symmetric operators is at most the sum of their top eigenvalues).

Not counted: spring damping and ``Drag`` (dissipative: they shrink an oscillation, though a
very heavy dashpot, c h / m of order 1, has an explicit limit of its own), ``Coulomb``,
``Buoyancy``, ``Wind`` and the other terms. The operator is taken at the current state: a
network that stretches as it moves (a cloth falling onto its pins) gets slightly stiffer
across its springs, so run a little below the step returned.

**Each integrator's limit** z_max is computed from its coefficients, not quoted: the one-step
map of x'' = -omega^2 x in the variables (x, v / omega) is a 2 x 2 amplification matrix
G(z), z = omega h (``amplification_matrix``); for the splitting methods (det G = 1) the step is
stable while |trace G| <= 2, for the Runge-Kutta methods while the spectral radius of G is <= 1
(Hairer, Lubich & Wanner, Geometric Numerical Integration; Hairer & Wanner, Solving Ordinary
Differential Equations II, section IV.2). z_max is the first z where this fails (a fine scan, then bisection):

    symplectic_euler, leapfrog, verlet   2            (trace = 2 - z^2)
    yoshida4                             1.5734...    (its substeps are 1.35 h and -1.70 h)
    pefrl                                2.9894...
    rk4                                  2 sqrt(2)    (|R(iz)|^2 = 1 - z^6/72 + z^8/576)
    rk45                                 0.9972...    (Dormand-Prince's fifth-order update)
    euler                                0            (|1 + iz| > 1 for every z > 0)

RK4's 2.785 is its limit on the negative real axis (decaying modes), not for oscillations.
``euler`` amplifies every undamped oscillation at every step (by sqrt(1 + z^2), slowly for
small z): its stable step is 0.0 as soon as anything oscillates. ``rk45`` chooses its own
steps (``sim.dt`` is only its first), so ``stable_dt`` refuses it with a ValueError; its
update amplifies an undamped mode only slightly beyond z = 0.9972 (by 1e-4 per step at
z = 1.1), and at loose tolerances its error control does take such steps, holding the slow
growth back by rejections. ``estimate(sim, "rk45")`` still gives 0.9972 / omega_max, the step
below which it would not amplify any mode.
"""
import functools
import math
from collections import namedtuple

import numpy as np
from .cache import jit

from .forces import gravity as _gravity
from .forces import point_mass as _point_mass
from .forces import springs as _springs
from .forces._kernels import pair_box
from .integrators import INTEGRATORS, check_name
from .integrators.dormand_prince import _A as _DP_A
from .integrators import janus as _janus
from .integrators import wisdom_holman
from .integrators.splitting import SCHEMES
from .space import wrap_scalar

#: relative stopping tolerance of the power iteration on omega_max^2
TOLERANCE = 1e-4
MIN_ITERATIONS = 32
MAX_ITERATIONS = 200_000
#: the seed of the power iteration's start vector (fixed: the same answer on every call)
SEED = 0x5AB1E

#: the classic fourth-order Runge-Kutta tableau (Kutta 1901)
_RK4_A = np.array([[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, 0.0, 0.0],
                   [0.0, 0.5, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
_RK4_B = np.array([1.0, 2.0, 2.0, 1.0]) / 6.0
#: Dormand-Prince 5(4): the propagated (fifth-order) solution's weights are its last row
_RK_TABLEAUS = {"rk4": (_RK4_A, _RK4_B), "rk45": (_DP_A[:6, :6], _DP_A[6, :6])}

Estimate = namedtuple("Estimate", "dt limit omega omega_springs omega_gravity iterations converged")
Estimate.__doc__ = """What ``estimate(sim)`` found.

``dt``: the largest stable step (``inf`` when nothing limits it, 0.0 when no step is stable);
``limit``: the integrator's z_max = omega h; ``omega``: the frequency used,
sqrt(omega_springs^2 + omega_gravity^2); ``iterations``: power iterations taken;
``converged``: the stopping rule was met (False after ``MAX_ITERATIONS``; the last estimate is
used all the same)."""


# -- the integrators' limits -------------------------------------------------------------------

def amplification_matrix(integrator, z):
    """The one-step matrix of ``integrator`` on x'' = -omega^2 x, z = omega h, acting on
    (x, v / omega): ``[x, v/omega]_{n+1} = G(z) [x, v/omega]_n``. ``z`` may be an array (the
    matrices are then stacked on the last two axes)."""
    check_name(integrator)
    z = np.asarray(z, dtype=np.float64)
    one, zero = np.ones_like(z), np.zeros_like(z)
    if integrator in SCHEMES or integrator in _KEPLER_TABLES:
        drifts, kicks = (SCHEMES[integrator][:2] if integrator in SCHEMES
                         else _KEPLER_TABLES[integrator])
        g = [[one, zero], [zero, one]]
        for c, d in zip(drifts, kicks):
            # drift x += c h v, i.e. x += c z (v / omega); then kick v / omega -= d z x
            g[0] = [g[0][0] + c * z * g[1][0], g[0][1] + c * z * g[1][1]]
            g[1] = [g[1][0] - d * z * g[0][0], g[1][1] - d * z * g[0][1]]
        return np.moveaxis(np.array(g), (0, 1), (-2, -1))
    if integrator == "euler":
        g = [[one, z], [-z, one]]
        return np.moveaxis(np.array(g), (0, 1), (-2, -1))
    a, b = _RK_TABLEAUS[integrator]
    # y' = J y with h J = z [[0, 1], [-1, 0]]: stage k_s = hJ (y + sum_j a_sj k_j)
    hj = np.moveaxis(np.array([[zero, z], [-z, zero]]), (0, 1), (-2, -1))
    eye = np.broadcast_to(np.eye(2), hj.shape)
    stages = []
    for s in range(len(b)):
        y = eye.copy()
        for j in range(s):
            if a[s, j] != 0.0:
                y = y + a[s, j] * stages[j]
        stages.append(hj @ y)
    return eye + sum(b[s] * stages[s] for s in range(len(b)))


def _kepler_table(drifts, kicks):
    """A Kepler-drift splitting as (drift, kick) stages: on a scene without a Kepler part its
    drifts are straight lines, and it is this splitting scheme."""
    return tuple(drifts), tuple(kicks) + (0.0,)


#: whfast and saba (its default method) as splitting schemes, for their limits on an
#: oscillator in the kick
def _leapfrog_composition(gammas):
    """Drift-kick-drift leapfrogs of steps g_i h in a row, the adjacent half drifts merged."""
    drifts = [0.5 * gammas[0]] + [0.5 * (a + b) for a, b in zip(gammas[:-1], gammas[1:])]
    return tuple(drifts) + (0.5 * gammas[-1],), tuple(gammas) + (0.0,)


_KEPLER_TABLES = {"whfast": _kepler_table(*wisdom_holman.WH),
                  "saba": _kepler_table(*wisdom_holman.saba_scheme(wisdom_holman.DEFAULT_SABA)[:2]),
                  # janus off its lattice (the default order 6)
                  "janus": _leapfrog_composition(list(_janus.stage_coefficients(6)))}
#: adaptive methods without a fixed-step limit of their own here
_NO_LIMIT = ("ias15",)


def _stable(integrator, z, slack=0.0):
    g = amplification_matrix(integrator, z)
    if integrator in SCHEMES or integrator in _KEPLER_TABLES:
        # det G = 1 (symplectic): stable while both eigenvalues stay on the unit circle
        return np.abs(g[..., 0, 0] + g[..., 1, 1]) <= 2.0 + slack
    return np.abs(np.linalg.eigvals(g)).max(axis=-1) <= 1.0 + slack


@functools.lru_cache(maxsize=None)
def step_limit(integrator):
    """z_max = (omega h)_max of ``integrator`` on an undamped oscillator (see the module):
    the first z where its amplification matrix stops being stable; 0.0 for ``euler``."""
    check_name(integrator)
    if integrator in _NO_LIMIT:
        raise ValueError(f"{integrator} adapts its own step: it has no fixed-step limit")
    if integrator == "euler":
        return 0.0
    grid = np.arange(1, 10001) * 1e-3  # z in (0, 10]: every limit lies below 3.5
    # the scan forgives round-off where |trace| only touches 2 (G = -I inside the region);
    # the bisection within the first failing grid cell is strict
    bad = ~_stable(integrator, grid, slack=1e-9)
    if not bad.any():
        raise RuntimeError(f"{integrator} is stable up to omega h = 10: not an explicit method?")
    first = int(np.argmax(bad))
    lo, hi = (grid[first - 1] if first else 0.0), grid[first]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if bool(_stable(integrator, mid)):
            lo = mid
        else:
            hi = mid
    return float(lo)


def step_limits():
    """``{integrator: z_max}`` for every integrator of ``engine.INTEGRATORS`` but ``ias15``
    (which adapts its step with no fixed-step limit)."""
    return {name: step_limit(name) for name in INTEGRATORS if name not in _NO_LIMIT}


# -- the spring network ------------------------------------------------------------------------

@jit(error_model="numpy")
def _spring_blocks(pos, active, box, params, f0, indices, i0, i1, out_a, out_b, out_h,
                   start):
    """The Hessian blocks H of one Springs term's springs with both ends active, written from
    row ``start`` of the outputs; returns the next free row, or -(s + 1) for a spring s with
    l > 0 whose ends coincide (no direction: the step itself would fail)."""
    dim = pos.shape[0]
    m = (i1 - i0) // 2
    row = start
    for s in range(m):
        a = indices[i0 + 2 * s]
        b = indices[i0 + 2 * s + 1]
        if not (active[a] and active[b]):
            continue
        k = params[f0 + s]
        rest = params[f0 + m + s]
        r2 = 0.0
        for c in range(dim):
            d = wrap_scalar(pos[c, b] - pos[c, a], box)  # the nearest image, as the force
            r2 += d * d
        r = math.sqrt(r2)
        if rest == 0.0:
            axial = k
            across = k
        elif r == 0.0:
            return -(s + 1)
        else:
            axial = k
            across = k * (1.0 - rest / r)
        for p in range(dim):
            up = wrap_scalar(pos[p, b] - pos[p, a], box) / r if r > 0.0 else 0.0
            for q in range(dim):
                uq = wrap_scalar(pos[q, b] - pos[q, a], box) / r if r > 0.0 else 0.0
                uu = up * uq
                out_h[row, p, q] = axial * uu + across * ((1.0 if p == q else 0.0) - uu)
        out_a[row] = a
        out_b[row] = b
        row += 1
    return row


@jit(error_model="numpy")
def _apply(pa, pb, h, scale, x, y):
    """y = A x with A = M^-1/2 K M^-1/2 (``scale`` = 1/sqrt(m) on moving particles, else 0)."""
    dim = x.shape[0]
    for c in range(dim):
        for i in range(x.shape[1]):
            y[c, i] = 0.0
    u = np.empty(dim)
    for s in range(pa.shape[0]):
        a = pa[s]
        b = pb[s]
        sa = scale[a]
        sb = scale[b]
        for c in range(dim):
            u[c] = sb * x[c, b] - sa * x[c, a]
        for p in range(dim):
            w = 0.0
            for q in range(dim):
                w += h[s, p, q] * u[q]
            y[p, a] -= sa * w
            y[p, b] += sb * w


@jit(error_model="numpy")
def _power(pa, pb, h, scale, x, shift, tol, min_iter, max_iter):
    """Power iteration on A + shift I from x: ``(rho, missing, iterations, converged)``."""
    dim, n = x.shape
    y = np.empty((dim, n))
    history = np.empty(max_iter + 1)
    norm = math.sqrt(np.sum(x * x))
    if norm == 0.0:
        return 0.0, 0.0, 0, True
    x = x / norm
    rho = 0.0
    missing = 0.0
    for k in range(1, max_iter + 1):
        _apply(pa, pb, h, scale, x, y)
        rho = 0.0
        ny = 0.0
        for c in range(dim):
            for i in range(n):
                y[c, i] += shift * x[c, i]
                rho += x[c, i] * y[c, i]
                ny += y[c, i] * y[c, i]
        history[k] = rho
        ny = math.sqrt(ny)
        if ny == 0.0:
            return 0.0, 0.0, k, True  # the start lies in A's null space: A is zero there
        for c in range(dim):
            for i in range(n):
                x[c, i] = y[c, i] / ny
        missing = abs(rho - history[k // 2]) if k >= 2 else abs(rho)
        if k >= min_iter and missing <= tol * abs(rho):
            return rho, missing, k, True
    return rho, missing, max_iter, False


def _moving(state):
    n = state.n
    return state.active[:n] & ~state.pinned[:n]


def _spring_network(state, model):
    """All spring Hessian blocks ``(a, b, H)`` of the declared Springs terms."""
    counts = [(model.index_offsets[s + 1] - model.index_offsets[s]) // 2
              for s in range(len(model.kinds)) if model.kinds[s] == _springs.KIND]
    total = int(sum(counts))
    dim = state.pos.shape[0]
    pa = np.empty(total, dtype=np.int64)
    pb = np.empty(total, dtype=np.int64)
    h = np.empty((total, dim, dim))
    row = 0
    term = 0
    for s in range(len(model.kinds)):
        if model.kinds[s] != _springs.KIND:
            continue
        got = _spring_blocks(state.pos, state.active, state.box, model.params,
                             model.param_offsets[s], model.indices, model.index_offsets[s],
                             model.index_offsets[s + 1], pa, pb, h, row)
        if got < 0:
            raise ValueError(f"spring {-got - 1} of Springs term {term} has coincident ends and "
                             "a rest length > 0: it has no direction (a step would fail too)")
        row = got
        term += 1
    return pa[:row], pb[:row], h[:row]


def stiffness_matrix(sim):
    """The dense mass-weighted stiffness matrix M^-1/2 K M^-1/2 of ``sim``'s springs over its
    moving (active, unpinned) particles, ``(d, d)`` with d = dim x moving, coordinates ordered
    particle by particle; plus the moving particles' indices. For checks on small systems:
    ``stable_dt`` never forms it. Massless moving particles are left out."""
    state, model = sim.kernel_arguments()
    pa, pb, h = _spring_network(state, model)
    moving = np.flatnonzero(_moving(state) & (state.mass[:state.n] > 0.0))
    dim = state.pos.shape[0]
    where = {int(i): row for row, i in enumerate(moving)}
    out = np.zeros((dim * len(moving), dim * len(moving)))
    for a, b, block in zip(pa, pb, h):
        ia, ib = where.get(int(a)), where.get(int(b))
        sa = 1.0 / math.sqrt(state.mass[a]) if ia is not None else 0.0
        sb = 1.0 / math.sqrt(state.mass[b]) if ib is not None else 0.0
        for i, si in ((ia, sa), (ib, sb)):
            for j, sj in ((ia, sa), (ib, sb)):
                if i is None or j is None:
                    continue
                sign = 1.0 if i == j else -1.0
                out[dim * i:dim * i + dim, dim * j:dim * j + dim] += sign * si * sj * block
    return out, moving


def apply_stiffness(sim, x):
    """``M^-1/2 K M^-1/2 x`` for ``x`` of shape (N, dim) (zero on particles that do not move):
    the operator the power iteration runs on, for checks against the forces."""
    state, model = sim.kernel_arguments()
    pa, pb, h = _spring_network(state, model)
    scale = _scale(state)
    x = np.ascontiguousarray(np.asarray(x, dtype=np.float64).T) * (scale > 0.0)
    y = np.empty_like(x)
    _apply(pa, pb, h, scale, x, y)
    return y.T


def _scale(state):
    n = state.n
    mass = state.mass[:n]
    scale = np.zeros(n)
    ok = _moving(state) & (mass > 0.0)
    scale[ok] = 1.0 / np.sqrt(mass[ok])
    return scale


@jit(error_model="numpy")
def _massless_spring(pa, pb, h, moving, mass):
    """True if a moving massless particle hangs on a spring of non-zero stiffness."""
    for s in range(pa.shape[0]):
        stiff = False
        for p in range(h.shape[1]):
            for q in range(h.shape[2]):
                if h[s, p, q] != 0.0:
                    stiff = True
        if not stiff:
            continue
        for i in (pa[s], pb[s]):
            if moving[i] and mass[i] == 0.0:
                return True
    return False


def spring_frequency(sim, tol=TOLERANCE, max_iterations=MAX_ITERATIONS):
    """``(omega_max, iterations, converged)`` of ``sim``'s spring network (see the module):
    the square root of the power iteration's estimate of the top eigenvalue of
    M^-1/2 K M^-1/2 over the moving particles; inf if a massless particle moves on a spring."""
    state, model = sim.kernel_arguments()
    pa, pb, h = _spring_network(state, model)
    if pa.shape[0] == 0:
        return 0.0, 0, True
    n = state.n
    moving = _moving(state)
    if _massless_spring(pa, pb, h, moving, state.mass[:n]):
        return math.inf, 0, True
    scale = _scale(state)
    dim = state.pos.shape[0]
    start = np.random.default_rng(SEED).standard_normal((dim, n)) * (scale > 0.0)
    rho, missing, its, ok = _power(pa, pb, h, scale, start.copy(), 0.0, tol, MIN_ITERATIONS,
                                   max_iterations)
    if rho < 0.0:  # the largest in magnitude is negative: shift it to the bottom, run again
        shift = abs(rho) + missing
        top, missing, more, ok = _power(pa, pb, h, scale, start.copy(), shift, tol,
                                        MIN_ITERATIONS, max_iterations)
        rho, its = top - shift, its + more
    lam = max(rho + missing, 0.0)  # the stopping rule's estimate from above
    return math.sqrt(lam), its, ok


# -- gravity near close pairs ------------------------------------------------------------------

@jit(error_model="numpy", inline="always")
def _pair_rate(C, r2, eps2):
    """Spectral radius of a softened pair's Hessian per unit of C = G M: C max(1,
    |eps^2 - 2 r^2| / s^2) / s^3, s^2 = r^2 + eps^2 (2 C / r^3 without softening)."""
    s2 = r2 + eps2
    if s2 == 0.0:
        return math.inf
    along = abs(eps2 - 2.0 * r2) / s2
    return C * max(1.0, along) / (s2 * math.sqrt(s2))


@jit(error_model="numpy")
def _gravity_rate(pos, mass, active, test, moving, n, G, eps2, box):
    dim = pos.shape[0]
    top = 0.0
    for i in range(n):
        if not active[i]:
            continue
        for j in range(i + 1, n):
            if not active[j]:
                continue
            # the pull of each source on the other, if that one moves
            C = 0.0
            if moving[j] and not test[i]:
                C += G * mass[i]
            if moving[i] and not test[j]:
                C += G * mass[j]
            if C == 0.0:
                continue
            r2 = 0.0
            for c in range(dim):
                d = pos[c, j] - pos[c, i]
                d = wrap_scalar(d, box)  # the nearest image (unchanged in open space)
                r2 += d * d
            top = max(top, _pair_rate(C, r2, eps2))
    return top


@jit(error_model="numpy")
def _point_mass_rate(pos, moving, n, params, f0, indices, i0, i1):
    dim = pos.shape[0]
    mu = params[f0]
    eps2 = params[f0 + 1]
    top = 0.0
    for k in range(n if i1 == i0 else i1 - i0):
        i = k if i1 == i0 else indices[i0 + k]
        if i >= n or not moving[i]:
            continue
        r2 = 0.0
        for c in range(dim):
            d = pos[c, i] - params[f0 + 2 + c]
            r2 += d * d
        top = max(top, _pair_rate(mu, r2, eps2))
    return top


def gravity_frequency(sim):
    """The close-pair estimate (see the module) of ``sim``'s NBodyGravity and PointMass
    terms: sqrt of the largest pair value, 0.0 without such terms."""
    state, model = sim.kernel_arguments()
    n = state.n
    moving = _moving(state)
    top = 0.0
    for s in range(len(model.kinds)):
        f0 = model.param_offsets[s]
        if model.kinds[s] == _gravity.KIND:
            G, eps2 = model.params[f0], model.params[f0 + 1]
            box = pair_box(model.params, f0, state)
            top = max(top, _gravity_rate(state.pos, state.mass, state.active, state.test,
                                         moving, n, G, eps2, box))
        elif model.kinds[s] == _point_mass.KIND:
            top = max(top, _point_mass_rate(state.pos, moving, n, model.params, f0, model.indices,
                                            model.index_offsets[s], model.index_offsets[s + 1]))
    return math.sqrt(top)


# -- the stable step ---------------------------------------------------------------------------

def estimate(sim, integrator=None):
    """The stable step of ``integrator`` (default: ``sim``'s) for ``sim``'s declared springs
    and gravity at its current state, with the frequencies it comes from (an ``Estimate``;
    see the module). For ``rk45`` it is the step below which its update amplifies no mode."""
    limit = step_limit(sim.integrator if integrator is None else integrator)
    w_springs, its, ok = spring_frequency(sim)
    w_gravity = gravity_frequency(sim)
    omega = math.sqrt(w_springs ** 2 + w_gravity ** 2)
    if omega == 0.0:
        dt = math.inf
    elif limit == 0.0 or math.isinf(omega):
        dt = 0.0
    else:
        dt = limit / omega
    return Estimate(dt, limit, omega, w_springs, w_gravity, its, ok)


def stable_dt(sim, integrator=None):
    """The largest stable |dt| of ``integrator`` (default: ``sim``'s) at ``sim``'s current
    state, in code units: ``inf`` when nothing declared limits the step, 0.0 when no step is
    stable (``euler`` on any oscillation, a massless particle on a spring, coincident bodies
    without softening). ``rk45`` is refused (ValueError): it adapts its own step."""
    name = check_name(sim.integrator if integrator is None else integrator)
    if name in _NO_LIMIT:
        raise ValueError(f"stable_dt is the step limit of a fixed-step integrator; {name} adapts "
                         "its own step (sim.dt is only its first)")
    if name == "rk45":
        raise ValueError(
            "stable_dt is the step limit of a fixed-step integrator; rk45 adapts its own step "
            "(sim.dt is only its first) and its error control keeps it stable. Its update "
            f"amplifies no mode for omega h < {step_limit('rk45'):.4f}: "
            "engine.stability.estimate(sim, 'rk45') gives that step")
    return estimate(sim, name).dt


__all__ = ["stable_dt", "estimate", "Estimate", "step_limit", "step_limits",
           "amplification_matrix", "spring_frequency", "gravity_frequency", "stiffness_matrix",
           "apply_stiffness", "TOLERANCE", "MIN_ITERATIONS", "MAX_ITERATIONS", "SEED"]
