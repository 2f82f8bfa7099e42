"""The compiled bots (spacewar.compiled_bots) against the Python reference bots.

Agreement: 100 seeded matches at once (``Game``), their ships scattered at random positions,
velocities, headings, fuel and magazines so that the frames cover the bots' branches (the
standard start is the same for every seed), played by the Python bots; at every frame, before
the step, each compiled bot decides on the same state and its code is compared with the Python
bot's. To stay within the time budget only the first ``FRAMES`` frames of each match are
played (the Python sniper and dodger cost about a millisecond per decision).
"""
import inspect
import math

import numpy as np
import pytest

from engine.cache import numpy_dot_kind
from spacewar import compiled_bots as cb, core
from spacewar.bots import chaser, dodger, random_bot, sniper
from spacewar.game import Game
from spacewar.rules import Rules

PY = {"chaser": chaser.Chaser, "sniper": sniper.Sniper, "dodger": dodger.Dodger,
      "random": random_bot.RandomBot}
MATCHES = 100
AGREEMENT = 0.99


def scatter(game, rng):
    """Random ship states (away from the star), fuel in [150, 1000] (so the fuel reserve
    matters) and 1 to 32 torpedoes (so the sniper's shot time varies)."""
    for m in range(game.n_matches):
        for s in range(2):
            while True:
                x, y = rng.uniform(-0.5, 0.5, 2)
                if x * x + y * y > 0.05 ** 2:
                    break
            speed, direction = rng.uniform(0.0, 1.6e-3), rng.uniform(-math.pi, math.pi)
            game.pos[m, :, s] = (x, y)
            game.vel[m, :, s] = (speed * math.cos(direction), speed * math.sin(direction))
            game.ship_gauges[m, s, core.HEADING] = rng.uniform(-math.pi, math.pi)
            game.ship_gauges[m, s, core.FUEL] = rng.uniform(150.0, 1000.0)
            game.ship_counters[m, s, core.TORPS] = rng.integers(1, game.rules.torpedoes + 1)


def arrays(game, memory, streams):
    return (game.pos, game.vel, game.charge, game.active, game.ship_gauges, game.ship_counters,
            game.torp_life, game.match_state, game.rules_vector, memory, streams)


def play(names, frames, seed=0, rules=None, on_frame=None):
    """Play ``MATCHES`` matches of the Python bots ``names`` for ``frames`` frames; return per
    seat (agreeing frames, compared frames) and the Python bots. ``on_frame(f, bots, memory)``
    is called after each frame's decisions (for extra checks)."""
    game = Game(rules, seeds=list(range(seed, seed + MATCHES)), rounds=3)
    scatter(game, np.random.default_rng(seed))
    bots = [[PY[n](seed=1000 * m + s) for s, n in enumerate(names)] for m in range(MATCHES)]
    memory = cb.new_memory(MATCHES)
    streams = cb.new_streams(MATCHES, seed)
    codes = np.zeros((MATCHES, 2), dtype=np.int64)
    actions = np.full((MATCHES, 2), core.NOOP, dtype=np.int64)
    agree = np.zeros(2, dtype=np.int64)
    total = np.zeros(2, dtype=np.int64)
    for f in range(frames):
        live = ~game.over
        for s in range(2):
            cb.decide_all(cb.KINDS[names[s]], s, *arrays(game, memory, streams), codes)
        for m in np.nonzero(live)[0]:
            for s in range(2):
                actions[m, s] = bots[m][s].act(game.observe(m, s)).code()
        if on_frame is not None:
            on_frame(f, bots, memory)
        for s in range(2):
            agree[s] += np.count_nonzero((codes[:, s] == actions[:, s]) & live)
            total[s] += np.count_nonzero(live)
        game.step(actions)
    return agree, total, bots


def assert_agrees(name, agree, total):
    rate = agree / total
    print(f"{name}: {agree} of {total} frames agree ({100 * rate:.3f}%)")
    assert total > 0
    assert rate >= AGREEMENT, f"{name} agrees on only {100 * rate:.2f}% of frames"


