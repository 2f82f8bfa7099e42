"""Geometry bots share: torus differences, bearings, turning towards a heading."""
import math

import numpy as np


def torus_delta(a, b):
    """The shortest vector from a to b on the unit torus."""
    d = np.asarray(b, dtype=float) - np.asarray(a, dtype=float)
    return d - np.floor(d + 0.5)


def angle_diff(target, heading):
    """target - heading wrapped to (-pi, pi]."""
    d = (target - heading + math.pi) % (2.0 * math.pi) - math.pi
    return d if d != -math.pi else math.pi


def turn_towards(heading, target, rules, deadband=None):
    """-1, 0 or +1: the turn that brings ``heading`` towards ``target`` fastest."""
    d = angle_diff(target, heading)
    band = 0.5 * rules.turn_rate if deadband is None else deadband
    if abs(d) <= band:
        return 0
    return 1 if d > 0 else -1
