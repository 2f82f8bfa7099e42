"""``spacewar.paint_pil``, a documented path kept: the Pillow painter. The code lives in
``spacewar.view.paint_pil``; this module only re-exports it (``docs/game.md``, "Layout"), and
nothing inside ``spacewar`` imports it."""
from spacewar.view import paint_pil as home
from spacewar.view.paint_pil import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.view.paint_pil``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.paint_pil' has no attribute {name!r}")
    return getattr(home, name)