def test_chaser_agrees_with_python_chaser():
    """Chaser against the random bot (120 frames of 100 matches); the escape flag in the
    compiled memory follows the Python bot's ``escaping`` frame by frame."""
    flags = []

    def check(f, bots, memory):
        flags.append(sum(bots[m][0].escaping == bool(memory[m, 0, cb.ESCAPING])
                         for m in range(MATCHES)))
    agree, total, bots = play(("chaser", "random"), frames=120, seed=11, on_frame=check)
    assert_agrees("chaser", agree[0], total[0])
    assert sum(flags) >= AGREEMENT * 120 * MATCHES


def test_sniper_agrees_with_python_sniper():
    """Sniper against the chaser (80 frames of 100 matches), both seats compared; the sniper's
    enemy-thrust estimate in the compiled memory is the Python bot's. Every branch of the
    sniper must have been taken (escape, navigate, aim) so the test cannot pass vacuously."""
    modes = {}
    tracked = []

    def check(f, bots, memory):
        for m in range(MATCHES):
            b = bots[m][0]
            modes[b.mode] = modes.get(b.mode, 0) + 1
            estimate = memory[m, 0, cb.THRUST_X:cb.THRUST_Y + 1]
            tracked.append(np.array_equal(b.enemy_thrust, estimate))
    agree, total, _ = play(("sniper", "chaser"), frames=80, seed=21, on_frame=check)
    assert_agrees("sniper", agree[0], total[0])
    assert_agrees("chaser (as the sniper's opponent)", agree[1], total[1])
    print("sniper modes", modes)
    assert all(modes.get(k, 0) > 50 for k in ("escape", "navigate", "aim"))
    assert np.mean(tracked) >= AGREEMENT


def test_dodger_agrees_with_python_dodger():
    """Dodger against the sniper (80 frames of 100 matches), both seats compared; the dodge
    branch must have been taken."""
    modes = {}

    def check(f, bots, memory):
        for m in range(MATCHES):
            mode = bots[m][0].mode
            modes[mode] = modes.get(mode, 0) + 1
    agree, total, _ = play(("dodger", "sniper"), frames=80, seed=31, on_frame=check)
    assert_agrees("dodger", agree[0], total[0])
    assert_agrees("sniper (as the dodger's opponent)", agree[1], total[1])
    print("dodger modes", modes)
    assert modes.get("dodge", 0) > 20


def test_parameters_are_the_python_bots_defaults():
    for cls, params in ((chaser.Chaser, cb.CHASER_PARAMS), (sniper.Sniper, cb.SNIPER_PARAMS),
                        (dodger.Dodger, cb.DODGER_PARAMS)):
        defaults = {k: v.default for k, v in inspect.signature(cls.__init__).parameters.items()
                    if v.default is not inspect.Parameter.empty and k != "seed"}
        assert {k: v for k, v in defaults.items() if k in params} == params
        assert set(defaults) <= set(params) | {"sniper_options"}


def test_reset_memory_is_a_fresh_bot():
    """After play, ``reset_memory`` gives the memory of ``new_memory`` for that seat only, and
    the Python bots' ``reset()`` gives their fresh state; from there both decide alike."""
    game = Game(seeds=list(range(8)), rounds=3)
    scatter(game, np.random.default_rng(5))
    memory = cb.new_memory(8)
    streams = cb.new_streams(8, 5)
    codes = np.zeros((8, 2), dtype=np.int64)
    for _ in range(40):
        cb.decide_all(cb.KINDS["sniper"], 0, *arrays(game, memory, streams), codes)
        cb.decide_all(cb.KINDS["chaser"], 1, *arrays(game, memory, streams), codes)
        game.step(codes)
    assert np.any(memory[:, 0] != 0.0)
    before = memory.copy()
    cb.reset_memory(3, 0, memory)
    assert np.array_equal(memory[3, 0], cb.new_memory(1)[0, 0])
    untouched = np.ones(memory.shape[:2], dtype=bool)
    untouched[3, 0] = False
    assert np.array_equal(memory[untouched], before[untouched])
    # a Python sniper that has played, then reset(), decides like the reset compiled one
    bot = sniper.Sniper()
    for _ in range(5):
        bot.act(game.observe(3, 0))
    bot.reset()
    assert not bot.escaping and bot._last is None and not bot.enemy_thrust.any()
    for _ in range(30):
        py = bot.act(game.observe(3, 0)).code()
        code = cb.decide(cb.KINDS["sniper"], 3, 0, *arrays(game, memory, streams))
        assert code == py
        codes[:, 0] = core.NOOP
        codes[3, 0] = code
        game.step(codes)


