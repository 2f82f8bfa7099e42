"""Batch bots: one act_batch call for all of a bot's matches, results identical to matches
played alone, and hostile batch answers that are faults, never crashes."""
import json
import sys
import textwrap

import numpy as np
import pytest

from spacewar import Rules
from spacewar.codes import NOOP
from spacewar.bots.batch import SingleFromBatch, ask_batch, checked_codes
from spacewar.arena.batch_match import play_matches
from spacewar.learn.batch import learning_layout
from spacewar.arena.match import play_match
from spacewar.sandbox.limits import Limits
from spacewar.wire import INVALID, OK, RAISED

SHORT = Rules(max_round_frames=400, post_round_delay=8)
ROOMY = Limits(budget=2.0, overage=20.0, startup=60.0, stop_after=0.5)
NAMES = learning_layout(SHORT)


class Pointer:
    """A stateless batch policy: turn toward the enemy (the sign of heading x direction),
    fire when nearly lined up; every row decided at once in NumPy."""

    def __init__(self):
        self.calls = []
        self.i = {n: NAMES.index(n) for n in ("enemy.dx", "enemy.dy", "me.cos_heading",
                                                  "me.sin_heading")}

    def act_batch(self, obs):
        self.calls.append(obs.shape)
        dx, dy = obs[:, self.i["enemy.dx"]], obs[:, self.i["enemy.dy"]]
        cross = obs[:, self.i["me.cos_heading"]] * dy - obs[:, self.i["me.sin_heading"]] * dx
        turn = np.where(cross > 0.05, 2, np.where(cross < -0.05, 0, 1))
        return (turn + 6 * (np.abs(cross) < 0.1)).astype(np.int64)


def _same(a, b):
    return json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def test_matches_played_together_give_each_match_alone():
    bot = Pointer()
    jobs = [("chaser", "sniper", 3), (bot, "chaser", 5), ("dodger", bot, 6), (bot, bot, 7),
            ("random", "idle", 8)]
    together = play_matches(jobs, rounds=1, rules=SHORT)
    calls = len(bot.calls)
    assert {shape for shape in bot.calls} == {(4, len(NAMES))}  # one call: all 4 of its rows
    for (result, _), (p1, p2, seed) in zip(together, jobs):
        alone, _, _ = play_match(p1, p2, seed=seed, rounds=1, rules=SHORT)
        assert _same(result, alone), (p1, p2)
    assert calls == max(r["steps"] for r, _ in together[1:4])


def test_matches_played_together_record_each_match_s_replay_and_act_times():
    """What ``spacewar check`` compares to judge a batch bot's determinism: each match's
    replay (actions, faults, final state) as the match alone records it, faults included."""
    bot, raising = Pointer(), Raising()
    jobs = [(bot, "chaser", 5), ("dodger", bot, 6), (raising, "sniper", 2), ("idle", "random", 8)]
    together = play_matches(jobs, rounds=1, rules=SHORT, max_faults=9, record=True,
                            act_seconds=True)
    for (result, replay, timing), (p1, p2, seed) in zip(together, jobs):
        alone, replay_alone, timing_alone = play_match(p1, p2, seed=seed, rounds=1, rules=SHORT,
                                                       max_faults=9, record=True)
        assert _same(result, alone) and _same(replay, replay_alone), (p1, p2)
        asked = [len(t) for t in timing["act_seconds"]]
        assert asked == [a["count"] for a in timing_alone["act"]] == \
            [a["count"] for a in timing["act"]], (p1, p2)
    assert together[2][0]["faults"][0]["raised"] == 9 and together[2][0]["forfeits"][0]


class Raising:
    def act_batch(self, obs):
        raise RuntimeError("no policy here")


class Lying:
    """Answers that are not one valid code per row, in turn."""

    def __init__(self):
        self.k = 0

    def act_batch(self, obs):
        self.k += 1
        k = len(obs)
        answers = [np.zeros(k + 1, dtype=np.int64), np.full(k, 0.5), np.full(k, 48),
                   [True] * k, "0" * k, (x for x in range(k)), None, np.full((k, 1), 1),
                   _Evil()]
        return answers[self.k % len(answers)]


class _Evil:
    def __len__(self):
        raise SystemExit("len")

    def __array__(self, *args, **kwargs):
        raise SystemExit("array")


@pytest.mark.parametrize("bot, kind", [(Raising(), "raised"), (Lying(), "invalid")])
def test_bad_batch_answers_are_faults_of_its_matches_only(bot, kind):
    jobs = [(bot, "idle", 1), ("chaser", "idle", 2), ("idle", bot, 3)]
    together = play_matches(jobs, rounds=1, rules=SHORT, max_faults=9)
    for m in (0, 2):
        result = together[m][0]
        seat = 0 if m == 0 else 1
        assert result["forfeits"][seat] and result["faults"][seat][kind] == 9
        assert result["winner"] == "idle" and result["steps"] == 8
    alone, _, _ = play_match("chaser", "idle", seed=2, rounds=1, rules=SHORT)
    assert _same(together[1][0], alone)


def test_checked_codes_take_only_k_valid_integers():
    np.testing.assert_array_equal(checked_codes([1, np.int32(2)], 2), [1, 2])
    for bad in ([1], [1.0, 2.0], np.array([1, 99]), np.array([-1, 0]), np.zeros((2, 1), int),
                {0: 1, 1: 2}, b"\x01\x02"):
        with pytest.raises(ValueError):
            checked_codes(bad, 2)
    status, codes, text = ask_batch(Lying(), np.zeros((3, 5), np.float32))
    assert status == INVALID and (codes == NOOP).all() and "3" in text
    assert ask_batch(Raising(), np.zeros((1, 5), np.float32))[0] == RAISED


