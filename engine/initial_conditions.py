"""Initial conditions for gravitating and charged many-body scenes, as plain numpy arrays.

Every function returns a :class:`Bodies` (``mass`` (n,), ``pos`` (n, dim), ``vel`` (n, dim),
``charge`` (n,): C-contiguous float64 arrays) that ``add_to(sim, bodies)`` puts into a
``Simulation``. ``seed`` is an int >= 0 or a ``numpy.random.Generator`` (which is then
advanced); the same int gives the same bits. ``mass`` is always the total mass, shared equally
(``mass / n`` each). ``dim`` is 2 or 3. In 2-D the engine's gravity is the 3-D 1/r^2 law
restricted to the plane, so a 2-D model is a razor-thin disk in 3-D space.

The models:

``plummer``
    Plummer's (1911, MNRAS 71, 460) sphere: density
    rho(r) = 3 M / (4 pi a^3) (1 + r^2/a^2)^(-5/2), potential Phi(r) = -G M / sqrt(r^2 + a^2),
    mass within r M(<r) = M r^3 / (r^2 + a^2)^(3/2), half-mass radius
    a / sqrt(2^(2/3) - 1) = 1.3048 a, potential energy -3 pi G M^2 / (32 a).
    Sampled as Aarseth, Henon & Wielen (1974, A&A 37, 183) do: the radius from the inverse of
    the cumulative mass, the speed q v_esc from the isotropic distribution function
    f(E) ~ E^(7/2), i.e. q with density ~ q^2 (1 - q^2)^(7/2), by rejection (von Neumann 1951)
    under the bound 0.1 (the maximum is 0.092 at q^2 = 2/9).
    In 2-D it is Kuzmin's (1956, Astron. Zh. 33, 27) disk (Toomre's 1963 model 1, ApJ 138, 385):
    the razor-thin disk of surface density Sigma(R) = a M / (2 pi (R^2 + a^2)^(3/2)), whose
    potential in its plane is exactly Plummer's, -G M / sqrt(R^2 + a^2), so its in-plane forces
    are those of the engine's 2-D gravity. Mass within R: M (1 - a / sqrt(R^2 + a^2)), half-mass
    radius sqrt(3) a. Its isotropic equilibrium follows from Eddington's inversion done in two
    dimensions (Binney & Tremaine 2008, Galactic Dynamics, sec. 4.3, for the 3-D one): with the
    relative potential Psi = -Phi and E = Psi - v^2/2, Sigma = 2 pi integral_0^Psi f(E) dE, and
    Sigma ~ Psi^3, so f(E) ~ E^2. At radius R the kinetic energy u = v^2/2 then has density
    ~ (Psi - u)^2 on [0, Psi], sampled exactly as u = Psi (1 - Y^(1/3)) with Y uniform.
    So the 2-D model is a true equilibrium of the engine's 2-D gravity (not a projection).
    Truncation: the bodies are the inner ``mass_cut`` of a model of mass ``mass / mass_cut``
    (radii drawn from the cumulative mass below that fraction), so the bodies weigh ``mass``
    in all and inside the cut the density and velocities are the untruncated model's: in 3-D
    the missing outer shell exerts no force inside it (Newton's theorem); in 2-D the missing
    outer rings pull outwards, by a fraction of order (1 - mass_cut) (R/R_cut)^3 of the pull
    inwards at R (a ring of radius R_c pulls a point inside it, r << R_c, outwards by
    G m r / (2 R_c^3)). Measured: 2T/|W| = 1.002 +- 0.003 (60 samples of 2000).
    Defaults: mass_cut = 0.999 in 3-D (r <= 38.7 a) and 0.95 in 2-D (R <= 19.97 a). The Kuzmin
    disk's Sigma ~ R^-3 tail is heavy: the sample's far bodies move its centre of mass, so its
    dense core sits off the origin by a random ~4 a / sqrt(n) (0.13 a rms at n = 1000 with
    0.95; 0.29 a with 0.99; the 3-D sphere's is 0.09 a).

``uniform_cube``
    n bodies uniform in the cube [-side/2, side/2]^dim (a square in 2-D), at rest.

``cold_disk``
    n bodies uniform in the disk R <= radius of the x-y plane (R^2 uniform, angle uniform), at
    rest; in 3-D, z uniform in [-thickness/2, thickness/2].

``two_clumps``
    two Plummer clumps of n/2 bodies and mass/2 each, centres at x = -+separation/2, moving
    towards each other at relative speed ``speed`` (each at speed/2): a head-on collision.

``disk_galaxy``
    an exponential disk (Freeman 1970, ApJ 160, 811: Sigma(R) ~ exp(-R/h), here cut at R = 6 h,
    radii from the inverse cumulative mass 1 - (1 + x) e^-x, x = R/h) holding round(n
    disk_fraction) bodies, and a Plummer bulge (the 2-D Kuzmin disk in 2-D) of the other
    bodies, all of mass mass/n. In 3-D the disk's vertical profile is the isothermal sheet
    rho ~ sech^2(z/z0) (Spitzer 1942, ApJ 95, 329) with z0 = ``thickness``. Disk bodies move
    counter-clockwise about +z on circular orbits of speed v_c(R) = sqrt(G M(<R) / R), where
    M(<R) is the model's mass within the sphere of radius R: the spherical approximation,
    which treats the disk's mass as if it were spherically distributed (a thin exponential
    disk alone really turns faster, by 3% at R = h, 15-16% at 2-4 h and 3% at 10 h: Freeman's
    1970 Bessel-function formula; so the disk starts slightly sub-circular and rings). The
    bulge's contribution is exact (Plummer's sphere in 3-D, Kuzmin's in-plane force, the same
    formula, in 2-D). To that a gaussian velocity of standard deviation ``dispersion`` v_c(R)
    per component is added. The bulge is sampled in its own equilibrium (it ignores the disk).
    The disk bodies come first: indices [0, round(n disk_fraction)). The bulge's own centre of
    mass is put on the disk's rotation axis, then the whole galaxy is moved to its centre of
    mass frame (which moves the rotation centre off the origin by the disk's sampling noise,
    about 0.03 h at 3000 disk bodies: measure rotation about the bulge's centre of mass).

``place``
    a copy rotated about the x axis (3-D), shifted, and given a bulk velocity.

``galaxy_pair``
    two disk galaxies of n/2 bodies each, on a Keplerian relative orbit of pericentre
    ``pericenter`` and eccentricity ``eccentricity`` (point masses; the default 0.95 is a bound,
    nearly parabolic orbit, like Toomre & Toomre's 1972 parabolic encounters, ApJ 178, 623),
    starting ``separation`` apart and approaching. The first galaxy (at -x) spins in the
    orbit's sense (prograde: the encounter that raises long tidal tails); the second is tilted
    about the x axis by ``tilt``.

``plasma``
    n bodies uniform in a cube, at rest, of charge +charge and -charge alternately (neutral) or
    all +charge: the one- or two-component plasma of Coulomb tests.

Isolated models (plummer, two_clumps, disk_galaxy, galaxy_pair) are moved to their centre of
mass frame (zero total position and momentum, up to rounding). The geometric ones (cube,
disk, plasma) start at rest with their box or disk centred on the origin; their sample's centre
of mass is off by about side / sqrt(12 n).
"""
import math
import numbers
from dataclasses import dataclass

