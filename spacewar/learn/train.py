"""Train a Spacewar! policy with PPO on the compiled vector env, and save it as ``.npz``.

    spacewar train --opponent random --minutes 5 --out policy.npz      # needs the [rl] extra
    spacewar match --p1 policy.npz --p2 chaser

    from spacewar.learn.train import TrainConfig, train
    result = train(TrainConfig(opponent="random", minutes=2, seed=1), "policy.npz")

The algorithm is Proximal Policy Optimization (Schulman, Wolski, Dhariwal, Radford & Klimov
2017, "Proximal Policy Optimization Algorithms", arXiv:1707.06347) with Generalized Advantage
Estimation (Schulman, Moritz, Levine, Jordan & Abbeel 2016, "High-Dimensional Continuous
Control Using Generalized Advantage Estimation", arXiv:1506.02438), written here in JAX and
optax (``pip install -e '.[rl]'``); the saved policy runs in NumPy alone (``spacewar.policy``).

- **Environment**: ``spacewar.learn.envs.SpacewarVectorEnv`` (``num_envs`` matches in one compiled
  call; next-step autoreset). An episode is a match of ``rounds`` rounds (default 1: a round is
  the unit of reward, and short episodes give the win rate sooner).
- **Frame skip**: the policy decides every ``frame_skip`` frames and holds its action in
  between (the saved policy's bot does the same), which shortens the credit-assignment horizon
  by that factor. A decision's reward is the sum over its frames of the episode it started in.
- **Policy**: an MLP (``hidden`` widths, tanh) from the learning observation (less the two
  entries scaled by the number of rounds, see ``spacewar.policy``) to 9 logits, four
  independent categorical factors (turn 3, thrust 2, fire 2, hyperspace 2), so
  ``log pi(a|s) = sum_f log softmax(z_f)[a_f]`` and the entropy is the sum of the factors'.
  A separate MLP of the same widths estimates the value V(s).
- **Advantages** (GAE, eq. 16 of Schulman et al. 2016):
  ``delta_t = r_t + gamma V(s_{t+1}) (1 - d_t) - V(s_t)``,
  ``A_t = delta_t + gamma lambda (1 - d_t) A_{t+1}``; returns ``R_t = A_t + V(s_t)``.
  A truncated episode (``max_frames``) is not a terminal state: its last reward gets
  ``+ gamma V(s_final)`` from the final observation. The transition that starts from a final
  observation (its first frame is the env's reset, which ignores the action) is left out of
  the loss.
- **Loss** (eq. 9 of Schulman et al. 2017), minimised with Adam and a clipped gradient norm:
  ``L = -E[min(rho A, clip(rho, 1 - eps, 1 + eps) A)] + c_v E[(V(s) - R)^2] / 2 - c_e E[H]``
  with ``rho = pi(a|s) / pi_old(a|s)`` and advantages normalised per minibatch, over
  ``epochs`` passes of ``minibatches`` shuffled minibatches of each rollout.

Deterministic for a seed: the network's initialisation, the sampled actions and the shuffles
come from JAX PRNG keys split from ``seed``, the env (and its random opponent) from the same
seed. A run stopped by ``steps`` is reproducible; one stopped by ``minutes`` is the same run cut
wherever the clock stopped it.
"""
import collections
import dataclasses
import json
import math
import os
import time

import numpy as np

try:
    import jax
    import jax.numpy as jnp
    import optax
except ImportError as error:  # pragma: no cover - the extra is missing
    raise ImportError("spacewar.learn.train needs JAX and optax: pip install -e '.[rl]'") from error

from spacewar.game.features import learning_layout, learning_length
from spacewar.bots.policy import (ACTION_FORMAT, ACTIVATIONS, FORMAT_VERSION, NVEC, Policy,
                          check_policy_path, default_inputs, layout_sha256, save_policy)
from spacewar.rules import Rules

_SLICES = tuple((int(a), int(b)) for a, b in zip(np.cumsum((0,) + NVEC)[:-1], np.cumsum(NVEC)))