def test_one_match_asks_a_batch_bot_with_one_row():
    from spacewar import Game
    from spacewar.learn.batch import learning_vector

    game = Game(SHORT, seeds=[4], rounds=2)
    for _ in range(50):
        game.step([[10, 5]])
    bot = Pointer()
    single = SingleFromBatch(bot, SHORT, 2)
    status, code, _ = single.answer(game.observe(0, 1))
    row = learning_vector(game.raw_observation(0, 1), SHORT, 2)
    assert status == OK and code == bot.act_batch(row[None])[0] and bot.calls[0] == (1, len(NAMES))
    np.testing.assert_array_equal(game.learning_observations()[0, 1], row)


def test_a_batch_bot_from_a_file_plays_in_its_confined_process(tmp_path):
    path = tmp_path / "batchbot.py"
    path.write_text(textwrap.dedent(f"""
        import numpy as np
        NAMES = {NAMES!r}
        class Pointer:
            def act_batch(self, obs):
                i = NAMES.index
                dx, dy = obs[:, i("enemy.dx")], obs[:, i("enemy.dy")]
                cross = obs[:, i("me.cos_heading")] * dy - obs[:, i("me.sin_heading")] * dx
                turn = np.where(cross > 0.05, 2, np.where(cross < -0.05, 0, 1))
                return (turn + 6 * (np.abs(cross) < 0.1)).astype(np.int64)
        class Reader:
            def act_batch(self, obs):
                return [len(open("/etc/shadow").read())] * len(obs)
    """))
    confined, _, _ = play_match(f"{path}:Pointer", "chaser", seed=5, rounds=1, rules=SHORT,
                                limits=ROOMY)
    inline, _, _ = play_match(Pointer(), "chaser", seed=5, rounds=1, rules=SHORT)
    assert confined["score"] == inline["score"] and confined["steps"] == inline["steps"]
    assert confined["faults"][0]["total"] == 0
    if sys.platform.startswith("linux"):
        hostile, _, _ = play_match(f"{path}:Reader", "idle", seed=5, rounds=1, rules=SHORT,
                                   limits=ROOMY, max_faults=3)
        assert hostile["forfeits"][0] and hostile["faults"][0]["raised"] == 3
        assert "Error" in hostile["faults"][0]["examples"][0]["message"]


def test_only_bots_that_can_share_a_game_are_played_together(tmp_path):
    with pytest.raises(ValueError, match="plays with play_match"):
        play_matches([("tests.spacewar.hostile_bots:Crasher", "idle", 1)], rules=SHORT)


@pytest.fixture(scope="module")
def policy_file(tmp_path_factory, optional):
    optional("jax")
    optional("optax")
    from spacewar.learn import train

    config = train.TrainConfig(seed=3)
    path = str(tmp_path_factory.mktemp("policy") / "policy.npz")
    params = train.initial_params(config)
    train.save_params(path, params, config)
    return path


def test_a_policy_file_plays_together_as_its_bot_plays_alone(policy_file):
    from spacewar.policy import PolicyBot

    jobs = [(policy_file, "chaser", 1), ("chaser", policy_file, 1),
            (policy_file, policy_file, 2), ("idle", policy_file, 3)]
    together = play_matches(jobs, rounds=1)
    for (result, _), (p1, p2, seed) in zip(together, jobs):
        alone, _, _ = play_match(p1, p2, seed=seed, rounds=1)
        assert _same(result, alone), (p1, p2)
    other = Rules(max_round_frames=400)  # not the rules it was trained under
    bad = play_matches([(policy_file, "idle", 4)], rules=other, rounds=1, max_faults=5)[0][0]
    alone, _, _ = play_match(policy_file, "idle", seed=4, rules=other, rounds=1, max_faults=5)
    assert _same(bad, alone) and bad["forfeits"][0] and "other rules" in \
        bad["faults"][0]["examples"][0]["message"]
    assert PolicyBot(policy_file).policy.frame_skip > 1  # the holding is exercised


def test_a_policy_file_is_the_envs_opponent_as_its_bot_would_play(policy_file, tmp_path,
                                                                  optional):
    optional("gymnasium")
    import shutil

    from spacewar.learn import envs
    from spacewar.policy import PolicyBot
    from spacewar.protocol import action_code

    shouting = str(tmp_path / "POLICY.NPZ")  # the suffix is found whatever its case
    shutil.copy(policy_file, shouting)
    vec = envs.SpacewarVectorEnv(3, opponent=shouting, max_frames=30)
    vec.reset(seed=2)
    bots = [PolicyBot(policy_file) for _ in range(3)]
    rng = np.random.default_rng(4)
    ended = np.zeros(3, dtype=bool)
    played = 0
    for _ in range(70):  # past two truncations: the bots restart with their matches
        game = vec.batch.game
        if ended.all():  # this step restarts the matches (next-step autoreset)
            vec.step(rng.integers(0, [3, 2, 2, 2], size=(3, 4)))
            for bot in bots:
                bot.reset()
            ended[:] = False
            continue
        expected = [action_code(bots[m].act(game.observe(m, 1))) for m in range(3)]
        *_, terminated, truncated, _ = vec.step(rng.integers(0, [3, 2, 2, 2], size=(3, 4)))
        assert vec.batch.actions[:, 1].tolist() == expected
        ended = terminated | truncated
        played += 1
    assert played == 68
