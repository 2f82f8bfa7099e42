"""Gymnasium environments on the compiled learning batch (``pip install -e '.[rl]'``).

    import gymnasium, spacewar.envs                   # importing registers "Spacewar-v0"
    env = gymnasium.make("Spacewar-v0", opponent="chaser")
    envs = gymnasium.make_vec("Spacewar-v0", num_envs=4096, opponent="chaser")   # native

``SpacewarVectorEnv`` is native (as Gymnasium's ``CartPoleVectorEnv`` is): every match is
stepped, observed, rewarded and restarted, and a compiled opponent decides, inside one
compiled call of ``spacewar.learn.batch``. ``SpacewarEnv`` is one match of it.

Description
    Spacewar! (1962): two ships, a star, torpedoes and hyperspace on a torus; a learner flies
    seat 0 against an opponent in seat 1 (or, in the vector env with ``opponent=None``, both
    seats learn: the agent axis is then 2 * matches, match m's seats at 2m and 2m + 1).
Action space
    ``MultiDiscrete([3, 2, 2, 2])`` (``action_type="multi_discrete"``, the default): turn (0
    right, 1 none, 2 left, i.e. ``spacewar.Action.turn + 1``), thrust, fire, hyperspace;
    in the electric mode a fifth entry, the polarity flip, ``MultiDiscrete([3, 2, 2, 2, 2])``.
    ``action_type="discrete"``: ``Discrete(24)`` (48 in the electric mode), the game's own
    action code ``turn + 3 thrust + 6 fire + 12 hyperspace + 24 flip``.
Observation space
    ``Box`` of float32, shape (D,): ``spacewar.game.features.learning_layout(rules)`` names the
    entries (egocentric, scaled to about [-1, 1]; see docs/game.md). Relative positions, headings,
    fractions and flags have their exact bounds; velocities are unbounded (thrust has no limit).
Rewards
    +1 when a frame scores a round for the learner's seat and not for the enemy, -1 the other
    way, 0 otherwise: an episode's rewards add up to the final score difference.
Episode end
    ``terminated`` when the match is over (``rounds`` rounds, plus tie-breaks); ``truncated``
    at ``max_frames`` frames (default 20000).
Autoreset (vector env)
    ``autoreset_mode``: ``"next_step"`` (default), ``"same_step"`` (the ended episode's last
    observation in ``info["final_obs"]``, an object array with the mask ``info["_final_obs"]``,
    and ``info["final_info"]``) or ``"disabled"`` (``reset(options={"reset_mask": mask})``
    restarts the ended ones); ``metadata["autoreset_mode"]`` says which.
Opponents
    A compiled bot's name (``spacewar.game.compiled_bots.KINDS``: they decide inside the compiled
    call), a policy (an object with ``act_batch(obs (K, D) float32) -> (K,) action codes``, or
    the path of a policy saved as ``.npz``: all matches in one call, on seat 1's
    observations), or a Python bot (an object with ``act(Observation) -> Action``: the
    single-match env only, since a bot keeps state per match), or None (self-play, vector env).
Seeding
    ``reset(seed=s)``: match m's episode e plays a stream made from (s, m, e) alone, so runs
    are reproducible whatever the number of envs or threads.
Copies
    The vector env returns fresh arrays (``copy=True``); ``copy=False`` returns views of the
    batch's own buffers, overwritten by the next step, as Gymnasium's ``SyncVectorEnv``.
Rendering
    ``SpacewarEnv(render_mode="rgb_array")``: ``render()`` gives a (480, 480, 3) uint8 frame
    drawn by ``spacewar.render``; ``"human"``: the pygame window (``[viz]`` extra).
Version history
    v0: first version.
"""
import os

import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
    from gymnasium.vector import AutoresetMode, VectorEnv
    from gymnasium.vector.utils import batch_space
except ImportError as error:  # pragma: no cover - the extra is missing
    raise ImportError("spacewar.learn.envs needs Gymnasium: pip install -e '.[rl]'") from error

from spacewar.game import core
from spacewar.codes import codes_from_parts
from spacewar.learn.batch import (LearningBatch, copy_rows, learning_layout, learning_length,
                                  seat_kinds)
from spacewar.game import compiled_bots
from spacewar.bots.batch import checked_codes
from spacewar.protocol import action_code
from spacewar.rules import Rules, count_at_least

ACTION_TYPES = ("multi_discrete", "discrete")
NVEC = (3, 2, 2, 2)
_NOOP_PARTS = (1, 0, 0, 0)
_AUTORESET = {"next_step": AutoresetMode.NEXT_STEP, "same_step": AutoresetMode.SAME_STEP,
              "disabled": AutoresetMode.DISABLED}