import numpy as np

from ._validate import finite_array, finite_float, nonnegative_float, positive_float, vector

__all__ = ["Bodies", "plummer", "uniform_cube", "cold_disk", "two_clumps", "disk_galaxy",
           "place", "galaxy_pair", "plasma", "add_to"]

#: Default fraction of a Plummer model's mass that is sampled, by dimension (see the module doc).
PLUMMER_MASS_CUT = {2: 0.95, 3: 0.999}
#: Where the exponential disk is cut, in scale lengths.
DISK_CUT = 6.0
# q^2 (1 - q^2)^(7/2) peaks at 0.092 (q^2 = 2/9): 0.1 bounds it for the rejection.
_SPEED_BOUND = 0.1


@dataclass(frozen=True, eq=False)
class Bodies:
    """A set of bodies: ``mass`` (n,), ``pos`` (n, dim), ``vel`` (n, dim), ``charge`` (n,).

    The arrays are new C-contiguous float64 copies of what is given, checked to be finite with
    matching shapes (dim 2 or 3) and masses >= 0.
    """
    mass: np.ndarray
    pos: np.ndarray
    vel: np.ndarray
    charge: np.ndarray

    def __post_init__(self):
        arrays = {name: np.ascontiguousarray(finite_array(f"Bodies.{name}", getattr(self, name)))
                  for name in ("mass", "pos", "vel", "charge")}
        mass, pos = arrays["mass"], arrays["pos"]
        if mass.ndim != 1:
            raise ValueError(f"Bodies.mass must be 1-D, got shape {mass.shape}")
        n = mass.shape[0]
        if pos.ndim != 2 or pos.shape[0] != n or pos.shape[1] not in (2, 3):
            raise ValueError(f"Bodies.pos must have shape ({n}, 2 or 3), got {pos.shape}")
        if arrays["vel"].shape != pos.shape:
            raise ValueError(f"Bodies.vel must have shape {pos.shape}, got {arrays['vel'].shape}")
        if arrays["charge"].shape != (n,):
            raise ValueError(f"Bodies.charge must have shape ({n},), "
                             f"got {arrays['charge'].shape}")
        if np.any(mass < 0.0):
            raise ValueError(f"Bodies.mass must be >= 0, got {mass[mass < 0.0][0]!r}")
        for name, arr in arrays.items():
            object.__setattr__(self, name, arr)

    @property
    def n(self):
        return self.mass.shape[0]

    @property
    def dim(self):
        return self.pos.shape[1]

    def copy(self):
        return Bodies(self.mass, self.pos, self.vel, self.charge)


