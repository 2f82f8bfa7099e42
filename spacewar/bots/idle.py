"""idle: does nothing at all. The baseline every other bot must beat."""
from ..protocol import NOOP


class Idle:
    def act(self, obs):
        return NOOP
