"""random: presses buttons at random, from its own seeded generator (reproducible)."""
import numpy as np

from spacewar.protocol import Action


class RandomBot:
    """Each frame: turn uniformly in {-1, 0, 1}, thrust with p = 0.5, fire with p = 0.2,
    hyperspace with p = 0.002."""

    def __init__(self, seed=None):
        self.seed = seed
        self.rng = np.random.default_rng(seed)

    def reset(self):
        self.rng = np.random.default_rng(self.seed)

    def act(self, obs):
        r = self.rng.random(4)
        return Action(turn=int(r[0] * 3) - 1, thrust=bool(r[1] < 0.5), fire=bool(r[2] < 0.2),
                      hyperspace=bool(r[3] < 0.002))