# ---------------------------------------------------------------- input checks

def _count(name, value, minimum=1):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an int >= {minimum}, got {value!r} "
                        f"({type(value).__name__})")
    if value < minimum:
        raise ValueError(f"{name} must be an int >= {minimum}, got {value!r}")
    return int(value)


def _even(name, value):
    value = _count(name, value, 2)
    if value % 2:
        raise ValueError(f"{name} must be even (two equal halves), got {value!r}")
    return value


def _dim(value):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"dim must be 2 or 3, got {value!r} ({type(value).__name__})")
    if value not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {value!r}")
    return int(value)


def _rng(seed):
    """A generator from an int seed >= 0, or the given generator itself."""
    if isinstance(seed, np.random.Generator):
        return seed
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, numbers.Integral):
        raise TypeError(f"seed must be an int >= 0 or a numpy.random.Generator, got {seed!r} "
                        f"({type(seed).__name__})")
    if seed < 0:
        raise ValueError(f"seed must be an int >= 0, got {seed!r}")
    return np.random.default_rng(int(seed))


def _fraction(name, value, low_open=False):
    value = finite_float(name, value)
    if value > 1.0 or value < 0.0 or (low_open and value == 0.0):
        interval = "(0, 1]" if low_open else "[0, 1]"
        raise ValueError(f"{name} must be in {interval}, got {value!r}")
    return value


def _mass_cut(value, dim):
    return PLUMMER_MASS_CUT[dim] if value is None else _fraction("mass_cut", value, True)


def _tilt(value, dim):
    value = finite_float("tilt", value)
    if dim == 2 and value != 0.0:
        raise ValueError(f"tilt rotates out of the plane: it must be 0 in 2-D, got {value!r}")
    return value


# ---------------------------------------------------------------- sampling helpers

def _directions(rng, n, dim):
    """n isotropic unit vectors: in 3-D cos(theta) and phi uniform (Archimedes' hat-box)."""
    if dim == 2:
        phi = 2.0 * np.pi * rng.random(n)
        return np.column_stack((np.cos(phi), np.sin(phi)))
    cos_t = 2.0 * rng.random(n) - 1.0
    phi = 2.0 * np.pi * rng.random(n)
    sin_t = np.sqrt(np.maximum(1.0 - cos_t * cos_t, 0.0))
    return np.column_stack((sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t))


