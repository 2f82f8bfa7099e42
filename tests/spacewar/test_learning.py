"""Learning observations: the compiled writer against the NumPy definition, bounds, layout."""
import numpy as np
import pytest

from spacewar import Game, Rules
from spacewar.learn.batch import learning_layout, learning_length, torpedo_slots


def _played(rules, matches=6, frames=400, seed=3):
    game = Game(rules, seeds=range(matches), rounds=3)
    rng = np.random.default_rng(seed)
    states = []
    for f in range(frames):
        game.step(rng.integers(0, 48 if rules.mode == "electric" else 24, size=(matches, 2)))
        if f % 40 == 39:
            states.append(game.learning_observations().copy())
    return game, states


@pytest.mark.parametrize("mode", ["classic", "newtonian", "electric"])
def test_the_compiled_observations_are_the_numpy_definition(mode):
    rules = Rules(mode=mode)
    game, _ = _played(rules)
    obs = game.learning_observations()
    assert obs.shape == (6, 2, learning_length(rules)) and obs.dtype == np.float32
    for m in range(6):
        for seat in range(2):
            # cos and sin may round differently in compiled code: one float32 ulp at most
            np.testing.assert_array_max_ulp(obs[m, seat], game.learning_observation(m, seat), 1)


@pytest.mark.parametrize("changes, slots, reached", [
    ({}, 6, True),                                  # 1962: life 96, reload 16
    ({"reload": 4, "torpedo_life": 30}, 8, True),   # 28 // 4 + 1
    ({"reload": 0}, 32, False),                     # a torpedo every frame: up to all 32
    ({"reload": 1, "torpedo_life": 12}, 11, False),
    ({"reload": 5, "torpedo_life": 40, "single_shot": True}, 8, False),
    ({"reload": 16, "torpedo_life": 17}, 1, True),
])
def test_the_torpedo_slots_hold_every_torpedo_in_flight(changes, slots, reached):
    """S is the most torpedoes a ship can have in flight, so the torpedoes that share a slot
    (k mod S) are never in flight together: ships that fire whenever they can, at the fastest
    cadence the rules allow, never see a torpedo missing, and fill every slot where the
    torpedoes fly far enough apart not to destroy each other."""
    rules = Rules(**changes)
    assert torpedo_slots(rules) == slots
    game = Game(rules, seeds=range(4), rounds=3)
    names = learning_layout(rules)
    present = [k for k, name in enumerate(names) if name.endswith(".present")]
    assert len(present) == 2 * slots
    most = 0
    for f in range(300):
        fire = 6 + 1 if not rules.single_shot or f % 2 == 0 else 1  # fire, no turn; released
        game.step(np.full((4, 2), fire))
        obs = game.learning_observations()
        live = game.active[:, 2:].reshape(4, 2, rules.torpedoes).sum(axis=2)
        # every torpedo in flight has a slot of its own: as many present flags as torpedoes
        seen = obs[:, :, present].reshape(4, 2, 2, slots).sum(axis=3)
        np.testing.assert_array_equal(seen[:, 0, 0], live[:, 0])
        np.testing.assert_array_equal(seen[:, 0, 1], live[:, 1])
        most = max(most, int(live.max()))
    assert most == slots if reached else most <= slots


def test_layout_names_every_entry_and_values_stay_about_unit():
    rules = Rules()
    names = learning_layout(rules)
    assert len(names) == len(set(names)) == learning_length(rules)
    _, states = _played(rules, matches=8, frames=1200)
    values = np.concatenate([s.reshape(-1, len(names)) for s in states])
    assert np.all(np.isfinite(values))
    assert np.abs(values).max() <= 1.5, names[int(np.abs(values).max(0).argmax())]
    # relative positions by the nearest image: never beyond half the torus
    for k, name in enumerate(names):
        if name.endswith(("dx", "dy")):
            assert np.abs(values[:, k]).max() <= 1.0, name


