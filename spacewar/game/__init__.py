"""The compiled game: ``core`` (the frame as numba functions over the state arrays), ``game``
(``Game``: M matches stepped as one ``engine.Batch``), ``features`` (the learning
observation), ``referee`` (one frame of a match between seats: ask, record faults, forfeit,
step) and ``compiled_bots`` (the built-in bots as compiled functions, one module each).

``spacewar.game.Game`` (and ``Checkpoint``, ``force_terms``, ``seed_state``) keep the path
they had when this package was one module; they are loaded on first use, so importing a
submodule does not build the game.
"""
__all__ = ["Game", "Checkpoint", "force_terms", "seed_state"]


def __getattr__(name):
    if name in __all__:
        from spacewar.game import game
        return getattr(game, name)
    raise AttributeError(f"module 'spacewar.game' has no attribute {name!r}")
