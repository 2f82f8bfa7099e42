"""Gymnasium environments on the compiled learning batch (``pip install -e '.[rl]'``).

    import gymnasium, spacewar.envs             # importing registers "Spacewar-v0"
    env = gymnasium.make("Spacewar-v0", opponent="random")
    envs = gymnasium.make_vec("Spacewar-v0", num_envs=4096, opponent="random")   # native

``SpacewarVectorEnv`` is native (as Gymnasium's ``CartPoleVectorEnv`` is): every match is
stepped, observed, rewarded and reset by one compiled call of ``spacewar.learning``.
``SpacewarEnv`` is one match of it.

Description
    Spacewar! (1962): two ships, a star, torpedoes and hyperspace on a torus; a learner flies
    seat 0 against an opponent in seat 1 (or, in the vector env with ``opponent=None``, both
    seats learn: the agent axis is then 2 * num_envs, match m's seats at 2m and 2m + 1).
Action space
    ``MultiDiscrete([3, 2, 2, 2])``: turn (0 right, 1 none, 2 left, i.e. turn - 1 of
    ``spacewar.Action``), thrust, fire, hyperspace; the game's action code is
    ``turn + 3 thrust + 6 fire + 12 hyperspace``.
Observation space
    ``Box`` of float32, shape (D,): ``spacewar.learning.learning_layout(rules)`` names the
    entries (egocentric, scaled to about [-1, 1]; see docs/game.md). Relative positions, headings,
    fractions and flags have their exact bounds; velocities are unbounded (thrust has no limit).
Rewards
    +1 when a frame scores a round for the learner's seat and not for the enemy, -1 the other
    way, 0 otherwise: an episode's rewards add up to the final score difference.
Episode end
    ``terminated`` when the match is over (``rounds`` rounds, plus tie-breaks); ``truncated``
    at ``max_frames`` frames (default 20000).
Opponents
    ``"idle"`` (no action) and ``"random"`` (uniform random actions from the env's seed) play
    inside the batch; the compiled versions of the other built-in bots come next.
Version history
    v0: first version.
"""
import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
    from gymnasium.vector import AutoresetMode, VectorEnv
    from gymnasium.vector.utils import batch_space
except ImportError as error:  # pragma: no cover - the extra is missing
    raise ImportError("spacewar.envs needs Gymnasium: pip install -e '.[rl]'") from error

from .learning import LearningBatch, learning_layout, learning_length
from .rules import Rules

OPPONENTS = ("idle", "random", None)
NVEC = (3, 2, 2, 2)
_NOOP_PARTS = (1, 0, 0, 0)


def action_space():
    return spaces.MultiDiscrete(np.array(NVEC, dtype=np.int64))


def observation_space(rules):
    """The Box with each entry's bounds (see the module's text)."""
    names = learning_layout(rules)
    low = np.full(len(names), -np.inf, dtype=np.float32)
    high = np.full(len(names), np.inf, dtype=np.float32)
    for k, name in enumerate(names):
        field = name.rsplit(".", 1)[-1]
        if field in ("dx", "dy", "star_dx", "star_dy", "cos_heading", "sin_heading",
                     "charge_sign", "turn_rate"):
            low[k], high[k] = -1.0, 1.0
        elif field in ("round_time_fraction", "rounds_fraction"):
            low[k] = 0.0  # past 1 in the post-round delay and in tie-break rounds
        elif field != "score_difference" and not field.startswith(("vx", "vy", "dvx", "dvy")):
            low[k], high[k] = 0.0, 1.0
    return spaces.Box(low, high, dtype=np.float32)


def codes_from_parts(parts):
    """(K, 4) MultiDiscrete actions as the game's action codes (K,)."""
    parts = np.asarray(parts, dtype=np.int64).reshape(-1, 4)
    return parts[:, 0] + 3 * parts[:, 1] + 6 * parts[:, 2] + 12 * parts[:, 3]


def _check(name, value, allowed):
    if value not in allowed:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, allowed))}, got {value!r}")
    return value


