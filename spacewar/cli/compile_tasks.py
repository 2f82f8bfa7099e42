"""The game's kernels compiled ahead, on every core (``spacewar compile``).

The tasks of ``engine.compile_ahead`` for the game: the frame a match loop steps (``spacewar
match``), the frame of every match of a batch (tournaments, leagues), and the learning batch
with the compiled bots (``spacewar.learn.batch``). ``spacewar compile`` runs those not yet
compiled for the current sources, one worker process per core; CI runs it, with
``python -m engine compile``, before the tests.
"""
from engine.compile_ahead import Task

#: the game's tasks, the slowest to compile first
TASKS = (
    Task("spacewar-learning", "spacewar.cli.compile_tasks:learning_frame", ()),
    Task("spacewar-batch", "spacewar.cli.compile_tasks:batch_frame", ()),
    Task("spacewar-match", "spacewar.cli.compile_tasks:match_frame", ()),
)


def match_frame():
    """A one-round match of built-in bots, as ``spacewar match`` plays it (a second or so
    once compiled)."""
    from spacewar.arena.match import play_match

    play_match("chaser", "sniper", seed=0, rounds=1)


def batch_frame():
    """One frame of a batch of matches, as a tournament's worker plays them."""
    from spacewar.arena.jobs import warm_up_game

    warm_up_game()


def learning_frame():
    """One step of the learning batch, its compiled bots playing one seat."""
    import numpy as np

    from spacewar.learn.batch import LearningBatch

    batch = LearningBatch(2, seed=1, rounds=1, frame_cap=10)
    batch.step(np.zeros((2, 2), dtype=np.int64))