def _plummer_speeds(rng, n):
    """q = v / v_esc with density ~ q^2 (1 - q^2)^(7/2), by rejection (Aarseth et al. 1974)."""
    q = np.empty(n)
    todo = np.arange(n)
    while todo.size:
        trial = rng.random(todo.size)
        height = _SPEED_BOUND * rng.random(todo.size)
        s = trial * trial
        ok = height < s * (1.0 - s) ** 3.5
        q[todo[ok]] = trial[ok]
        todo = todo[~ok]
    return q


def _plummer_raw(rng, n, dim, mass, scale, G, mass_cut):
    """Positions and velocities of a Plummer sphere (3-D) or Kuzmin disk (2-D), not centred."""
    model_mass = mass / mass_cut
    x = mass_cut * rng.random(n)                     # enclosed-mass fraction of the full model
    if dim == 3:
        # M(<r)/M = x  <=>  r = a x^(1/3) / sqrt(1 - x^(2/3))
        x23 = np.cbrt(x) ** 2
        r = scale * np.sqrt(x23 / (1.0 - x23))
    else:
        # M(<R)/M = 1 - a / sqrt(R^2 + a^2) = x  <=>  R = a sqrt(1 / (1 - x)^2 - 1)
        r = scale * np.sqrt(1.0 / (1.0 - x) ** 2 - 1.0)
    pos = r[:, None] * _directions(rng, n, dim)
    psi = G * model_mass / np.sqrt(r * r + scale * scale)   # relative potential -Phi
    if dim == 3:
        speed = _plummer_speeds(rng, n) * np.sqrt(2.0 * psi)
    else:
        # f(E) ~ E^2: u = v^2/2 has density ~ (psi - u)^2, so u = psi (1 - Y^(1/3))
        y = 1.0 - rng.random(n)
        speed = np.sqrt(2.0 * psi * (1.0 - np.cbrt(y)))
    vel = speed[:, None] * _directions(rng, n, dim)
    return pos, vel


def _centred(mass, pos, vel):
    """Shift to the centre-of-mass frame: zero mass-weighted mean position and velocity."""
    total = mass.sum()
    if total > 0.0:
        pos = pos - (mass @ pos) / total
        vel = vel - (mass @ vel) / total
    return pos, vel


def _bodies(mass, pos, vel, charge=None):
    n = pos.shape[0]
    mass = np.full(n, mass) if np.ndim(mass) == 0 else mass
    return Bodies(mass, pos, vel, np.zeros(n) if charge is None else charge)


def _join(*parts):
    return Bodies(np.concatenate([p.mass for p in parts]), np.concatenate([p.pos for p in parts]),
                  np.concatenate([p.vel for p in parts]),
                  np.concatenate([p.charge for p in parts]))


def _disk_enclosed(x, cut=DISK_CUT):
    """Fraction of an exponential disk's mass within x = R/h when it is cut at ``cut``."""
    x = np.minimum(x, cut)
    return -np.expm1(-x) - x * np.exp(-x), -math.expm1(-cut) - cut * math.exp(-cut)


def _disk_radii(p, cut=DISK_CUT):
    """x = R/h with enclosed fraction p of the cut disk, by bisection (60 halvings of [0, cut]:
    the result is exact to rounding, the same bits for the same p)."""
    _, whole = _disk_enclosed(0.0, cut)
    target = p * whole
    lo = np.zeros_like(p)
    hi = np.full_like(p, cut)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = _disk_enclosed(mid, cut)[0] < target
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    return 0.5 * (lo + hi)


def _rotate_x(arr, angle):
    """Rotate (n, 3) vectors about the x axis by ``angle`` (right-handed: y goes towards z)."""
    c, s = math.cos(angle), math.sin(angle)
    out = arr.copy()
    out[:, 1] = c * arr[:, 1] - s * arr[:, 2]
    out[:, 2] = s * arr[:, 1] + c * arr[:, 2]
    return out


# ---------------------------------------------------------------- models