def electric(rules):
    return rules.mode == "electric"


def action_space(rules=None, action_type="multi_discrete"):
    """The action space under these rules: MultiDiscrete parts, or the flat Discrete code."""
    rules = Rules() if rules is None else rules
    flip = electric(rules)
    if _check("action_type", action_type, ACTION_TYPES) == "discrete":
        return spaces.Discrete(48 if flip else 24)
    return spaces.MultiDiscrete(np.array(NVEC + ((2,) if flip else ()), dtype=np.int64))


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


def _check(name, value, allowed):
    if not isinstance(value, (str, type(None))) or value not in allowed:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, allowed))}, got {value!r}")
    return value


class _Opponent:
    """Seat 1's player as the vector env drives it: compiled (inside the batch), a batch
    policy (seat 1's observations in, codes out) or a Python bot (one match)."""

    def __init__(self, opponent, num_envs, rules):
        from spacewar.bots import is_policy_file

        self.compiled = None
        self.policy = None
        self.bot = None
        if opponent is None or isinstance(opponent, str) and opponent in compiled_bots.KINDS:
            self.compiled = opponent
        elif isinstance(opponent, (str, os.PathLike)) and is_policy_file(os.fspath(opponent)):
            from spacewar.bots.policy import PolicyBatch

            # seat 1's rows, each held frame_skip frames: as PolicyBot plays each match
            self.policy = PolicyBatch(os.fspath(opponent), rules, np.ones(num_envs, np.int64))
        elif hasattr(opponent, "act_batch"):
            self.policy = opponent
        elif hasattr(opponent, "act"):
            if num_envs != 1:
                raise ValueError("a Python bot keeps state per match: give it to SpacewarEnv "
                                 "(one match), or give the vector env a compiled bot's name or a "
                                 "policy with act_batch")
            self.bot = opponent
        else:
            raise ValueError(f"opponent must be None, one of {', '.join(sorted(compiled_bots.KINDS))}, "
                             f"a policy (.npz path or an object with act_batch) or a bot with act, "
                             f"got {opponent!r}")

    def codes(self, batch):
        """Seat 1's codes for the coming frame (None when the batch decides them)."""
        if self.policy is not None:
            answer = self.policy.act_batch(batch.observations[:, 1])
            try:
                return checked_codes(answer, batch.game.n_matches)
            except ValueError as exc:
                raise ValueError(f"the opponent policy's act_batch: {exc}") from None
        if self.bot is not None:
            return np.array([action_code(self.bot.act(batch.game.observe(0, 1)))])
        return None

    def episode_started(self, mask=None):
        """The matches of ``mask`` (all if None) start again."""
        if self.bot is not None and hasattr(self.bot, "reset"):
            self.bot.reset()
        restart = getattr(self.policy, "restart", None)
        if restart is not None:
            restart(np.ones(len(self.policy.seats), bool) if mask is None else mask)