def test_the_seats_see_each_other_egocentrically():
    game = Game(Rules(), seeds=[0], rounds=1)
    game.pos[0, :, 0] = (0.45, 0.0)
    game.pos[0, :, 1] = (-0.45, 0.1)  # 0.1 away through the edge, 0.1 up
    obs = game.learning_observations()
    names = learning_layout(game.rules)
    dx, dy = names.index("enemy.dx"), names.index("enemy.dy")
    np.testing.assert_allclose(obs[0, 0, [dx, dy]], [0.2, 0.2], rtol=1e-6)
    np.testing.assert_allclose(obs[0, 1, [dx, dy]], [-0.2, -0.2], rtol=1e-6)


def test_out_is_checked_and_written_in_place():
    game = Game(Rules(), seeds=[0, 1], rounds=1)
    buffer = np.zeros((2, 2, learning_length(game.rules)), dtype=np.float32)
    assert game.learning_observations(buffer) is buffer and buffer.any()
    with pytest.raises(ValueError, match="out must be a writeable C-contiguous float32"):
        game.learning_observations(np.zeros((2, 2, 3), dtype=np.float32))


def test_a_run_is_the_same_whatever_the_batch_size_and_thread_count():
    import numba

    from spacewar.learn.batch import LearningBatch

    threads = numba.get_num_threads()

    # the same actions for the first three matches: drive both with one action stream
    def driven(matches):
        batch = LearningBatch(matches, seed=11, rounds=1, frame_cap=300)
        rng = np.random.default_rng(2)
        out = []
        for _ in range(700):
            codes = np.zeros((matches, 2), dtype=np.int64)
            codes[:3] = rng.integers(0, 24, size=(3, 2))
            obs, rew, term, trunc = batch.step(codes)
            out.append((obs[:3].copy(), rew[:3].copy(), term[:3].copy(), trunc[:3].copy()))
        return out
    try:  # all the threads numba may start (a test worker runs on one), then one
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        a = driven(3)
        numba.set_num_threads(1)
        b = driven(7)
    finally:
        numba.set_num_threads(threads)
    for x, y in zip(a, b):
        for u, v in zip(x, y):
            np.testing.assert_array_equal(u, v)
    assert any(t.any() for _, _, _, t in a)  # episodes were cut at the frame cap and restarted


def test_rewards_follow_the_score_and_episodes_restart_the_step_after_they_end():
    from spacewar.learn.batch import LearningBatch, learning_layout

    batch = LearningBatch(4, seed=3, rounds=2)
    names = learning_layout(batch.rules)
    round_time = names.index("round_time_fraction")
    rng = np.random.default_rng(8)
    totals = np.zeros((4, 2))
    ended = np.zeros(4, dtype=bool)
    restarted = np.zeros(4, dtype=bool)
    obs, rew, term, trunc = batch.step(np.zeros((4, 2), dtype=np.int64))  # the first call resets
    assert not rew.any() and not term.any() and np.all(obs[:, :, round_time] == 0.0)
    for _ in range(20000):
        was_ended = term.copy()
        before = batch.game.scores.copy()
        obs, rew, term, trunc = batch.step(rng.integers(0, 24, size=(4, 2)))
        after = batch.game.scores
        for m in range(4):
            if was_ended[m]:  # the call after the end: a fresh match, no reward
                assert not rew[m].any() and batch.game.frame[m] == 0
                assert np.all(obs[m, :, round_time] == 0.0)
                restarted[m] = True
                continue
            d = after[m] - before[m]
            expected = np.sign(d[0] - d[1]) if (d > 0).sum() == 1 else 0.0
            assert rew[m, 0] == expected and rew[m, 1] == -expected
            if not ended[m]:
                totals[m] += rew[m]
        for m in np.flatnonzero(term):
            if not ended[m]:
                ended[m] = True
                score = batch.game.scores[m]
                # a round scored for one seat alone is +-1; for both or neither it is 0: so an
                # episode's rewards add up to the final score difference
                assert totals[m, 0] == score[0] - score[1] == -totals[m, 1]
        np.testing.assert_array_equal(obs, batch.game.learning_observations())
        if restarted.all():
            break
    assert restarted.all() and not trunc.any()
    assert np.all(totals[:, 0] == -totals[:, 1])


def test_bad_frame_cap_is_refused():
    from spacewar.learn.batch import LearningBatch

    with pytest.raises(ValueError, match="frame_cap must be an int >= 0, got -1"):
        LearningBatch(2, frame_cap=-1)
