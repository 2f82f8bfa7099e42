"""idle: does nothing at all. The baseline every other bot must beat."""
from spacewar.protocol import NOOP


class Idle:
    def act(self, obs):
        return NOOP
