"""Section 8: Spacewar for learning code, ``spacewar.learn.batch.LearningBatch`` and
``spacewar.learn.envs.SpacewarVectorEnv`` stepping 4096 matches with observations and rewards, at 1
thread and at every thread; and the harness's own cost per frame of a match of Python bots."""
import math
import time

import numpy as np

from .timing import each_thread_count

NAME = "learning"
KEYS = ("learning",)
NEEDS = ()


def run(quick):
    return {"learning": bench_learning(1024 if quick else 4096)}


def _vector_env_rate(opponent, matches, frames, repeats, seed=1, copy=True):
    """Agent-steps per second of ``SpacewarVectorEnv(matches, ...).step`` with random actions
    (the env's own checks, the conversion of actions, observations, rewards and flags
    included; match-frames per second but in self-play, ``opponent=None``, where ``matches``
    agents are ``matches / 2`` matches) and the final observations, so that runs at different
    thread counts can be compared."""
    from spacewar.learn.envs import SpacewarVectorEnv

    env = SpacewarVectorEnv(matches, opponent=opponent, max_frames=3000, copy=copy)
    env.reset(seed=seed)
    actions = np.random.default_rng(0).integers(0, [3, 2, 2, 2], size=(frames, matches, 4))
    env.step(actions[0])
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        for f in range(frames):
            obs = env.step(actions[f])[0]
        best = min(best, time.perf_counter() - start)
    return matches * frames / best, obs


def bench_learning(matches=4096, frames=50, repeats=5, opponents=("random", "chaser")):
    """Match-frames per second, at 1 thread and at every thread, with the results compared
    between the two: ``LearningBatch.step`` (random actions; observations, rewards,
    terminations and resets included) and ``SpacewarVectorEnv.step`` against each compiled
    opponent (the learner's actions random), and in self-play (both seats learners: agent-steps
    per second, two per match-frame). Each figure is the best of ``repeats`` runs: this
    machine's speed varies by up to 2x from one minute to the next."""
    from spacewar.learn.batch import LearningBatch, compiled_bots

    codes = np.random.default_rng(0).integers(0, 24, size=(frames, matches, 2))
    opponents = [o for o in opponents if o in compiled_bots.KINDS]
    rows, finals = {}, []
    for count in each_thread_count():
        batch = LearningBatch(matches, seed=1, rounds=3, frame_cap=3000)
        batch.step(codes[0])
        best = math.inf
        for _ in range(repeats):
            start = time.perf_counter()
            for f in range(frames):
                batch.step(codes[f])
            best = min(best, time.perf_counter() - start)
        row = {"match_frames_per_second": matches * frames / best}
        final = [batch.observations.copy()]
        for opponent in opponents:
            rate, obs = _vector_env_rate(opponent, matches, frames, repeats)
            row[f"vector_env_vs_{opponent}_match_frames_per_second"] = rate
            final.append(obs.copy())
        rate, obs = _vector_env_rate("random", matches, frames, repeats, copy=False)
        row["vector_env_vs_random_no_copy_match_frames_per_second"] = rate
        final.append(obs.copy())
        rate, obs = _vector_env_rate(None, 2 * matches, frames, repeats)  # 2 agents a match
        row["vector_env_self_play_agent_steps_per_second"] = rate
        final.append(obs.copy())
        rows[str(count)] = row
        finals.append(final)
    same = all(np.array_equal(a, b) for other in finals[1:] for a, b in zip(finals[0], other))
    return {"matches": matches, "opponents": opponents, "threads": rows,
            "identical_across_threads": bool(same), "harness": bench_harness()}


def bench_harness(rounds=1, repeats=5):
    """One match between two idle Python bots: the harness's own cost per frame, i.e. the
    match's wall time per frame less the two bots' ``act`` calls (timed alone on the same
    observations)."""
    from spacewar import Game, Rules
    from spacewar.bots.idle import Idle
    from spacewar.arena.match import play_match

    play_match("idle", "idle", seed=1, rounds=1)  # compiled code loaded
    per_frame = math.inf
    for _ in range(repeats):
        result, _, timing = play_match("idle", "idle", seed=1, rounds=rounds)
        per_frame = min(per_frame, timing["wall_seconds"] / result["steps"])
    game = Game(Rules(), seeds=[1], rounds=rounds)
    bot = Idle()
    obs = game.observe(0, 0)
    calls = 20000
    act = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(calls):
            bot.act(obs)
        act = min(act, (time.perf_counter() - start) / calls)
    return {"frames": result["steps"], "seconds_per_frame": per_frame,
            "act_seconds": act, "harness_seconds_per_frame": per_frame - 2 * act}


