"""The vector env's autoreset modes, action types, opponents and rendering."""
import numpy as np
import pytest

from spacewar.bots.chaser import Chaser
from spacewar.rules import Rules

CAP = 40  # frames: episodes end by truncation, at a known step


def _lockstep(envs, mode, steps, num_envs=3, seed=11):
    """The same seeded run under next-step autoreset and under ``mode``, step by step."""
    ref = envs.SpacewarVectorEnv(num_envs, opponent="random", max_frames=CAP)
    other = envs.SpacewarVectorEnv(num_envs, opponent="random", max_frames=CAP,
                                   autoreset_mode=mode)
    actions = np.random.default_rng(0).integers(0, [3, 2, 2, 2], size=(steps, num_envs, 4))
    return ref, other, actions, ref.reset(seed=seed)[0], other.reset(seed=seed)[0]


def test_same_step_autoreset_returns_the_next_episode_and_the_final_observation(envs, gymnasium):
    ref, same, actions, o_ref, o_same = _lockstep(envs, "same_step", 2 * CAP + 4)
    assert same.metadata["autoreset_mode"] == gymnasium.vector.AutoresetMode.SAME_STEP
    np.testing.assert_array_equal(o_ref, o_same)
    k = 0
    ends = 0
    for a in actions[:CAP]:
        o_ref, r_ref, t_ref, u_ref, _ = ref.step(a)
        o_same, r_same, t_same, u_same, info = same.step(a)
        np.testing.assert_array_equal(r_ref, r_same)
        np.testing.assert_array_equal(u_ref, u_same)
        if u_ref.any():
            ends += 1
            # the ended episode's last observation is what next-step mode shows now ...
            assert info["_final_obs"].tolist() == u_ref.tolist()
            assert info["final_info"] == {} and info["_final_info"].tolist() == u_ref.tolist()
            for e in np.flatnonzero(u_ref):
                np.testing.assert_array_equal(info["final_obs"][e], o_ref[e])
            # ... and same-step already shows the next episode, which next-step shows next
            o_ref2, r_ref2, *_ = ref.step(actions[CAP])
            np.testing.assert_array_equal(o_ref2, o_same)
            assert (r_ref2 == 0).all()
        else:
            np.testing.assert_array_equal(o_ref, o_same)
            assert info == {}
        k += 1
    assert ends == 1 and k == CAP


def test_disabled_autoreset_waits_for_a_reset_mask(envs):
    ref, off, actions, _, _ = _lockstep(envs, "disabled", CAP + 1)
    for a in actions[:CAP]:
        ref.step(a)
        obs, _, _, truncated, _ = off.step(a)
    assert truncated.all()
    with pytest.raises(RuntimeError, match="ended .*reset them"):
        off.step(actions[CAP])
    mask = np.array([True, False, True])
    first = ref.step(actions[CAP])[0]  # next-step mode's restart: each episode's first frame
    again, _ = off.reset(options={"reset_mask": mask})
    np.testing.assert_array_equal(again[mask], first[mask])
    np.testing.assert_array_equal(again[~mask], obs[~mask])  # untouched
    with pytest.raises(RuntimeError, match=r"matches \[1\] ended"):
        off.step(actions[CAP])
    again, _ = off.reset(options={"reset_mask": ~mask})
    np.testing.assert_array_equal(again, first)
    off.step(actions[CAP])  # all restarted: stepping is allowed again
    with pytest.raises(ValueError, match="reset_mask must be a bool array of shape"):
        off.reset(options={"reset_mask": np.ones(2, dtype=bool)})


def test_the_flat_discrete_actions_play_the_same_game(envs, gymnasium):
    multi = envs.SpacewarVectorEnv(4, opponent="random", max_frames=300)
    flat = envs.SpacewarVectorEnv(4, opponent="random", max_frames=300, action_type="discrete")
    assert flat.single_action_space == gymnasium.spaces.Discrete(24)
    a, _ = multi.reset(seed=5)
    b, _ = flat.reset(seed=5)
    parts = np.random.default_rng(1).integers(0, [3, 2, 2, 2], size=(200, 4, 4))
    for p in parts:
        a = multi.step(p)[0]
        b = flat.step(envs.codes_from_parts(p))[0]
        np.testing.assert_array_equal(a, b)