class SpacewarVectorEnv(VectorEnv):
    """``num_envs`` agents over compiled matches (see the module's text)."""

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, num_envs=1, opponent="random", rules=None, rounds=3, max_frames=20000,
                 render_mode=None, autoreset_mode="next_step", action_type="multi_discrete",
                 copy=True):
        count_at_least("num_envs", num_envs, 1)
        if render_mode is not None:
            raise ValueError(f"render_mode must be None for the vector env (SpacewarEnv renders), "
                             f"got {render_mode!r}")
        if isinstance(autoreset_mode, AutoresetMode):
            autoreset_mode = autoreset_mode.value
        self.autoreset = _check("autoreset_mode", autoreset_mode, tuple(_AUTORESET))
        self.metadata = {**type(self).metadata, "autoreset_mode": _AUTORESET[self.autoreset]}
        self.render_mode = None
        self.rules = Rules() if rules is None else rules
        self.rounds = count_at_least("rounds", rounds, 1)
        self.max_frames = count_at_least("max_frames", max_frames, 0)
        self.self_play = opponent is None
        if self.self_play and num_envs % 2:
            raise ValueError(f"self-play (opponent=None) needs an even num_envs (two seats a "
                             f"match), got {num_envs}")
        self._opponent = _Opponent(opponent, num_envs, self.rules)
        self.opponent = opponent
        self.matches = int(num_envs) // 2 if self.self_play else int(num_envs)
        self.num_envs = int(num_envs)
        self.action_type = _check("action_type", action_type, ACTION_TYPES)
        self.single_action_space = action_space(self.rules, action_type)
        self.single_observation_space = observation_space(self.rules)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self._batch = None
        # as Gymnasium's SyncVectorEnv(copy=...): False returns views of the batch's own
        # buffers, which the next step overwrites (no copy of 4096 x 107 floats per step)
        self.copy = bool(copy)

    def _new_batch(self, seed):
        seed = int(np.random.SeedSequence(seed).entropy if seed is None else seed)
        self._batch = LearningBatch(self.matches, self.rules, seed=seed, rounds=self.rounds,
                                    frame_cap=self.max_frames, autoreset=self.autoreset,
                                    opponents=(None, self._opponent.compiled))

    def _view(self, array):
        """(M, 2, ...) per seat as the agent axis: seat 0 of each match, or both seats."""
        if self.self_play:
            return array.reshape((2 * self.matches,) + array.shape[2:])
        return array[:, 0]

    def _per_agent(self, flags):
        return np.repeat(flags, 2) if self.self_play else flags.copy()

    def reset(self, *, seed=None, options=None):
        mask = None if options is None else options.get("reset_mask")
        if mask is not None:
            if seed is not None:
                raise ValueError("reset with a reset_mask keeps the batch's seed: give seed "
                                 "without reset_mask")
            if self._batch is None:
                raise RuntimeError("call reset() without a reset_mask first")
            mask = self._match_mask(mask)
            self._batch.reset(mask)
            self._opponent.episode_started(mask)
        else:
            if seed is not None or self._batch is None:
                self._new_batch(seed)
            self._batch.reset()
            self._opponent.episode_started()
        return self._out(self._view(self._batch.observations)), {}

    def _out(self, array):
        if not self.copy:
            return array
        out = np.empty(array.shape, dtype=array.dtype)
        copy_rows(array, out)
        return out

    def _match_mask(self, mask):
        mask = np.asarray(mask)
        if mask.shape != (self.num_envs,) or mask.dtype != np.bool_:
            raise ValueError(f"reset_mask must be a bool array of shape ({self.num_envs},), got "
                             f"{mask.dtype} {mask.shape}")
        if self.self_play:
            pairs = mask.reshape(self.matches, 2)
            if (pairs[:, 0] != pairs[:, 1]).any():
                raise ValueError("reset_mask must treat a match's two seats alike (agents 2m "
                                 "and 2m + 1 are one match)")
            return pairs[:, 0].copy()
        return mask.copy()

    def step(self, actions):
        batch = self._batch
        if batch is None:
            raise RuntimeError("call reset() before step()")
        actions = np.asarray(actions)
        if not self.action_space.contains(actions.astype(np.int64, copy=False)
                                          if actions.dtype.kind in "iu" else actions):
            raise ValueError(f"actions must be {self.num_envs} actions of "
                             f"{self.single_action_space}, got {actions.tolist()!r:.200}")
        codes = actions.astype(np.int64) if self.action_type == "discrete" \
            else codes_from_parts(actions)
        full = np.empty((self.matches, 2), dtype=np.int64)
        if self.self_play:
            full[:] = codes.reshape(self.matches, 2)
        else:
            full[:, 0] = codes
            opponent = self._opponent.codes(batch)
            full[:, 1] = core.NOOP if opponent is None else opponent
        episodes = batch.episodes.copy()
        obs, rewards, terminated, truncated = batch.step(full)
        infos = {}
        if self.autoreset == "same_step" and batch.ended.any():
            infos = self._final_infos(batch)
        restarted = batch.episodes != episodes
        if restarted.any():
            self._opponent.episode_started(restarted)
        return (self._out(self._view(obs)), self._view(rewards).astype(np.float64),
                self._per_agent(terminated), self._per_agent(truncated), infos)

    def _final_infos(self, batch):
        """Gymnasium's same-step infos: the ended agents' last observations (object array)."""
        ended = self._per_agent(batch.ended)
        final = np.full(self.num_envs, None, dtype=object)
        last = self._view(batch.final_observations)
        for k in np.flatnonzero(ended):
            final[k] = last[k].copy()
        return {"final_obs": final, "_final_obs": ended, "final_info": {},
                "_final_info": ended.copy()}

    @property
    def batch(self):
        """The ``spacewar.learn.batch.LearningBatch`` underneath (its ``game`` is the matches)."""
        return self._batch


