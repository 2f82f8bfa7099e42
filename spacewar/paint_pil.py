"""``spacewar.paint_pil``, kept: the Pillow painter, now ``spacewar.view.paint_pil``; re-exports
only."""
from spacewar.view.paint_pil import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.view.paint_pil")
