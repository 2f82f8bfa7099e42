"""The Gymnasium environments: the standard checker, registration, self-play, seeding."""
import numpy as np
import pytest

from spacewar.bots.idle import Idle
from spacewar.learn.batch import learning_length
from spacewar.rules import Rules


@pytest.mark.parametrize("opponent", ["idle", "random"])
def test_the_env_passes_gymnasiums_checker(opponent, gymnasium, envs):
    from gymnasium.utils.env_checker import check_env

    env = gymnasium.make("Spacewar-v0", opponent=opponent, max_frames=300)
    check_env(env.unwrapped, skip_render_check=True)


def test_make_vec_gives_the_native_vector_env_and_its_spaces(envs, gymnasium):
    envs_ = gymnasium.make_vec("Spacewar-v0", num_envs=16, opponent="random", max_frames=200)
    assert isinstance(envs_, envs.SpacewarVectorEnv)
    assert envs_.metadata["autoreset_mode"] == gymnasium.vector.AutoresetMode.NEXT_STEP
    obs, info = envs_.reset(seed=3)
    assert obs.shape == (16, learning_length(Rules())) and obs.dtype == np.float32
    assert envs_.observation_space.contains(obs)
    ended = np.zeros(16, dtype=bool)
    for _ in range(230):
        obs, reward, terminated, truncated, info = envs_.step(envs_.action_space.sample())
        assert envs_.observation_space.contains(obs) and reward.shape == (16,)
        ended |= truncated
    assert ended.all()  # every match was cut at max_frames and restarted


def test_self_play_puts_both_seats_on_the_agent_axis(envs):
    vec = envs.SpacewarVectorEnv(8, opponent=None, max_frames=500)
    obs, _ = vec.reset(seed=1)
    assert obs.shape == (8, learning_length(Rules()))
    total = np.zeros(8)
    for _ in range(500):
        obs, reward, terminated, truncated, _ = vec.step(vec.action_space.sample())
        total += reward
        assert np.all(terminated[0::2] == terminated[1::2])
    np.testing.assert_array_equal(total[0::2], -total[1::2])  # zero-sum seats
    with pytest.raises(ValueError, match="self-play .* needs an even num_envs"):
        envs.SpacewarVectorEnv(3, opponent=None)


def test_a_seed_fixes_the_run(envs):
    def run(seed):
        vec = envs.SpacewarVectorEnv(4, opponent="random", max_frames=400)
        obs, _ = vec.reset(seed=seed)
        rng = np.random.default_rng(0)
        trace = [obs]
        for _ in range(300):
            trace.append(vec.step(rng.integers(0, [3, 2, 2, 2], size=(4, 4)))[0])
        return np.array(trace)
    np.testing.assert_array_equal(run(7), run(7))
    assert not np.array_equal(run(7), run(8))


def test_bad_arguments_are_refused(envs):
    with pytest.raises(ValueError, match="opponent must be None, one of .*idle.*random"):
        envs.SpacewarVectorEnv(2, opponent="nobody")
    with pytest.raises(ValueError, match="a Python bot keeps state per match"):
        envs.SpacewarVectorEnv(2, opponent=Idle())
    with pytest.raises(ValueError, match="autoreset_mode must be one of"):
        envs.SpacewarVectorEnv(2, autoreset_mode="sometimes")
    with pytest.raises(ValueError, match="action_type must be one of"):
        envs.SpacewarVectorEnv(2, action_type="continuous")
    vec = envs.SpacewarVectorEnv(2, opponent="idle")
    with pytest.raises(RuntimeError, match="call reset"):
        vec.step(np.zeros((2, 4), dtype=np.int64))
    vec.reset(seed=0)
    with pytest.raises(ValueError, match="actions must be 2 actions of MultiDiscrete"):
        vec.step(np.full((2, 4), 5))
    np.testing.assert_array_equal(envs.codes_from_parts([[2, 1, 1, 0]]), [2 + 3 + 6])


def test_the_parallel_env_passes_pettingzoos_api_and_seed_tests(envs, optional):
    optional("pettingzoo")
    from pettingzoo.test import parallel_api_test, parallel_seed_test

    parallel_api_test(envs.parallel_env(max_frames=400), num_cycles=500)
    parallel_seed_test(lambda: envs.parallel_env(max_frames=400), num_cycles=300)


def test_the_parallel_env_is_a_zero_sum_match_that_ends_for_both(envs, optional):
    optional("pettingzoo")
    env = envs.parallel_env(max_frames=600)
    obs, infos = env.reset(seed=4)
    assert set(obs) == set(envs.AGENTS)
    totals = dict.fromkeys(envs.AGENTS, 0.0)
    while env.agents:
        obs, rewards, terms, truncs, infos = env.step(
            {a: env.action_space(a).sample() for a in env.agents})
        for a, r in rewards.items():
            totals[a] += r
    assert totals["ship_0"] == -totals["ship_1"] and (any(terms.values()) or any(truncs.values()))
    with pytest.raises(RuntimeError, match="the match has ended"):
        env.step({a: np.zeros(4, dtype=np.int64) for a in envs.AGENTS})
