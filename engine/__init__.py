"""engine: a fast, validated N-body particle engine for games (numba core, plain floats).

    import engine
    from engine import Simulation, forces, analytic

    sim = Simulation(dim=2, integrator="symplectic_euler", dt=1.0)
    i = sim.add(mass=1.0, pos=(0.0, 0.0), vel=(2.0, 4.0))
    sim.add_force(forces.UniformGravity(g=(0.0, -1.0)))
    sim.step(7)
"""
from . import analytic, atomic, cache, clock, diagnostics, forces, integrators, space, state
from . import initial_conditions, stability
from .batch import Batch
from .atomic import OutputPathError, atomic_write, check_output_dir, check_output_path
from .clock import FixedStepClock
from .collisions import Collisions, Contact, Wall, box_walls
from .errors import Collision, SimulationError
from .integrators import ADAPTIVE_INTEGRATORS, INTEGRATORS, ORDERS, SYMPLECTIC
from .simulation import Simulation
from . import advisor
from .advisor import advise

__version__ = "0.1.0"

__all__ = ["Simulation", "Batch", "space", "state", "SimulationError", "INTEGRATORS", "ADAPTIVE_INTEGRATORS", "ORDERS", "SYMPLECTIC", "forces", "integrators",
           "analytic", "clock", "diagnostics", "stability", "FixedStepClock", "__version__", "atomic",
           "atomic_write", "check_output_path", "check_output_dir", "OutputPathError", "advise",
           "advisor", "initial_conditions", "Collisions", "Collision", "Contact", "Wall",
           "box_walls"]
