"""The script behind docs/rl.md's figures: evaluate a run's checkpoints, plot its curve.

    spacewar train ... (or spacewar.train.train(..., log=LOG, checkpoints=(5, 10)))
    python docs/rl_figures.py LOG POLICY_STEM [--matches 50] [--out docs/rl_curve.png]

``POLICY_STEM`` is the run's ``--out`` without ``.npz``: the checkpoints ``STEM.5min.npz``,
``STEM.10min.npz`` and the final ``STEM.npz`` are played against the vector env's compiled
opponents (``spacewar.policy.evaluate``: matches of 3 rounds, the policy in seat 0) and the
figures printed as JSON; the plot shows the training win rate over recent episodes and the
evaluated win rates.
"""
import argparse
import json
import os

import numpy as np


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log")
    parser.add_argument("stem")
    parser.add_argument("--matches", type=int, default=50)
    parser.add_argument("--opponents", default="random,chaser,sniper")
    parser.add_argument("--minutes", default="5,10,20", help="the checkpoints' minutes")
    parser.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "rl_curve.png"))
    parser.add_argument("--seed", type=int, default=1000)
    args = parser.parse_args(argv)

    from spacewar.policy import evaluate

    history = [json.loads(line) for line in open(args.log, encoding="utf-8")]
    minutes = [float(m) for m in args.minutes.split(",")]
    paths = [f"{args.stem}.{m:g}min.npz" for m in minutes[:-1]] + [f"{args.stem}.npz"]
    results = {}
    for m, path in zip(minutes, paths):
        for opponent in args.opponents.split(","):
            r = evaluate(path, opponent=opponent, matches=args.matches, seed=args.seed, rounds=3)
            results.setdefault(opponent, []).append((m, r["win_rate"], r))
            print(json.dumps({"minutes": m, "opponent": opponent, **r}), flush=True)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    t = np.array([h["seconds"] for h in history]) / 60.0
    w = np.array([h["win_rate"] for h in history], dtype=float)
    ax.plot(t, w, color="0.6", lw=1, label="training episodes (1 round, sampled actions)")
    for opponent, rows in results.items():
        ax.plot([r[0] for r in rows], [r[1] for r in rows], "o-",
                label=f"vs {opponent}: {args.matches} matches of 3 rounds, greedy")
    ax.set_xlabel("training minutes (2 shared cores)")
    ax.set_ylabel("win rate")
    ax.set_ylim(0, 1)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    from engine.atomic import atomic_write

    atomic_write(args.out, lambda f: fig.savefig(f, format="png", dpi=110), mode="wb")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
