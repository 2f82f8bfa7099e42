"""Contact: particles' spheres that meet during a step, found along their paths and resolved
at the moment they touch (bounce, merge or halt), and static walls they bounce off.

A scene declares it (``sim.collisions = engine.Collisions(...)``); a scene that does not
imports and compiles none of the kernels here. The modules, in the order a step uses them:

- ``settings``: ``Collisions``, ``Wall``, ``box_walls``, the ``Contact`` record;
- ``grid``: the broad phase (which pairs can touch this step), a uniform grid of cells;
- ``narrow``: when a pair, or a body and a wall, first touch along their paths;
- ``queue``: the step's events in time order;
- ``resolve``: what a bounce or a merge does to the bodies;
- ``events``: the loop that takes the events in order, resolves them and searches again.
"""
from .settings import ACTIONS, RESOLVE, SEARCH, Collisions, Contact, Wall, box_walls

__all__ = ["Collisions", "Contact", "Wall", "box_walls", "RESOLVE", "SEARCH", "ACTIONS"]
