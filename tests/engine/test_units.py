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


def _earth_about_the_sun():
    sim = Simulation(dim=3, units=("AU", "yr", "Msun"), integrator="leapfrog", dt=1e-3)
    sim.add(mass=1.0 * u.Msun)
    sim.add(mass=const.M_earth, pos=[1.0, 0.0, 0.0] * u.AU, vel=[0.0, 29.78, 0.0] * u.km / u.s)
    sim.add_force(forces.NBodyGravity())
    return sim


def test_time_arithmetic_with_quantities_reads_as_written():
    sim = _earth_about_the_sun()
    sim.integrate(sim.time + 0.5 * u.yr)
    assert sim.time.unit == u.yr and sim.t == pytest.approx(0.5, abs=1e-12)
    later = sim.time + 30 * u.d
    assert later.to_value(u.yr) == pytest.approx(0.5 + 30 / 365.25, rel=1e-12)
    sim.time = 2 * u.d
    assert sim.t == pytest.approx(2 / 365.25, rel=1e-12)
    with pytest.raises(ValueError, match="^time must be a time"):
        sim.time = 3 * u.kg
    with pytest.raises(ValueError, match="^time"):
        sim.time = float("nan")
    assert sim.t == pytest.approx(2 / 365.25, rel=1e-12)  # refused: nothing changed


def test_every_read_out_is_a_quantity_with_the_code_value():
    sim = _earth_about_the_sun()
    sim.step(10)
    q = sim.quantities
    assert q.energy.unit.is_equivalent(u.J)
    assert q.energy.to_value(u.Msun * u.AU ** 2 / u.yr ** 2) == sim.energy()
    assert q.kinetic_energy.value + q.potential_energy.value == pytest.approx(sim.energy())
    np.testing.assert_array_equal(q.pos.to_value(u.AU), sim.pos)
    np.testing.assert_array_equal(q.vel.to_value(u.AU / u.yr), sim.vel)
    np.testing.assert_array_equal(q.mass.to_value(u.Msun), sim.mass)
    np.testing.assert_array_equal(q.momentum.value, sim.momentum())
    np.testing.assert_array_equal(q.angular_momentum.value, sim.angular_momentum())
    assert q.dt.to_value(u.d) == pytest.approx(1e-3 * 365.25, rel=1e-12)
    assert q.G.to_value(u.m ** 3 / u.kg / u.s ** 2) == pytest.approx(const.G.value, rel=1e-12)
    com_pos, com_vel = q.center_of_mass
    assert com_pos.unit == u.AU and com_vel.unit == u.AU / u.yr
    # a copy: writing into the Quantity leaves the simulation alone
    before = sim.pos.copy()
    q.pos[0, 0] = 99 * u.AU
    np.testing.assert_array_equal(sim.pos, before)
    with pytest.raises(AttributeError, match="energy"):
        q.enrgy


def test_a_simulation_without_units_has_no_quantities():
    sim = Simulation(dim=2)
    with pytest.raises(ValueError, match="no units"):
        sim.quantities
