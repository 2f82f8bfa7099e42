"""With numba's JIT off (``NUMBA_DISABLE_JIT=1``) the engine and the game run as the Python they
are written in (for a debugger, a coverage tool, a Python twin of a kernel), and give the
compiled code's bits: the force table's kernel "addresses" then index plain Python functions
(``engine.address_calls.python_function``)."""
import json
import os
import subprocess
import sys

import numpy as np

SCRIPT = r"""
import json, sys
import numpy as np
from engine import Simulation, forces
from spacewar import Game, Rules

sim = Simulation(dim=2, integrator="leapfrog", dt=0.01)
sim.add(mass=1e-3, pos=[1.0, 0.0], vel=[0.0, 1.0])
sim.add(mass=1e-3, pos=[-1.3, 0.2], vel=[0.1, -0.8])
sim.add_force(forces.PointMass(mu=1.0))
sim.add_force(forces.Drag(linear=0.01))
sim.step(200)
game = Game(Rules(), seeds=[3, 4], rounds=1)
rng = np.random.default_rng(5)
for frame in range(40):
    game.step(rng.integers(0, 8, size=(2, 2)))
print(json.dumps({"sim": sim.pos.tolist() + sim.vel.tolist(),
                  "game": game.pos.tolist() + game.vel.tolist(),
                  "active": game.active.tolist()}))
"""


def _run(disable_jit):
    env = dict(os.environ, NUMBA_DISABLE_JIT="1" if disable_jit else "0")
    out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                         text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_interpreted_engine_and_game_give_the_compiled_bits():
    interpreted, compiled = _run(True), _run(False)
    for key in ("sim", "game", "active"):
        a, b = np.array(interpreted[key]), np.array(compiled[key])
        assert a.shape == b.shape
        differ = np.flatnonzero(a.ravel() != b.ravel())
        assert differ.size == 0, (f"{key}: {differ.size} values differ, the first at flat index "
                                  f"{differ[0]}: {a.ravel()[differ[0]]!r} != "
                                  f"{b.ravel()[differ[0]]!r}")
    assert np.array(compiled["game"]).std() > 0  # the scenes moved