def plummer(n, dim=3, seed=0, mass=1.0, scale=1.0, G=1.0, mass_cut=None):
    """n equal bodies of a Plummer sphere of total ``mass`` and scale radius ``scale``, in
    equilibrium under gravity of constant ``G``, in its centre-of-mass frame.

    3-D: Plummer (1911), sampled as Aarseth, Henon & Wielen (1974). 2-D: Kuzmin's (1956) disk,
    whose in-plane potential is Plummer's, with its isotropic equilibrium f(E) ~ E^2: an
    equilibrium of the engine's 2-D gravity (not a projection of the 3-D sphere). The bodies
    are the inner ``mass_cut`` (default 0.999 in 3-D: r <= 38.7 scale; 0.95 in 2-D:
    R <= 19.97 scale) of a model of mass ``mass / mass_cut``. The module docstring has the
    formulas.
    """
    n, dim, rng = _count("n", n), _dim(dim), _rng(seed)
    mass, scale, G = positive_float("mass", mass), positive_float("scale", scale), \
        positive_float("G", G)
    cut = _mass_cut(mass_cut, dim)
    pos, vel = _plummer_raw(rng, n, dim, mass, scale, G, cut)
    m = np.full(n, mass / n)
    return _bodies(m, *_centred(m, pos, vel))


def uniform_cube(n, dim=3, seed=0, mass=1.0, side=1.0):
    """n bodies of mass mass/n uniform in [-side/2, side/2]^dim, at rest."""
    n, dim, rng = _count("n", n), _dim(dim), _rng(seed)
    mass, side = positive_float("mass", mass), positive_float("side", side)
    pos = side * (rng.random((n, dim)) - 0.5)
    return _bodies(mass / n, pos, np.zeros((n, dim)))


def cold_disk(n, dim=3, seed=0, mass=1.0, radius=1.0, thickness=0.0):
    """n bodies of mass mass/n uniform in the disk R <= radius of the x-y plane (R^2 and the
    angle uniform), at rest; in 3-D z uniform in [-thickness/2, thickness/2] (a slab of full
    width ``thickness``; ignored in 2-D)."""
    n, dim, rng = _count("n", n), _dim(dim), _rng(seed)
    mass, radius = positive_float("mass", mass), positive_float("radius", radius)
    thickness = nonnegative_float("thickness", thickness)
    r = radius * np.sqrt(rng.random(n))
    phi = 2.0 * np.pi * rng.random(n)
    columns = [r * np.cos(phi), r * np.sin(phi)]
    if dim == 3:
        columns.append(thickness * (rng.random(n) - 0.5))
    return _bodies(mass / n, np.column_stack(columns), np.zeros((n, dim)))


def two_clumps(n, dim=3, seed=0, mass=1.0, scale=0.2, separation=2.0, speed=0.0, G=1.0,
               mass_cut=None):
    """Two Plummer clumps (see :func:`plummer`) of n/2 bodies and mass/2 each (n even), centred
    at x = -separation/2 and +separation/2 and moving towards each other along x at relative
    speed ``speed`` (+speed/2 and -speed/2). Zero total momentum."""
    n, dim, rng = _even("n", n), _dim(dim), _rng(seed)
    mass, scale, G = positive_float("mass", mass), positive_float("scale", scale), \
        positive_float("G", G)
    separation = positive_float("separation", separation)
    speed = nonnegative_float("speed", speed)
    cut = _mass_cut(mass_cut, dim)
    half = n // 2
    clumps = []
    for side in (-1.0, 1.0):
        m = np.full(half, mass / n)
        pos, vel = _centred(m, *_plummer_raw(rng, half, dim, mass / 2.0, scale, G, cut))
        pos[:, 0] += side * separation / 2.0
        vel[:, 0] -= side * speed / 2.0
        clumps.append(_bodies(m, pos, vel))
    return _join(*clumps)


