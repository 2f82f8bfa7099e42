"""Astropy units <-> code units: the only module that imports astropy (lazily).

A simulation made with ``units=("AU", "yr", "Msun")`` (any astropy units of length, time and
mass, in any order) works internally in those units: ``sim.G`` is Newton's constant expressed
in them (from ``astropy.constants.G``), ``add()`` converts Quantities, and ``to_quantity`` turns
code-unit values back into Quantities. Plain floats are always taken as code units.
"""

#: how each kind of value is built from (length, time, mass) exponents
DIMENSIONS = {
    "length": (1, 0, 0),
    "time": (0, 1, 0),
    "mass": (0, 0, 1),
    "velocity": (1, -1, 0),
    "acceleration": (1, -2, 0),
    "force": (1, -2, 1),
    "energy": (2, -2, 1),
    "momentum": (1, -1, 1),
    "angular_momentum": (2, -1, 1),
    "G": (3, -2, -1),
}


def is_quantity(value):
    """True for an astropy Quantity (checked without importing astropy)."""
    return hasattr(value, "unit") and hasattr(value, "to_value")


class UnitSystem:
    """Code units made of one astropy unit each of length, time and mass."""

    def __init__(self, units):
        from astropy import units as u

        if isinstance(units, (str, bytes)) or not hasattr(units, "__len__") or len(units) != 3:
            raise ValueError(f"units must be three units (length, time, mass in any order), got {units!r}")
        found = {}
        for item in units:
            try:
                unit = u.Unit(item)
            except (ValueError, TypeError):
                raise ValueError(f"units: {item!r} is not an astropy unit") from None
            kind = None
            for name, ref in (("length", u.m), ("time", u.s), ("mass", u.kg)):
                if unit.is_equivalent(ref):
                    kind = name
            if kind is None:
                raise ValueError(f"units: {item!r} is not a unit of length, time or mass")
            if kind in found:
                raise ValueError(f"units: two units of {kind} given ({found[kind]} and {unit}) in {units!r}")
            found[kind] = unit
        self.length = found["length"]
        self.time = found["time"]
        self.mass = found["mass"]

    def unit(self, kind):
        """The astropy unit of ``kind`` (a key of DIMENSIONS) in this system."""
        try:
            el, et, em = DIMENSIONS[kind]
        except KeyError:
            raise ValueError(f"kind must be one of {sorted(DIMENSIONS)}, got {kind!r}") from None
        return self.length ** el * self.time ** et * self.mass ** em

    @property
    def G(self):
        from astropy import constants

        return float(constants.G.to_value(self.unit("G")))

    def to_code(self, value, kind, field):
        """Convert a Quantity (or pass through plain numbers) to code units of ``kind``."""
        from astropy import units as u

        if not is_quantity(value):
            return value
        try:
            return value.to_value(self.unit(kind))
        except u.UnitConversionError:
            raise ValueError(f"{field} must be a {kind} (convertible to {self.unit(kind)}), "
                             f"got {value!r}") from None

    def to_quantity(self, value, kind):
        return value * self.unit(kind)

    def __repr__(self):
        return f"UnitSystem(length={self.length}, time={self.time}, mass={self.mass})"


class Readouts:
    """A simulation's read-outs as astropy Quantities in its units (``sim.quantities``)::

        sim = Simulation(dim=3, units=("AU", "yr", "Msun"))
        ...
        sim.quantities.energy.to(u.J)        # the total energy
        sim.quantities.pos[1]                # a particle's position, in AU
        sim.integrate(sim.time + 5 * u.yr)   # ``sim.time`` is the time as a Quantity

    Each attribute is read when asked for (a copy: writing into a Quantity never changes the
    simulation; change the state through ``sim.pos``, ``sim.vel`` or ``add``)."""

    #: attribute -> (what it reads from the simulation, its kind in DIMENSIONS)
    VALUES = {"time": ("t", "time"), "dt": ("dt", "time"), "G": ("G", "G"),
              "box": ("box", "length"), "pos": ("pos", "length"), "vel": ("vel", "velocity"),
              "mass": ("mass", "mass")}
    DIAGNOSTICS = {"energy": "energy", "kinetic_energy": "energy", "potential_energy": "energy",
                   "momentum": "momentum", "angular_momentum": "angular_momentum"}

    def __init__(self, sim, units):
        self._sim = sim
        self._units = units

    def __getattr__(self, name):
        import numpy as np

        if name in self.VALUES:
            source, kind = self.VALUES[name]
            return self._units.to_quantity(np.array(getattr(self._sim, source)), kind)
        if name in self.DIAGNOSTICS:
            return self._units.to_quantity(getattr(self._sim, name)(), self.DIAGNOSTICS[name])
        if name == "center_of_mass":
            pos, vel = self._sim.center_of_mass()
            return (self._units.to_quantity(pos, "length"),
                    self._units.to_quantity(vel, "velocity"))
        raise AttributeError(f"no read-out {name!r}; there are: "
                             f"{', '.join([*self.VALUES, *self.DIAGNOSTICS, 'center_of_mass'])}")

    def __dir__(self):
        return [*self.VALUES, *self.DIAGNOSTICS, "center_of_mass"]

    def __repr__(self):
        return f"<read-outs in {self._units!r}>"


def strip_without_units(value, field):
    """Refuse a Quantity when the simulation has no units (its meaning would be ambiguous)."""
    if is_quantity(value):
        raise ValueError(f"{field} is a Quantity ({value!r}) but the simulation has no units; "
                         "create it with Simulation(units=(length, time, mass))")
    return value


__all__ = ["UnitSystem", "Readouts", "DIMENSIONS", "is_quantity"]
