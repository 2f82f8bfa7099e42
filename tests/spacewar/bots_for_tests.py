"""Misbehaving and scripted bots for the fault-isolation and rules tests."""
import time

from spacewar import Action


class Raising:
    def act(self, obs):
        raise RuntimeError("boom")


class Slow:
    """Sleeps 0.4 s an action (tests/spacewar/test_match.py gives it a 0.1 s budget)."""

    SECONDS = 0.4

    def act(self, obs):
        time.sleep(self.SECONDS)
        return Action()


class Garbage:
    def act(self, obs):
        return "left" if obs.frame % 2 else {"turn": 1}


class Hanging:
    def act(self, obs):
        while True:
            pass


class SometimesRaising:
    """Raises on 3 frames only, plays a sensible chaser otherwise."""

    def __init__(self):
        from spacewar.bots.chaser import Chaser
        self.inner = Chaser()

    def act(self, obs):
        if obs.frame in (5, 6, 7):
            raise ValueError("transient")
        return self.inner.act(obs)


class Dies:
    """Exits its own process on the 3rd frame."""

    def act(self, obs):
        if obs.frame >= 3:
            import os
            os._exit(3)
        return Action()


class Thruster:
    def act(self, obs):
        return Action(thrust=True)