def test_the_electric_mode_has_a_flip_action_that_reverses_the_charge(envs, gymnasium):
    rules = Rules(mode="electric")
    env = envs.SpacewarEnv(opponent="idle", rules=rules, max_frames=100)
    assert env.action_space == gymnasium.spaces.MultiDiscrete([3, 2, 2, 2, 2])
    assert envs.action_space(rules, "discrete") == gymnasium.spaces.Discrete(48)
    names = envs.learning_layout(rules)
    sign = names.index("me.charge_sign")
    obs, _ = env.reset(seed=0)
    before = obs[sign]
    assert before != 0.0
    obs, *_ = env.step(np.array([1, 0, 0, 0, 1]))
    assert obs[sign] == -before
    obs, *_ = env.step(np.array([1, 0, 0, 0, 1]))  # cooling down: no second flip yet
    assert obs[sign] == -before


class _Constant:
    """A batch policy that always answers one action code."""

    def __init__(self, code):
        self.code = code
        self.calls = []

    def act_batch(self, obs):
        self.calls.append(obs.copy())
        return np.full(len(obs), self.code, dtype=np.int64)


def test_a_batch_policy_plays_every_match_from_seat_ones_observations(envs):
    policy = _Constant(3)  # thrust only
    vec = envs.SpacewarVectorEnv(5, opponent=policy, max_frames=200)
    obs, _ = vec.reset(seed=2)
    for _ in range(3):
        seat_one = vec.batch.observations[:, 1].copy()
        vec.step(np.ones((5, 4), dtype=np.int64) * [1, 0, 0, 0])
        np.testing.assert_array_equal(policy.calls[-1], seat_one)  # what seat 1 saw
    assert (vec.batch.actions[:, 1] == 3).all()
    assert len(policy.calls) == 3 and policy.calls[0].dtype == np.float32
    bad = envs.SpacewarVectorEnv(2, opponent=_Constant(99), max_frames=50)
    bad.reset(seed=0)
    with pytest.raises(ValueError, match="act_batch: action code 99 out of range"):
        bad.step(np.ones((2, 4), dtype=np.int64))


def test_a_python_bot_object_can_be_the_single_envs_opponent(envs):
    class Counting(Chaser):
        resets = 0

        def reset(self):
            Counting.resets += 1
            super().reset()

    env = envs.SpacewarEnv(opponent=Counting(), max_frames=60)
    env.reset(seed=1)
    for _ in range(60):
        *_, terminated, truncated, _ = env.step(env.action_space.sample())
    assert truncated
    env.reset()
    assert Counting.resets == 2


def test_rgb_array_rendering_draws_the_match(envs, optional):
    optional("PIL")
    from gymnasium.utils.env_checker import check_env

    env = envs.SpacewarEnv(opponent="random", max_frames=200, render_mode="rgb_array")
    check_env(env)
    env.reset(seed=0)
    first = env.render()
    assert first.shape == (480, 480, 3) and first.dtype == np.uint8 and first.any()
    for _ in range(30):
        env.step(np.array([2, 1, 1, 0]))
    assert (env.render() != first).any()


def test_human_rendering_opens_the_window(monkeypatch, envs, optional):
    optional("pygame")
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    env = envs.SpacewarEnv(opponent="idle", max_frames=20, render_mode="human", size=240)
    env.metadata = {**env.metadata, "render_fps": 0}  # no waiting in a test
    env.reset(seed=0)
    for _ in range(5):
        env.step(np.array([1, 1, 0, 0]))
    assert env._screen is not None and env._screen.get_size() == (240, 240)
    env.close()
    assert env._screen is None


@pytest.mark.parametrize("name", ["chaser", "sniper"])
def test_a_compiled_opponent_decides_as_its_python_twin_inside_the_env(name, envs):
    from spacewar.bots import make_bot
    from spacewar.protocol import action_code

    vec = envs.SpacewarVectorEnv(3, opponent=name, max_frames=2000)
    vec.reset(seed=9)
    twins = [make_bot(name) for _ in range(3)]
    rng = np.random.default_rng(2)
    agree = total = 0
    for frame in range(150):
        game = vec.batch.game
        expected = [action_code(twins[m].act(game.observe(m, 1))) for m in range(3)]
        vec.step(rng.integers(0, [3, 2, 2, 2], size=(3, 4)))
        if frame > 0:  # the first call starts the episodes
            agree += int((vec.batch.actions[:, 1] == expected).sum())
            total += 3
    assert agree == total


