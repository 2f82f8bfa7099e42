"""``spacewar.jobs``, a documented path kept: what a worker does with a job (``make_jobs``,
``warm_up_game``). The code lives in ``spacewar.arena.jobs``; this module only re-exports it
(``docs/game.md``, "Layout"), and nothing inside ``spacewar`` imports it."""
from spacewar.arena import jobs as home
from spacewar.arena.jobs import *  # noqa: F401,F403


def __getattr__(name):
    """Every other public name of ``spacewar.arena.jobs``."""
    if name.startswith("_") or not hasattr(home, name):
        raise AttributeError(f"module 'spacewar.jobs' has no attribute {name!r}")
    return getattr(home, name)
