"""Drawing Spacewar!: a replay to an animated GIF, one frame to a Pillow image.

    from spacewar.render import render_gif
    render_gif("match.json", "match.gif")          # a replay file or a replay dict

The drawing has two halves. ``scene(snapshot, size, ...)`` turns the plain data of one frame
(``Game.snapshot``) into a list of backend-neutral primitives in pixel coordinates: dots,
rings, outlined and filled polygons, lines and text. ``render_frame`` paints that list with
Pillow; the pygame window (``spacewar.view.window``, for ``play``, ``watch`` and ``replay --view``)
paints the same list with pygame, so the GIF and the live game look alike.

What is drawn: black space with a faint fixed star field, the central star as a flickering
dot with rays (nothing when the rules have no star), the two ships as outlined shapes as in
1962 (seat 0 the needle, seat 1 the wedge) turned to their heading with a flame behind a
thrusting ship, torpedoes as dots in their owner's colour (a few pixels across even in a
480-pixel GIF), expanding rings of debris where a ship died, a short flash where a ship jumps
into or back out of hyperspace (a ship in hyperspace is not drawn), a small burst where a
torpedo vanishes, and the names, scores and round at the top. Objects near an edge are also
drawn on the opposite edge (the arena is a torus). Screen y points up, as the game's: a
positive turn is anticlockwise on screen.

Given a snapshot from ``frame_snapshot(game)`` (``Game.snapshot`` plus the rules' capacities),
the top also shows the mode and, for each ship, its fuel (as a percentage and a bar), its
torpedoes and hyperspace jumps left and, in the electric mode, the sign of its charge (red +,
blue -), also drawn beside the ship and as a ring round each torpedo.

Pillow (and pygame for the window) are the optional ``[viz]`` extra; they are imported only
when something is drawn.

This module keeps the documented path: the code lives in ``spacewar.view.look`` (colours, shapes,
durations), ``spacewar.view.scene`` (the primitives), ``spacewar.view.paint_pil`` (Pillow) and
``spacewar.view.gif`` (``render_gif``); nothing inside ``spacewar`` imports this module.
"""
from spacewar.kept_paths import forward
from spacewar.view.gif import render_gif  # noqa: F401
from spacewar.view.look import VIZ_HINT  # noqa: F401
from spacewar.view.paint_pil import (PALETTE, new_image, paint_pil, palette_index,  # noqa: F401
                                     render_frame, require_pillow)
from spacewar.view.scene import (Effects, footer_top, frame_snapshot, hud_bottom,  # noqa: F401
                                 scene, to_pixels)

__all__ = ["Effects", "render_frame", "render_gif", "scene", "frame_snapshot", "paint_pil",
           "new_image", "palette_index", "require_pillow", "to_pixels", "footer_top",
           "hud_bottom", "PALETTE", "VIZ_HINT"]

__getattr__ = forward(__name__, "spacewar.view.look", "spacewar.view.scene",
                      "spacewar.view.paint_pil", "spacewar.view.gif")