class SpacewarVectorEnv(VectorEnv):
    """``num_envs`` matches stepped together (see the module's text)."""

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, num_envs=1, opponent="random", rules=None, rounds=3, max_frames=20000,
                 render_mode=None):
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) \
                or num_envs < 1:
            raise ValueError(f"num_envs must be an int >= 1, got {num_envs!r}")
        self.opponent = _check("opponent", opponent, OPPONENTS)
        if render_mode is not None:
            raise ValueError(f"render_mode must be None for the vector env, got {render_mode!r}")
        self.render_mode = None
        self.rules = Rules() if rules is None else rules
        self.rounds = rounds
        self.max_frames = max_frames
        self.matches = int(num_envs) if opponent is not None else (int(num_envs) + 1) // 2
        if opponent is None and num_envs % 2:
            raise ValueError(f"self-play (opponent=None) needs an even num_envs (two seats a "
                             f"match), got {num_envs}")
        self.num_envs = int(num_envs)
        self.single_action_space = action_space()
        self.single_observation_space = observation_space(self.rules)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self._batch = None
        self._seed = None
        self._opponent_rng = None
        self._codes = np.zeros((self.matches, 2), dtype=np.int64)

    def _new_batch(self, seed):
        self._seed = int(np.random.SeedSequence(seed).entropy if seed is None else seed)
        self._batch = LearningBatch(self.matches, self.rules, seed=self._seed, rounds=self.rounds,
                                    frame_cap=self.max_frames)
        self._opponent_rng = np.random.default_rng([self._seed, 1])

    def _view(self, array):
        """(M, 2, ...) per seat as the agent axis: seat 0 of each match, or both seats."""
        if self.opponent is None:
            return array.reshape((2 * self.matches,) + array.shape[2:])
        return array[:, 0]

    def reset(self, *, seed=None, options=None):
        if seed is not None or self._batch is None:
            self._new_batch(seed)
        else:
            self._batch.pending[:] = True
        self._codes[:] = 4  # turn none; what the resetting call ignores anyway
        obs, _, _, _ = self._batch.step(self._codes)
        return self._view(obs).copy(), {}

    def step(self, actions):
        if self._batch is None:
            raise RuntimeError("call reset() before step()")
        parts = np.asarray(actions, dtype=np.int64)
        if not self.action_space.contains(parts):
            raise ValueError(f"actions must be {self.num_envs} MultiDiscrete{list(NVEC)} actions, "
                             f"got {np.asarray(actions).tolist()!r:.200}")
        codes = codes_from_parts(parts)
        if self.opponent is None:
            self._codes[:] = codes.reshape(self.matches, 2)
        else:
            self._codes[:, 0] = codes
            if self.opponent == "idle":
                self._codes[:, 1] = codes_from_parts(_NOOP_PARTS)[0]
            else:
                self._codes[:, 1] = self._opponent_rng.integers(0, 24, size=self.matches)
        obs, rewards, terminated, truncated = self._batch.step(self._codes)
        if self.opponent is None:
            done_t = np.repeat(terminated, 2)
            done_u = np.repeat(truncated, 2)
        else:
            done_t, done_u = terminated, truncated
        return (self._view(obs).copy(), self._view(rewards).astype(np.float64),
                done_t.copy(), done_u.copy(), {})


class SpacewarEnv(gymnasium.Env):
    """One match against an opponent (see the module's text)."""

    metadata = {"render_modes": []}

    def __init__(self, opponent="random", rules=None, rounds=3, max_frames=20000,
                 render_mode=None):
        _check("opponent", opponent, ("idle", "random"))
        self._vector = SpacewarVectorEnv(1, opponent=opponent, rules=rules, rounds=rounds,
                                         max_frames=max_frames, render_mode=render_mode)
        self.render_mode = None
        self.action_space = self._vector.single_action_space
        self.observation_space = self._vector.single_observation_space
        self._ended = False

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        obs, info = self._vector.reset(seed=seed, options=options)
        self._ended = False
        return obs[0], info

    def step(self, action):
        if self._ended:
            raise RuntimeError("the episode has ended: call reset()")
        obs, rewards, terminated, truncated, info = self._vector.step(np.asarray(action)[None])
        self._ended = bool(terminated[0] or truncated[0])
        return obs[0], float(rewards[0]), bool(terminated[0]), bool(truncated[0]), info


AGENTS = ("ship_0", "ship_1")


def parallel_env(rules=None, rounds=3, max_frames=20000, render_mode=None):
    """One match with both seats as agents, a PettingZoo ``ParallelEnv`` (``pip install -e
    '.[rl]'``): agents ``"ship_0"`` and ``"ship_1"``, the spaces, rewards and episode end of
    the Gymnasium environments; both agents leave when the match ends."""
    try:
        from pettingzoo import ParallelEnv
    except ImportError as error:  # pragma: no cover - the extra is missing
        raise ImportError("spacewar.envs.parallel_env needs PettingZoo: pip install -e '.[rl]'") \
            from error

    class SpacewarParallelEnv(ParallelEnv):
        metadata = {"name": "spacewar_v0", "render_modes": []}

        def __init__(self):
            self._vector = SpacewarVectorEnv(2, opponent=None, rules=rules, rounds=rounds,
                                             max_frames=max_frames, render_mode=render_mode)
            self.render_mode = None
            self.possible_agents = list(AGENTS)
            self.agents = []
            self._spaces = (self._vector.single_observation_space,
                            self._vector.single_action_space)

        def observation_space(self, agent):
            return self._spaces[0]

        def action_space(self, agent):
            return self._spaces[1]

        def reset(self, seed=None, options=None):
            obs, _ = self._vector.reset(seed=seed, options=options)
            self.agents = list(AGENTS)
            return {a: obs[k] for k, a in enumerate(AGENTS)}, {a: {} for a in AGENTS}

        def step(self, actions):
            if not self.agents:
                raise RuntimeError("the match has ended: call reset()")
            missing = [a for a in AGENTS if a not in actions]
            if missing:
                raise ValueError(f"actions must hold one action per agent, missing {missing}")
            parts = np.array([actions[a] for a in AGENTS], dtype=np.int64)
            obs, rewards, terminated, truncated, _ = self._vector.step(parts)
            out = ({a: obs[k] for k, a in enumerate(AGENTS)},
                   {a: float(rewards[k]) for k, a in enumerate(AGENTS)},
                   {a: bool(terminated[k]) for k, a in enumerate(AGENTS)},
                   {a: bool(truncated[k]) for k, a in enumerate(AGENTS)},
                   {a: {} for a in AGENTS})
            if terminated[0] or truncated[0]:
                self.agents = []
            return out

        def close(self):
            pass

    return SpacewarParallelEnv()


gymnasium.register("Spacewar-v0", entry_point=SpacewarEnv, vector_entry_point=SpacewarVectorEnv)

__all__ = ["SpacewarEnv", "SpacewarVectorEnv", "parallel_env", "AGENTS", "action_space",
           "observation_space", "codes_from_parts", "learning_length"]