def test_random_bot_frequencies():
    """Over 4096 matches x 40 frames per seat, each button's frequency is within 5 standard
    deviations of its probability (thrust 0.5, fire 0.2, hyperspace 0.002, each turn 1/3)."""
    m = 4096
    game = Game(seeds=list(range(m)), rounds=3)
    memory = cb.new_memory(m)
    streams = cb.new_streams(m, 9)
    codes = np.zeros((m, 2), dtype=np.int64)
    seen = []
    for _ in range(40):
        for s in range(2):
            cb.decide_all(cb.KINDS["random"], s, *arrays(game, memory, streams), codes)
        seen.append(codes.copy())
    seen = np.array(seen).ravel()
    n = seen.size
    for name, hit, p in (("turn -1", seen % 3 == 0, 1 / 3), ("turn 0", seen % 3 == 1, 1 / 3),
                         ("thrust", (seen // 3) % 2 == 1, 0.5), ("fire", (seen // 6) % 2 == 1, 0.2),
                         ("hyperspace", (seen // 12) % 2 == 1, 0.002)):
        sigma = math.sqrt(n * p * (1 - p))
        assert abs(hit.sum() - n * p) < 5 * sigma, (name, hit.sum(), n * p)
    assert not np.any(seen >= 24)  # never flips
    # the two seats' streams differ
    assert not np.array_equal(np.array(seen).reshape(40, m, 2)[:, :, 0],
                              np.array(seen).reshape(40, m, 2)[:, :, 1])


@pytest.mark.parametrize("name", ["idle", "random", "chaser", "sniper", "dodger"])
def test_deterministic(name):
    """Same state, memory and streams: the same codes, from decide_all (threads) and from
    decide (one match at a time)."""
    m = 64
    game = Game(seeds=list(range(m)), rounds=3)
    scatter(game, np.random.default_rng(3))
    runs = []
    for way in ("all", "all", "one"):
        g = Game(seeds=list(range(m)), rounds=3)
        for a in ("pos", "vel"):
            getattr(g, a)[:] = getattr(game, a)
        g.ship_gauges[:] = game.ship_gauges
        g.ship_counters[:] = game.ship_counters
        memory = cb.new_memory(m)
        streams = cb.new_streams(m, 3)
        codes = np.zeros((m, 2), dtype=np.int64)
        out = []
        for _ in range(30):
            for s, kind in ((0, cb.KINDS[name]), (1, cb.KINDS["chaser"])):
                if way == "all":
                    cb.decide_all(kind, s, *arrays(g, memory, streams), codes)
                else:
                    for k in range(m):
                        codes[k, s] = cb.decide(kind, k, s, *arrays(g, memory, streams))
            out.append(codes.copy())
            g.step(codes)
        runs.append((np.array(out), memory.copy(), streams.copy()))
    for other in runs[1:]:
        for a, b in zip(runs[0], other):
            assert np.array_equal(a, b)
    if name == "idle":
        assert np.all(runs[0][0][:, :, 0] == core.NOOP)


def test_reference_arithmetic():
    """The pieces that reproduce Python's and numpy's own arithmetic: CPython's hypot and
    numpy's (BLAS) dot of 2-vectors, bit for bit."""
    rng = np.random.default_rng(0)
    xy = rng.normal(size=(20000, 2)) * np.exp(rng.uniform(-15, 2, size=(20000, 1)))
    assert all(cb.py_hypot(x, y) == math.hypot(x, y) for x, y in xy)
    other = rng.normal(size=(20000, 2))
    same = sum(cb.dot_blas(a[0], a[1], b[0], b[1]) == float(a @ b) for a, b in zip(xy, other))
    if numpy_dot_kind() == "other":
        pytest.skip(f"numpy's 2-vector dot rounds neither plain nor fused here ({same} of 20000)")
    assert same == 20000, numpy_dot_kind()
    r = Rules()
    assert (0.5 * r.star_capture) ** 2 == (0.5 * r.star_capture) * (0.5 * r.star_capture)
    assert (1.2 * r.star_capture) ** 2 == (1.2 * r.star_capture) * (1.2 * r.star_capture)