@dataclasses.dataclass(frozen=True)
class TrainConfig:
    """Everything a training run depends on (``spacewar train --help`` shows the CLI's)."""

    opponent: str = "random"     # an env opponent, or several: "random,chaser" (envs split)
    minutes: float = 10.0        # wall-clock budget
    steps: int = None            # frame budget (env frames over all envs); None: the clock only
    seed: int = 0
    envs: int = 512              # matches played side by side
    rollout: int = 32            # decisions per env between updates
    frame_skip: int = 4          # frames each decision is held for
    rounds: int = 1              # rounds per training episode
    max_frames: int = 20000      # an episode is truncated after this many frames
    hidden: tuple = (128, 128)
    activation: str = "tanh"
    gamma: float = 0.99          # per decision (4 frames): a horizon of ~400 frames
    gae_lambda: float = 0.95
    clip: float = 0.2
    ent_coef: float = 0.005
    vf_coef: float = 0.5
    lr: float = 1e-3
    max_grad_norm: float = 0.5
    epochs: int = 4
    minibatches: int = 4
    window: int = 200            # finished episodes the shown win rate is taken over

    def __post_init__(self):
        def check(name, ok, why):
            if not ok:
                raise ValueError(f"{name} must be {why}, got {getattr(self, name)!r}")

        def is_int(v):
            return isinstance(v, (int, np.integer)) and not isinstance(v, bool)

        check("minutes", isinstance(self.minutes, (int, float)) and math.isfinite(self.minutes)
              and self.minutes > 0, "a number of minutes > 0")
        check("steps", self.steps is None or (is_int(self.steps) and self.steps > 0),
              "None or an int > 0")
        check("seed", is_int(self.seed) and 0 <= self.seed < 2**63, "an int in [0, 2**63)")
        for name, high in (("envs", 1 << 16), ("rollout", 1 << 14), ("frame_skip", 64),
                           ("rounds", 100), ("epochs", 100), ("window", 1 << 20)):
            check(name, is_int(getattr(self, name)) and 1 <= getattr(self, name) <= high,
                  f"an int in [1, {high}]")
        check("minibatches", is_int(self.minibatches) and 1 <= self.minibatches
              and (self.envs * self.rollout) % self.minibatches == 0,
              "an int >= 1 dividing envs * rollout")
        check("max_frames", is_int(self.max_frames) and self.max_frames >= 0, "an int >= 0")
        check("hidden", isinstance(self.hidden, tuple) and len(self.hidden) >= 1
              and all(is_int(h) and 1 <= h <= 4096 for h in self.hidden),
              "a non-empty tuple of widths in [1, 4096]")
        check("activation", self.activation in ACTIVATIONS, f"one of {ACTIVATIONS}")
        for name in ("gamma", "gae_lambda"):
            check(name, 0.0 <= getattr(self, name) <= 1.0, "in [0, 1]")
        for name in ("clip", "ent_coef", "vf_coef", "lr", "max_grad_norm"):
            v = getattr(self, name)
            check(name, isinstance(v, (int, float)) and math.isfinite(v) and v >= 0, ">= 0")


# -- the networks ---------------------------------------------------------------------------
def init_mlp(key, sizes, last_gain):
    """Weights of an MLP ``sizes[0] -> ... -> sizes[-1]``: orthogonal matrices (gain sqrt 2 for
    the hidden layers, ``last_gain`` for the output), zero biases. A small output gain (0.01
    for the policy) starts every factor near uniform, so early exploration is broad."""
    layers = []
    keys = jax.random.split(key, len(sizes) - 1)
    for i, (k, a, b) in enumerate(zip(keys, sizes[:-1], sizes[1:])):
        gain = last_gain if i == len(sizes) - 2 else math.sqrt(2.0)
        w = jax.nn.initializers.orthogonal(gain)(k, (a, b), jnp.float32)
        layers.append((w, jnp.zeros((b,), jnp.float32)))
    return layers


def mlp(layers, x, activation="tanh"):
    """``h_{i+1} = act(h_i W_i + b_i)``, the last layer linear (as ``spacewar.policy``)."""
    act = jnp.tanh if activation == "tanh" else jax.nn.relu
    for i, (w, b) in enumerate(layers):
        x = x @ w + b
        if i < len(layers) - 1:
            x = act(x)
    return x