def test_a_compiled_opponent_plays_the_same_whatever_the_batch_size(envs):
    small = envs.SpacewarVectorEnv(2, opponent="chaser", max_frames=300)
    large = envs.SpacewarVectorEnv(5, opponent="chaser", max_frames=300)
    a, _ = small.reset(seed=4)
    b, _ = large.reset(seed=4)
    rng = np.random.default_rng(3)
    for _ in range(320):
        parts = rng.integers(0, [3, 2, 2, 2], size=(5, 4))
        a = small.step(parts[:2])[0]
        b = large.step(parts)[0]
        np.testing.assert_array_equal(a, b[:2])
        np.testing.assert_array_equal(small.batch.actions, large.batch.actions[:2])


def test_copy_false_returns_the_batchs_own_buffers_with_the_same_numbers(envs):
    copied = envs.SpacewarVectorEnv(3, opponent="random", max_frames=100)
    shared = envs.SpacewarVectorEnv(3, opponent="random", max_frames=100, copy=False)
    a, _ = copied.reset(seed=1)
    b, _ = shared.reset(seed=1)
    assert not np.shares_memory(a, copied.batch.observations)
    assert np.shares_memory(b, shared.batch.observations)
    parts = np.random.default_rng(0).integers(0, [3, 2, 2, 2], size=(120, 3, 4))
    for p in parts:
        a = copied.step(p)[0]
        b = shared.step(p)[0]
        np.testing.assert_array_equal(a, b)


def test_a_reset_mask_under_next_step_autoreset_restarts_only_the_masked_matches(envs):
    ref, vec, actions, _, _ = _lockstep(envs, "next_step", CAP + 2)
    for a in actions[:CAP]:
        ref.step(a)
        obs, *_ = vec.step(a)
    before = vec.batch.episodes.copy()
    with pytest.raises(ValueError, match="at least one"):
        vec.reset(options={"reset_mask": np.zeros(3, dtype=bool)})
    again, _ = vec.reset(options={"reset_mask": np.array([True, False, False])})
    assert (vec.batch.episodes - before).tolist() == [1, 0, 0]
    np.testing.assert_array_equal(again[1:], obs[1:])  # not restarted yet ...
    after, reward, *_ = vec.step(actions[CAP])
    restarted, *_ = ref.step(actions[CAP])
    np.testing.assert_array_equal(after[1:], restarted[1:])  # ... but at the next step
    assert (reward[1:] == 0).all() and (vec.batch.episodes - before).tolist() == [1, 1, 1]


def test_more_matches_than_chunks_give_the_same_games():
    from spacewar.learn.batch import CHUNKS, LearningBatch

    few = LearningBatch(12, seed=6, frame_cap=500, opponents=("chaser", "sniper"))
    many = LearningBatch(CHUNKS + 44, seed=6, frame_cap=500, opponents=("chaser", "sniper"))
    for _ in range(60):
        few.step()
        many.step()
    np.testing.assert_array_equal(few.actions, many.actions[:12])
    for name in ("pos", "vel"):
        np.testing.assert_array_equal(getattr(few.game, name), getattr(many.game, name)[:12])


def test_a_python_bot_opponent_s_actions_are_played(envs):
    from spacewar.protocol import action_code

    twin = Chaser()
    env = envs.SpacewarEnv(opponent=Chaser(), max_frames=100)
    env.reset(seed=3)
    for _ in range(80):
        expected = action_code(twin.act(env.game.observe(0, 1)))
        env.step(env.action_space.sample())
        assert env._vector.batch.actions[0, 1] == expected


@pytest.mark.parametrize("field, value", [("max_frames", -1), ("max_frames", 2.5),
                                          ("rounds", 0)])
def test_bad_lengths_are_refused_at_construction(field, value, envs):
    with pytest.raises(ValueError, match=f"{field} must be an int"):
        envs.SpacewarVectorEnv(2, **{field: value})
