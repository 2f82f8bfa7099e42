"""Units at the edges: astropy Quantities in, code units inside, Quantities out."""
import math

import numpy as np
import pytest
from astropy import constants as const
from astropy import units as u

from engine import Simulation, forces


def test_G_in_au_year_solar_mass():
    sim = Simulation(dim=3, units=("AU", "yr", "Msun"))
    # G M_sun in AU^3/yr^2 is about 4 pi^2 (Kepler's third law for the Earth)
    assert sim.G == pytest.approx(4 * math.pi ** 2, rel=1e-3)
    assert sim.G == pytest.approx(const.G.to_value(u.AU ** 3 / u.yr ** 2 / u.Msun), rel=1e-15)


def test_any_order_and_other_units():
    a = Simulation(units=("yr", "Msun", "AU"))
    b = Simulation(units=("m", "s", "kg"))
    assert a.G == Simulation(units=("AU", "yr", "Msun")).G
    assert b.G == pytest.approx(6.6743e-11, rel=1e-4)


def test_add_converts_quantities_and_floats_are_code_units():
    sim = Simulation(dim=2, units=("AU", "yr", "Msun"))
    i = sim.add(mass=1.0 * u.Msun, pos=[1.0, 0.0] * u.AU, vel=[0.0, 29.78] * u.km / u.s)
    j = sim.add(mass=const.M_earth, pos=(2.0, 0.0))
    assert sim.vel[i, 1] == pytest.approx(6.28, rel=2e-3)  # 29.78 km/s ~ 2 pi AU/yr
    assert sim.mass[j] == pytest.approx(3.0e-6, rel=2e-2)
    assert sim.pos[j, 0] == 2.0
    sim.dt = 1 * u.day
    assert sim.dt == pytest.approx(1 / 365.25)
    q = sim.quantity(sim.pos, "length")
    assert q.unit == u.AU and q[j, 0].to_value(u.km) == pytest.approx(2 * 1.495978707e8)


def test_earth_orbit_period_is_one_year():
    sim = Simulation(dim=2, integrator="rk45", dt=1e-3, tolerance=1e-12, units=("AU", "yr", "Msun"))
    sim.add(mass=1.0 * u.Msun)
    v = math.sqrt(sim.G * 1.0)
    sim.add(mass=0.0, pos=[1.0, 0.0] * u.AU, vel=(0.0, v), test=True)
    sim.add_force(forces.NBodyGravity())
    sim.integrate(1.0 * u.yr)  # a circular orbit at 1 AU about 1 Msun takes ~1 year
    np.testing.assert_allclose(sim.pos[1], (1.0, 0.0), atol=2e-3)


def test_wrong_dimension_quantity_is_refused():
    sim = Simulation(units=("AU", "yr", "Msun"))
    with pytest.raises(ValueError, match="pos must be a length"):
        sim.add(pos=[1.0, 0.0] * u.s)
    with pytest.raises(ValueError, match="mass must be a mass"):
        sim.add(mass=1 * u.m)


def test_quantity_without_units_is_refused():
    sim = Simulation()
    with pytest.raises(ValueError, match="pos is a Quantity.*no units"):
        sim.add(pos=[1.0, 0.0] * u.AU)
    with pytest.raises(ValueError, match="no units"):
        sim.quantity(sim.pos, "length")


@pytest.mark.parametrize("units, match", [
    (("AU", "yr"), "three units"),
    (("AU", "km", "Msun"), "two units of length"),
    (("AU", "yr", "K"), "not a unit of length, time or mass"),
    (("AU", "yr", "blorp"), "not an astropy unit"),
    ("AU", "three units"),
])
def test_bad_units(units, match):
    with pytest.raises(ValueError, match=match):
        Simulation(units=units)


def test_time_is_a_quantity_in_the_simulations_units():
    import astropy.units as u

    from engine import Simulation
    sim = Simulation(dim=3, units=("AU", "yr", "Msun"), dt=0.25 * u.yr)
    sim.add(mass=1.0 * u.Msun)
    sim.step(3)
    assert sim.time.unit == u.yr and sim.time.value == 0.75
    plain = Simulation(dt=0.5)
    plain.step(2)
    assert plain.time == 1.0 and isinstance(plain.time, float)
