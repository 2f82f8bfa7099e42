"""``spacewar.jobs``, kept: what a worker does with a job (``make_jobs``, ``warm_up_game``), now
``spacewar.arena.jobs``; re-exports only."""
from spacewar.arena.jobs import *  # noqa: F401,F403
from spacewar.kept_paths import forward

__getattr__ = forward(__name__, "spacewar.arena.jobs")