class SpacewarEnv(gymnasium.Env):
    """One match against an opponent (see the module's text)."""

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 60}

    def __init__(self, opponent="random", rules=None, rounds=3, max_frames=20000,
                 render_mode=None, action_type="multi_discrete", size=480):
        if opponent is None:
            raise ValueError("SpacewarEnv needs an opponent (self-play: the vector env with "
                             "opponent=None, or spacewar.learn.envs.parallel_env())")
        if render_mode not in (None, "rgb_array", "human"):
            raise ValueError(f"render_mode must be None, 'rgb_array' or 'human', got "
                             f"{render_mode!r}")
        self._vector = SpacewarVectorEnv(1, opponent=opponent, rules=rules, rounds=rounds,
                                         max_frames=max_frames, action_type=action_type)
        self.render_mode = render_mode
        self.size = size
        self.action_space = self._vector.single_action_space
        self.observation_space = self._vector.single_observation_space
        self._ended = False
        self._screen = None
        self._effects = None

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        obs, info = self._vector.reset(seed=seed, options=options)
        self._ended = False
        self._start_drawing()
        return obs[0], info

    def step(self, action):
        if self._ended:
            raise RuntimeError("the episode has ended: call reset()")
        obs, rewards, terminated, truncated, info = self._vector.step(np.asarray(action)[None])
        self._ended = bool(terminated[0] or truncated[0])
        if self._effects is not None:
            self._effects.update(self.game.snapshot(0))
        if self.render_mode == "human":
            self.render()
        return obs[0], float(rewards[0]), bool(terminated[0]), bool(truncated[0]), info

    @property
    def game(self):
        """The ``spacewar.game.Game`` of this env's match."""
        return self._vector.batch.game

    def _start_drawing(self):
        self._effects = None
        if self.render_mode is not None:
            from spacewar.view.scene import Effects

            self._effects = Effects()
            self._effects.update(self.game.snapshot(0))
            if self.render_mode == "human":
                self.render()

    def render(self):
        """``rgb_array``: the frame as (size, size, 3) uint8; ``human``: draws the window."""
        if self.render_mode is None or self._vector.batch is None:
            return None
        from spacewar.view.paint_pil import render_frame
        from spacewar.view.scene import scene

        snapshot = self.game.snapshot(0)
        names = ("learner", _name(self._vector.opponent))
        if self.render_mode == "rgb_array":
            image = render_frame(snapshot, self.size, effects=self._effects, names=names,
                                 rounds=self._vector.rounds)
            return np.asarray(image.convert("RGB"))
        self._draw_window(scene(snapshot, self.size, effects=self._effects, names=names,
                                rounds=self._vector.rounds))
        return None

    def _draw_window(self, prims):
        from spacewar.view.window import paint, require_pygame

        pygame = require_pygame()
        if self._screen is None:
            pygame.init()
            self._screen = pygame.display.set_mode((self.size, self.size))
            pygame.display.set_caption("Spacewar-v0")
            self._clock = pygame.time.Clock()
            self._fonts = {}
        pygame.event.pump()
        paint(pygame, self._screen, prims, self._fonts)
        pygame.display.flip()
        self._clock.tick(self.metadata["render_fps"])

    def close(self):
        if self._screen is not None:
            from spacewar.view.window import require_pygame

            require_pygame().display.quit()
            self._screen = None


def _name(opponent):
    if isinstance(opponent, str):
        return os.path.basename(opponent)
    return type(opponent).__name__


AGENTS = ("ship_0", "ship_1")


def parallel_env(rules=None, rounds=3, max_frames=20000, render_mode=None,
                 action_type="multi_discrete"):
    """One match with both seats as agents, a PettingZoo ``ParallelEnv`` (``pip install -e
    '.[rl]'``): agents ``"ship_0"`` and ``"ship_1"``, the spaces, rewards and episode end of
    the Gymnasium environments; both agents leave when the match ends."""
    try:
        from pettingzoo import ParallelEnv
    except ImportError as error:  # pragma: no cover - the extra is missing
        raise ImportError("spacewar.learn.envs.parallel_env needs PettingZoo: pip install -e '.[rl]'") \
            from error

    class SpacewarParallelEnv(ParallelEnv):
        metadata = {"name": "spacewar_v0", "render_modes": []}

        def __init__(self):
            self._vector = SpacewarVectorEnv(2, opponent=None, rules=rules, rounds=rounds,
                                             max_frames=max_frames, render_mode=render_mode,
                                             action_type=action_type)
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
            parts = np.array([actions[a] for a in AGENTS])
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


#: the compiled opponents' names, and None for self-play
OPPONENTS = tuple(sorted(compiled_bots.KINDS)) + (None,)

gymnasium.register("Spacewar-v0", entry_point=SpacewarEnv, vector_entry_point=SpacewarVectorEnv)

__all__ = ["SpacewarEnv", "SpacewarVectorEnv", "parallel_env", "AGENTS", "action_space",
           "observation_space", "codes_from_parts", "learning_length", "ACTION_TYPES",
           "OPPONENTS"]