def init_params(key, n_inputs, config):
    k_pi, k_v = jax.random.split(key)
    return {"pi": init_mlp(k_pi, (n_inputs,) + config.hidden + (sum(NVEC),), 0.01),
            "v": init_mlp(k_v, (n_inputs,) + config.hidden + (1,), 1.0)}


def log_prob(logits, parts):
    """``log pi(a|s)``: the sum over the four factors of their log-softmax at the choice."""
    total = 0.0
    for f, (a, b) in enumerate(_SLICES):
        lp = jax.nn.log_softmax(logits[:, a:b])
        total = total + jnp.take_along_axis(lp, parts[:, f:f + 1], axis=1)[:, 0]
    return total


def entropy(logits):
    """The policy's entropy: the sum of the independent factors' entropies."""
    total = 0.0
    for a, b in _SLICES:
        lp = jax.nn.log_softmax(logits[:, a:b])
        total = total - jnp.sum(jnp.exp(lp) * lp, axis=1)
    return total


def _make_functions(config, optimizer):
    """The jitted rollout step, value and update of a run (closed over its config)."""
    act = config.activation

    @jax.jit
    def policy_step(params, x, key):
        logits = mlp(params["pi"], x, act)
        keys = jax.random.split(key, len(NVEC))
        parts = jnp.stack([jax.random.categorical(keys[f], logits[:, a:b])
                           for f, (a, b) in enumerate(_SLICES)], axis=1)
        value = mlp(params["v"], x, act)[:, 0]
        return parts, log_prob(logits, parts), value

    @jax.jit
    def value(params, x):
        return mlp(params["v"], x, act)[:, 0]

    def loss(params, mb):
        w = mb["valid"]
        n = jnp.maximum(jnp.sum(w), 1.0)

        def mean(v):
            return jnp.sum(w * v) / n

        logits = mlp(params["pi"], mb["x"], act)
        logp = log_prob(logits, mb["parts"])
        ratio = jnp.exp(logp - mb["logp"])
        adv = mb["adv"]
        mu = mean(adv)
        adv = (adv - mu) / (jnp.sqrt(mean((adv - mu) ** 2)) + 1e-8)
        clipped = jnp.clip(ratio, 1.0 - config.clip, 1.0 + config.clip)
        pg = -mean(jnp.minimum(ratio * adv, clipped * adv))
        v = mlp(params["v"], mb["x"], act)[:, 0]
        vloss = 0.5 * mean((v - mb["ret"]) ** 2)
        ent = mean(entropy(logits))
        total = pg + config.vf_coef * vloss - config.ent_coef * ent
        # k3 estimator of KL(old || new) (Schulman 2020, "Approximating KL divergence")
        kl = mean((ratio - 1.0) - (logp - mb["logp"]))
        frac = mean((jnp.abs(ratio - 1.0) > config.clip).astype(jnp.float32))
        return total, {"policy_loss": pg, "value_loss": vloss, "entropy": ent, "kl": kl,
                       "clip_fraction": frac}

    @jax.jit
    def update(params, opt_state, batch, key):
        size = batch["x"].shape[0]
        m = config.minibatches

        def minibatch(carry, mb):
            params, opt_state = carry
            grads, aux = jax.grad(loss, has_aux=True)(params, mb)
            updates, opt_state = optimizer.update(grads, opt_state, params)
            return (optax.apply_updates(params, updates), opt_state), aux

        def epoch(carry, k):
            perm = jax.random.permutation(k, size)
            shuffled = jax.tree_util.tree_map(
                lambda a: a[perm].reshape((m, size // m) + a.shape[1:]), batch)
            return jax.lax.scan(minibatch, carry, shuffled)

        (params, opt_state), aux = jax.lax.scan(epoch, (params, opt_state),
                                                jax.random.split(key, config.epochs))
        return params, opt_state, jax.tree_util.tree_map(jnp.mean, aux)

    return policy_step, value, update


def gae(rewards, values, dones, last_value, gamma, lam):
    """Advantages and returns of a rollout (T, N) by GAE (eq. 16 of Schulman et al. 2016):
    ``delta_t = r_t + gamma V_{t+1} (1 - d_t) - V_t``, ``A_t = delta_t + gamma lam (1 - d_t)
    A_{t+1}``, ``R_t = A_t + V_t``; ``last_value`` is V of the observation after the rollout."""
    t_len = rewards.shape[0]
    adv = np.zeros_like(rewards)
    running = np.zeros_like(last_value)
    next_value = last_value
    for t in range(t_len - 1, -1, -1):
        keep = 1.0 - dones[t]
        delta = rewards[t] + gamma * next_value * keep - values[t]
        running = delta + gamma * lam * keep * running
        adv[t] = running
        next_value = values[t]
    return adv, adv + values


def _macro_step(env, parts, frame_skip):
    """Hold ``parts`` for ``frame_skip`` frames of every match.

    Returns ``(obs, reward, done, terminated, final_obs, ended_last)``: the observation after
    the frames; each match's reward summed over the frames of the episode that was current at
    the start; whether that episode ended (and whether by termination) and its final
    observation; ``ended_last``: it ended at the very last frame, so ``obs`` is that final
    observation and the next call's first frame resets the match. Rewards of a new episode's
    first frames within the same call are dropped (a round cannot be won that fast)."""
    n = parts.shape[0]
    reward = np.zeros(n)
    done = np.zeros(n, dtype=bool)
    term = np.zeros(n, dtype=bool)
    final = None
    ended = done
    for _ in range(frame_skip):
        obs, r, te, tr, _ = env.step(parts)
        live = ~done
        reward += np.where(live, r, 0.0)
        ended = live & (te | tr)
        if ended.any():
            if final is None:
                final = obs.copy()
            else:
                final[ended] = obs[ended]
            term |= ended & te
            done |= ended
    return obs, reward, done, term, final, ended


class _Mixed:
    """Several vector envs, one per opponent, stepped as one: the agents of the first, then
    the second's, ... (``opponent="random,chaser"`` trains against both at once)."""

    def __init__(self, envs):
        self.envs = envs
        self.cuts = np.cumsum([0] + [e.num_envs for e in envs])

    def reset(self, seed):
        # each env its own seed (seed, k) so that their matches differ
        obs = [e.reset(seed=int(np.random.SeedSequence([seed, k]).generate_state(1)[0]))[0]
               for k, e in enumerate(self.envs)]
        return np.concatenate(obs), {}

    def step(self, parts):
        out = [e.step(parts[a:b]) for e, a, b in zip(self.envs, self.cuts[:-1], self.cuts[1:])]
        return tuple(np.concatenate([o[i] for o in out]) for i in range(4)) + ({},)


def _make_env(config, rules):
    from spacewar.learn.envs import SpacewarVectorEnv

    names = [o.strip() for o in config.opponent.split(",")] if "," in config.opponent \
        else [config.opponent]
    if len(names) == 1:
        env = SpacewarVectorEnv(config.envs, opponent=names[0], rules=rules,
                                rounds=config.rounds, max_frames=config.max_frames)
        return env, lambda seed: env.reset(seed=seed)
    if config.envs < len(names):
        raise ValueError(f"envs ({config.envs}) must be at least the number of opponents "
                         f"({len(names)})")
    sizes = [config.envs // len(names) + (k < config.envs % len(names)) for k in range(len(names))]
    mixed = _Mixed([SpacewarVectorEnv(n, opponent=name, rules=rules, rounds=config.rounds,
                                      max_frames=config.max_frames)
                    for n, name in zip(sizes, names)])
    return mixed, mixed.reset


def _metadata(config, rules, inputs, training):
    return {"observation_length": learning_length(rules), "rules": rules.to_dict(),
            "rounds": config.rounds, "layout_sha256": layout_sha256(learning_layout(rules)),
            "action_format": ACTION_FORMAT, "nvec": list(NVEC), "activation": config.activation,
            "layers": len(config.hidden) + 1, "frame_skip": config.frame_skip,
            "format_version": FORMAT_VERSION, "training": training}


def policy_arrays(params, inputs):
    """The policy's weights as the float32 arrays of a policy file."""
    arrays = {"inputs": np.asarray(inputs, dtype=np.int64)}
    for i, (w, b) in enumerate(params["pi"]):
        arrays[f"w{i}"] = np.asarray(w, dtype=np.float32)
        arrays[f"b{i}"] = np.asarray(b, dtype=np.float32)
    return arrays


def _save(path, config, rules, inputs, params, training):
    return save_policy(path, policy_arrays(params, inputs),
                       _metadata(config, rules, inputs, training))


def initial_params(config, rules=None):
    """The network a run of ``config`` starts from (before any update)."""
    rules = Rules() if rules is None else rules
    key = jax.random.split(jax.random.PRNGKey(config.seed))[1]  # as ``train`` splits it
    return init_params(key, default_inputs(rules).size, config)


def save_params(path, params, config, rules=None, training=None):
    """Save ``params`` (``initial_params``, or ``train``'s result["params"]) as a policy file."""
    rules = Rules() if rules is None else rules
    return _save(check_policy_path(path), config, rules, default_inputs(rules), params,
                 training or {})


def train(config, out, rules=None, progress=True, log=None, checkpoints=(), on_update=None):
    """Train a policy with PPO (see the module's text) and save it to ``out``; return a dict
    with the run's figures (frames, updates, episodes, elapsed seconds, the recent win rate,
    the per-update ``history``).

    ``out`` is checked writable before anything else. ``log``: a path to write one JSON line
    per update. ``checkpoints``: minutes at which to save the policy so far to
    ``<out without .npz>.<minutes>min.npz`` too. ``on_update(summary)`` is called after each
    update (a dict; return True to stop)."""
    if not isinstance(config, TrainConfig):
        raise TypeError(f"config must be a TrainConfig, got {type(config).__name__}")
    check_policy_path(out)
    stem = out[:-4] if out.endswith(".npz") else out
    checkpoint_paths = [(float(m), f"{stem}.{m:g}min.npz") for m in sorted(checkpoints)]
    for _, path in checkpoint_paths:
        check_policy_path(path)
    log_file = None
    if log is not None:
        from engine.atomic import check_output_path

        check_output_path(log)
        log_file = open(log, "w", encoding="utf-8")
    rules = Rules() if rules is None else rules
    if rules.mode == "electric":
        raise ValueError("the trainer's policies have the four action factors of the classic and "
                         "newtonian modes; the electric mode's flip is not supported yet")
    env, reset = _make_env(config, rules)
    inputs = default_inputs(rules)
    n, t_len, k = config.envs, config.rollout, config.frame_skip
    optimizer = optax.chain(optax.clip_by_global_norm(config.max_grad_norm),
                            optax.adam(config.lr, eps=1e-5))
    policy_step, value_fn, update = _make_functions(config, optimizer)
    key = jax.random.PRNGKey(config.seed)
    key, init_key = jax.random.split(key)
    params = init_params(init_key, inputs.size, config)
    opt_state = optimizer.init(params)

    buf_x = np.zeros((t_len, n, inputs.size), dtype=np.float32)
    buf_parts = np.zeros((t_len, n, len(NVEC)), dtype=np.int32)
    buf_logp = np.zeros((t_len, n), dtype=np.float32)
    buf_value = np.zeros((t_len, n), dtype=np.float32)
    buf_reward = np.zeros((t_len, n), dtype=np.float32)
    buf_done = np.zeros((t_len, n), dtype=np.float32)
    buf_valid = np.zeros((t_len, n), dtype=np.float32)

    obs, _ = reset(config.seed)
    x = np.ascontiguousarray(obs[:, inputs])
    junk = np.zeros(n, dtype=bool)  # the next transition starts from a final observation
    episode_return = np.zeros(n)
    recent = collections.deque(maxlen=config.window)
    episodes = wins = 0
    frames = updates = 0
    history = []
    budget = config.minutes * 60.0
    start = time.perf_counter()
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=config.steps if config.steps else int(budget),
                   unit=" frames" if config.steps else "s", unit_scale=bool(config.steps),
                   desc=f"PPO vs {config.opponent}", dynamic_ncols=True)
    shown = 0
    training = {}
    try:
        while True:
            for t in range(t_len):
                key, step_key = jax.random.split(key)
                parts, logp, val = policy_step(params, x, step_key)
                parts = np.asarray(parts)
                buf_x[t] = x
                buf_parts[t] = parts
                buf_logp[t] = np.asarray(logp)
                buf_value[t] = np.asarray(val)
                buf_valid[t] = ~junk
                obs, reward, done, term, final, ended_last = _macro_step(env, parts, k)
                frames += n * k
                episode_return += reward
                truncated = done & ~term
                if truncated.any():  # not a terminal state: bootstrap from the final observation
                    v_final = np.asarray(value_fn(params, np.ascontiguousarray(final[:, inputs])))
                    reward = reward + np.where(truncated, config.gamma * v_final, 0.0)
                buf_reward[t] = reward
                buf_done[t] = done
                for i in np.flatnonzero(done):  # a win: the episode's score difference is > 0
                    won = episode_return[i] > 0.5
                    recent.append(1.0 if won else 0.0)
                    episodes += 1
                    wins += int(won)
                episode_return[done] = 0.0
                junk = ended_last
                x = np.ascontiguousarray(obs[:, inputs])
            last_value = np.asarray(value_fn(params, x))
            adv, ret = gae(buf_reward, buf_value, buf_done, last_value, config.gamma,
                           config.gae_lambda)
            batch = {"x": buf_x.reshape(t_len * n, -1), "parts": buf_parts.reshape(t_len * n, -1),
                     "logp": buf_logp.ravel(), "adv": adv.ravel().astype(np.float32),
                     "ret": ret.ravel().astype(np.float32), "valid": buf_valid.ravel()}
            key, update_key = jax.random.split(key)
            params, opt_state, aux = update(params, opt_state, batch, update_key)
            updates += 1
            elapsed = time.perf_counter() - start
            win_rate = float(np.mean(recent)) if recent else float("nan")
            summary = {"update": updates, "frames": frames, "seconds": round(elapsed, 3),
                       "episodes": episodes, "win_rate": win_rate,
                       **{name: float(v) for name, v in aux.items()}}
            history.append(summary)
            if log_file is not None:
                log_file.write(json.dumps(summary) + "\n")
                log_file.flush()
            training = {"opponent": config.opponent, "seed": config.seed, "frames": frames,
                        "updates": updates, "seconds": round(elapsed, 1), "episodes": episodes,
                        "recent_win_rate": win_rate,
                        "config": {f.name: getattr(config, f.name)
                                   for f in dataclasses.fields(config)},
                        "library": f"jax {jax.__version__}, optax {optax.__version__}"}
            while checkpoint_paths and elapsed >= checkpoint_paths[0][0] * 60.0:
                _save(checkpoint_paths.pop(0)[1], config, rules, inputs, params, training)
            if bar is not None:
                now = frames if config.steps else int(min(elapsed, budget))
                bar.update(now - shown)
                shown = now
                bar.set_postfix_str(f"win {win_rate:.0%} of last {len(recent)}, "
                                    f"{episodes} episodes, {frames / elapsed:,.0f} frames/s")
            stop = on_update(summary) if on_update is not None else False
            if stop or elapsed >= budget or (config.steps and frames >= config.steps):
                break
    finally:
        if bar is not None:
            bar.close()
        if log_file is not None:
            log_file.close()
    _save(out, config, rules, inputs, params, training)
    for _, path in checkpoint_paths:  # the run ended before these: they get the final policy
        _save(path, config, rules, inputs, params, training)
    return {**training, "wins": wins, "history": history, "out": out, "params": params}


def jax_logits(params, x, activation="tanh"):
    """The JAX forward pass of the policy on selected inputs (for checking NumPy inference)."""
    return np.asarray(mlp(params["pi"], jnp.asarray(x), activation))


__all__ = ["TrainConfig", "train", "gae", "init_params", "initial_params", "save_params", "mlp", "log_prob", "entropy",
           "policy_arrays", "jax_logits", "Policy"]