def disk_galaxy(n, dim=3, seed=0, mass=1.0, disk_fraction=0.8, scale_length=1.0,
                bulge_scale=0.2, thickness=0.05, dispersion=0.05, G=1.0, mass_cut=None):
    """An exponential disk (cut at 6 scale lengths) of round(n disk_fraction) bodies plus a
    Plummer bulge (Kuzmin disk in 2-D) of the rest, all of mass mass/n, in the centre-of-mass
    frame. The disk turns counter-clockwise about +z on circular orbits
    v_c(R) = sqrt(G M(<R) / R) in the spherical approximation, plus a gaussian velocity of
    standard deviation ``dispersion`` v_c per component; in 3-D its vertical profile is
    sech^2(z / thickness) (``thickness`` is ignored in 2-D). Disk bodies first, then the
    bulge. See the module docstring."""
    n, dim, rng = _count("n", n), _dim(dim), _rng(seed)
    mass, G = positive_float("mass", mass), positive_float("G", G)
    disk_fraction = _fraction("disk_fraction", disk_fraction)
    h = positive_float("scale_length", scale_length)
    b = positive_float("bulge_scale", bulge_scale)
    z0 = nonnegative_float("thickness", thickness)
    dispersion = nonnegative_float("dispersion", dispersion)
    cut = _mass_cut(mass_cut, dim)
    n_disk = int(round(n * disk_fraction))
    n_bulge = n - n_disk
    m_disk, m_bulge = n_disk * mass / n, n_bulge * mass / n

    big_r = h * _disk_radii(rng.random(n_disk))
    phi = 2.0 * np.pi * rng.random(n_disk)
    cos_p, sin_p = np.cos(phi), np.sin(phi)
    enclosed = m_disk * np.divide(*_disk_enclosed(big_r / h))
    if n_bulge:
        # the bulge's model has mass m_bulge / cut; beyond its cut it holds m_bulge
        plummer_part = m_bulge / cut * big_r ** 3 / (big_r * big_r + b * b) ** 1.5
        enclosed = enclosed + np.minimum(plummer_part, m_bulge)
    v_c = np.sqrt(G * np.divide(enclosed, big_r, out=np.zeros(n_disk), where=big_r > 0.0))
    pos = np.zeros((n_disk, dim))
    pos[:, 0], pos[:, 1] = big_r * cos_p, big_r * sin_p
    vel = np.zeros((n_disk, dim))
    vel[:, 0], vel[:, 1] = -v_c * sin_p, v_c * cos_p
    if dim == 3:
        # sech^2(z/z0) / (2 z0) is the logistic distribution of scale z0/2
        pos[:, 2] = 0.5 * z0 * rng.logistic(size=n_disk)
    vel += dispersion * v_c[:, None] * rng.standard_normal((n_disk, dim))

    # the bulge, the centre of the potential, is centred on the disk's rotation axis
    bulge_pos, bulge_vel = _centred(np.ones(n_bulge),
                                    *_plummer_raw(rng, n_bulge, dim, m_bulge, b, G, cut))
    m = np.full(n, mass / n)
    pos, vel = _centred(m, np.concatenate((pos, bulge_pos)), np.concatenate((vel, bulge_vel)))
    return _bodies(m, pos, vel)


def place(b, offset, velocity, tilt=0.0):
    """A copy of ``b`` rotated about the x axis by ``tilt`` radians (3-D only; y turns towards
    z), then shifted by ``offset`` and given the bulk ``velocity`` (vectors of length b.dim)."""
    if not isinstance(b, Bodies):
        raise TypeError(f"b must be an initial_conditions.Bodies, got {type(b).__name__}")
    offset = vector("offset", offset, b.dim)
    velocity = vector("velocity", velocity, b.dim)
    tilt = _tilt(tilt, b.dim)
    pos, vel = b.pos, b.vel
    if tilt != 0.0:
        pos, vel = _rotate_x(pos, tilt), _rotate_x(vel, tilt)
    return Bodies(b.mass, pos + offset, vel + velocity, b.charge)


