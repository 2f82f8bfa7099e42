"""The built-in bots, listed once: their names, where their Python classes live, and (by
their place in the list) their kind codes in the compiled game. ``spacewar.bots.BUILTIN``,
``spacewar.game.compiled_bots.KINDS`` and ``spacewar.learn.envs.OPPONENTS`` are made from this list.
Pure Python: a bot's process may load it."""

#: (name, module, class) of each built-in bot; the k-th is compiled kind k
BUILTIN_BOTS = (
    ("idle", "spacewar.bots.idle", "Idle"),
    ("random", "spacewar.bots.random_bot", "RandomBot"),
    ("chaser", "spacewar.bots.chaser", "Chaser"),
    ("sniper", "spacewar.bots.sniper", "Sniper"),
    ("dodger", "spacewar.bots.dodger", "Dodger"),
)

#: the built-in bots' names, in kind-code order
NAMES = tuple(name for name, _, _ in BUILTIN_BOTS)
