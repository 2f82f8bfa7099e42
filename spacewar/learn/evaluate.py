"""How well a trained policy plays: ``evaluate`` runs it against an opponent of the Gymnasium
vector env (``spacewar.learn.envs``), many matches at once. Needs Gymnasium (the ``[rl]`` extra),
not JAX."""
import numpy as np

from spacewar.bots.policy import Policy


def evaluate(policy, opponent="random", matches=50, seed=0, rounds=3, max_frames=20000,
             greedy=True):
    """Play ``matches`` matches of ``rounds`` rounds against an opponent of the vector env
    (``spacewar.learn.envs.OPPONENTS``), all at once, the policy in seat 0 deciding every
    ``frame_skip`` frames as its bot does; return ``{"wins", "losses", "draws", "matches",
    "win_rate"}`` (a win: the match's score difference is > 0; a truncated match counts by
    its score so far). Needs Gymnasium (the ``[rl]`` extra), not JAX."""
    from spacewar.learn.envs import SpacewarVectorEnv

    policy = policy if isinstance(policy, Policy) else Policy.load(policy)
    env = SpacewarVectorEnv(matches, opponent=opponent, rules=policy.rules, rounds=rounds,
                            max_frames=max_frames)
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng([seed, 2])
    score = np.zeros(matches)
    over = np.zeros(matches, dtype=bool)
    parts = None
    frame = 0
    while not over.all():
        if frame % policy.frame_skip == 0:
            codes = policy.act_batch(obs, greedy=greedy, rng=rng)
            parts = np.stack([codes % 3, (codes // 3) % 2, (codes // 6) % 2, (codes // 12) % 2], 1)
        obs, reward, terminated, truncated, _ = env.step(parts)
        score += np.where(over, 0.0, reward)
        over |= terminated | truncated
        frame += 1
    wins, losses = int(np.sum(score > 0)), int(np.sum(score < 0))
    return {"wins": wins, "losses": losses, "draws": matches - wins - losses, "matches": matches,
            "win_rate": wins / matches}


__all__ = ["evaluate"]