def text(r):
    lines = []
    g = r["learning"]
    same = "identical" if g["identical_across_threads"] else "DIFFERENT"
    lines.append(f"\n8. learning: {g['matches']} matches, observations and rewards included "
                 f"({same} at every thread count), match-frames/s")
    for count, row in g["threads"].items():
        lines.append(f"  {count} thread(s): LearningBatch.step "
                     f"{row['match_frames_per_second']:.3e}" + "".join(
                         f"; SpacewarVectorEnv.step vs {o} "
                         f"{row[f'vector_env_vs_{o}_match_frames_per_second']:.3e}"
                         for o in g["opponents"])
                     + f"; vs random with copy=False "
                       f"{row['vector_env_vs_random_no_copy_match_frames_per_second']:.3e}"
                     + (f"; self-play {row['vector_env_self_play_agent_steps_per_second']:.3e}"
                        " agent-steps/s"
                        if "vector_env_self_play_agent_steps_per_second" in row else ""))
    h = g["harness"]
    lines.append(f"  one match of two idle Python bots: {h['seconds_per_frame'] * 1e6:.1f} us "
                 f"per frame, of which the bots' act {2 * h['act_seconds'] * 1e6:.2f} us: the "
                 f"harness's own cost {h['harness_seconds_per_frame'] * 1e6:.1f} us per frame")
    return lines


def markdown(r):
    out = []
    g = r["learning"]
    opponents = g.get("opponents", [])
    out += [f"## 8. Spacewar for learning code ({g['matches']} matches)", "",
            "Random actions; every match's two egocentric observations, rewards, "
            "terminations and resets included in the compiled step; "
            "`SpacewarVectorEnv.step` also includes its action checks and conversion and "
            "the compiled opponent's decisions. Results "
            + ("identical" if g["identical_across_threads"] else "**different**")
            + " at every thread count. Match-frames per second:", "",
            "| threads | `LearningBatch.step` | "
            + " | ".join(f"`SpacewarVectorEnv.step` vs {o}" for o in opponents)
            + " | vs random, `copy=False` | self-play (agent-steps/s) |",
            "|---|---|" + "---|" * (len(opponents) + 2)]
    out += [f"| {count} | {row['match_frames_per_second']:.3e} | " + " | ".join(
                f"{row[f'vector_env_vs_{o}_match_frames_per_second']:.3e}"
                for o in opponents)
            + f" | {row['vector_env_vs_random_no_copy_match_frames_per_second']:.3e} | "
            + (f"{row['vector_env_self_play_agent_steps_per_second']:.3e}"
               if "vector_env_self_play_agent_steps_per_second" in row else "-") + " |"
            for count, row in g["threads"].items()]
    h = g.get("harness")
    if h:
        out += ["", f"One match of two idle Python bots ({h['frames']} frames): "
                f"{h['seconds_per_frame'] * 1e6:.1f} us per frame, of which the two bots' "
                f"`act` {2 * h['act_seconds'] * 1e6:.2f} us: the harness's own cost is "
                f"{h['harness_seconds_per_frame'] * 1e6:.1f} us per frame."]
    out.append("")
    return out


def targets(r):
    rows = []
    g = r["learning"]
    fastest = max(g["threads"].values(), key=lambda row: row["match_frames_per_second"])
    for opponent, goal in (("random", 2e6), ("chaser", 1e6)):
        key = f"vector_env_vs_{opponent}_match_frames_per_second"
        if key in fastest:
            rows.append((f"SpacewarVectorEnv.step vs {opponent}, {g['matches']} matches: "
                         f"at least {goal:.0e} match-frames/s", f"{fastest[key]:.2e}",
                         fastest[key] >= goal))
    key = "vector_env_self_play_agent_steps_per_second"
    if key in fastest:
        rows.append((f"SpacewarVectorEnv.step in self-play, {g['matches']} matches: at least "
                     "4e+06 agent-steps/s", f"{fastest[key]:.2e}", fastest[key] >= 4e6))
    h = g["harness"]["harness_seconds_per_frame"]
    rows.append(("one match of two idle Python bots: the harness's own cost at most 10 us "
                 "per frame", f"{h * 1e6:.1f} us", h <= 10e-6))
    return rows
