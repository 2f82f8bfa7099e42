"""Force terms: one module each, holding its numba kernel, its potential and its parameters."""
from .base import Force
from .gravity import NBodyGravity
from .point_mass import PointMass
from .uniform_gravity import UniformGravity
from .coulomb import Coulomb
from .springs import Springs, rope, cloth
from .drag import Drag
from .thrust import Thrust
from .wind import Wind, grid_triangles
from .buoyancy import Buoyancy
from .blast import Blast

__all__ = ["Force", "NBodyGravity", "PointMass", "UniformGravity", "Coulomb", "Springs",
           "rope", "cloth", "Drag", "Thrust", "Wind", "grid_triangles", "Buoyancy", "Blast"]