def galaxy_pair(n, dim=3, seed=0, separation=8.0, pericenter=2.0, eccentricity=0.95,
                tilt=None, mass=1.0, disk_fraction=0.8, scale_length=0.5, bulge_scale=0.1,
                thickness=0.025, dispersion=0.05, G=1.0):
    """Two equal disk galaxies (see :func:`disk_galaxy`) of n/2 bodies and mass/2 each (n even),
    ``separation`` apart on the x axis and approaching on the Keplerian orbit of two point
    masses with pericentre distance ``pericenter`` and eccentricity ``eccentricity`` (<= 1; 1 is
    Toomre & Toomre's 1972 parabola), turning counter-clockwise about +z. The first galaxy
    (at -x) is prograde; the second is tilted about the x axis by ``tilt`` radians (default
    pi/3 in 3-D; it must be 0 in 2-D). Zero total momentum.

    The relative orbit (vis-viva, and the angular momentum sqrt(G M q (1 + e))): at distance d,
    v^2 = G M (2/d - (1 - e)/q), tangential speed sqrt(G M q (1 + e)) / d, the rest radial and
    inwards; d must lie between q and the apocentre q (1 + e) / (1 - e).
    """
    n, dim, rng = _even("n", n), _dim(dim), _rng(seed)
    d = positive_float("separation", separation)
    q = positive_float("pericenter", pericenter)
    e = _fraction("eccentricity", eccentricity)
    tilt = (math.pi / 3.0 if dim == 3 else 0.0) if tilt is None else _tilt(tilt, dim)
    mass, G = positive_float("mass", mass), positive_float("G", G)
    if d < q:
        raise ValueError(f"separation must be >= pericenter ({q!r}), got {d!r}")
    if e < 1.0 and d > q * (1.0 + e) / (1.0 - e):
        raise ValueError(f"separation {d!r} is beyond the apocentre {q * (1.0 + e) / (1.0 - e)!r} "
                         f"of the orbit (pericenter {q!r}, eccentricity {e!r})")
    galaxy = dict(dim=dim, seed=rng, mass=mass / 2.0, disk_fraction=disk_fraction,
                  scale_length=scale_length, bulge_scale=bulge_scale, thickness=thickness,
                  dispersion=dispersion, G=G)
    first = disk_galaxy(n // 2, **galaxy)
    second = disk_galaxy(n // 2, **galaxy)

    gm = G * mass
    v_t = math.sqrt(gm * q * (1.0 + e)) / d
    v_r = -math.sqrt(max(gm * (2.0 / d - (1.0 - e) / q) - v_t * v_t, 0.0))
    rel_pos = np.zeros(dim)
    rel_vel = np.zeros(dim)
    rel_pos[0] = d
    rel_vel[0], rel_vel[1] = v_r, v_t
    return _join(place(first, -rel_pos / 2.0, -rel_vel / 2.0),
                 place(second, rel_pos / 2.0, rel_vel / 2.0, tilt=tilt))


def plasma(n, dim=3, seed=0, side=1.0, neutral=True, mass=1.0, charge=1.0):
    """n bodies of mass mass/n uniform in [-side/2, side/2]^dim, at rest. ``charge`` is each
    body's charge (> 0): neutral=True alternates +charge and -charge (even indices +, so the
    total is exactly 0; n must be even), neutral=False gives every body +charge."""
    if not isinstance(neutral, (bool, np.bool_)):
        raise TypeError(f"neutral must be True or False, got {neutral!r} "
                        f"({type(neutral).__name__})")
    n = _even("n", n) if neutral else _count("n", n)
    dim, rng = _dim(dim), _rng(seed)
    side, mass = positive_float("side", side), positive_float("mass", mass)
    charge = positive_float("charge", charge)
    pos = side * (rng.random((n, dim)) - 0.5)
    q = np.full(n, charge)
    if neutral:
        q[1::2] = -charge
    return _bodies(mass / n, pos, np.zeros((n, dim)), q)


def add_to(sim, b):
    """Add the bodies ``b`` to ``sim`` (``sim.add_many``); return the range of their indices."""
    if not isinstance(b, Bodies):
        raise TypeError(f"b must be an initial_conditions.Bodies, got {type(b).__name__}")
    ids = sim.add_many(mass=b.mass, pos=b.pos, vel=b.vel, charge=b.charge)
    start = int(ids[0]) if len(ids) else int(sim.n)
    return range(start, start + len(ids))
