"""The ``spacewar`` command: bots, match, tournament, league, replay, play, train."""
import argparse
import json
import math
import sys

from engine.atomic import check_output_path

from .rules import MODES, STARS, Rules


def _rules_from(args):
    return Rules(mode=args.mode, star=args.star, star_kills=not args.star_teleports,
                 angular_momentum=args.angular_momentum, single_shot=args.single_shot)


def _add_rules_options(p):
    g = p.add_argument_group("rules (the 1962 sense switches, and newer modes)")
    g.add_argument("--mode", choices=MODES, default="classic",
                   help="classic (1962), newtonian (N-body: ships attract, torpedoes feel the "
                        "star) or electric (charged ships and torpedoes, F flips polarity)")
    g.add_argument("--star", choices=STARS, default="heavy", help="heavy, light (1/4) or none")
    g.add_argument("--star-teleports", action="store_true",
                   help="touching the star moves the ship to the corner instead of killing it")
    g.add_argument("--angular-momentum", action="store_true",
                   help="turn keys change the angular velocity")
    g.add_argument("--single-shot", action="store_true", help="one torpedo per press of fire")


def _add_fault_options(p):
    g = p.add_argument_group("bot budgets and fault isolation (see docs/game.md, "
                             "'Running untrusted bots')")
    g.add_argument("--budget-ms", type=_positive_float, default=50.0,
                   help="time budget per action in ms; a slower answer is paid from the overage "
                        "bank, then dropped")
    g.add_argument("--overage-ms", type=_non_negative_float, default=1000.0,
                   help="overage bank per match in ms, for answers over the budget")
    g.add_argument("--startup-s", type=_positive_float, default=10.0,
                   help="start-up budget in s for a bot's import, construction and reset")
    g.add_argument("--bot-memory-mb", type=_positive_int, default=1024,
                   help="address-space limit of an isolated bot's process in MiB")
    g.add_argument("--max-faults", type=_positive_int, default=25,
                   help="faults (exception, timeout, invalid action) that forfeit a match")
    g.add_argument("--isolation", choices=("auto", "process"), default="auto",
                   help="auto: built-in bots in this process, every other bot in its own "
                        "confined process; process: built-in bots too")


def _limits_from(args):
    from .seats import Limits

    return Limits(budget=args.budget_ms / 1000.0, overage=args.overage_ms / 1000.0,
                  startup=args.startup_s, memory_mb=args.bot_memory_mb)


def _finite(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite, got {text!r}")
    return value


def _positive_float(text):
    value = _finite(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text!r}")
    return value


def _non_negative_float(text):
    value = _finite(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text!r}")
    return value


def _int(text, low, high):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer, got {text!r}") from None
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(f"must be in [{low}, {high}], got {text}")
    return value


def _positive_int(text):
    return _int(text, 1, 1_000_000)


def _non_negative_int(text):
    return _int(text, 0, 1_000_000)


def _seed(text):
    return _int(text, 0, 2**63 - 1)


def build_parser():
    parser = argparse.ArgumentParser(
        prog="spacewar", description="Spacewar! (1962) on an N-body engine, for bots.")
    sub = parser.add_subparsers(dest="command", required=True)
    fmt = {"formatter_class": argparse.ArgumentDefaultsHelpFormatter}

    sub.add_parser("bots", **fmt, help="list the built-in bots")

    m = sub.add_parser("match", **fmt, help="play one match between two bots")
    m.add_argument("--p1", required=True, help="bot: a built-in name, package.module:Class or path/to/file.py:Class")
    m.add_argument("--p2", required=True, help="the other bot")
    m.add_argument("--seed", type=_seed, default=0)
    m.add_argument("--rounds", type=_positive_int, default=5)
    m.add_argument("--json", action="store_true", help="print the result as JSON")
    m.add_argument("--replay", metavar="FILE", help="record the match to a JSON replay file")
    _add_rules_options(m)
    _add_fault_options(m)

    t = sub.add_parser("tournament", **fmt, help="round robin between bots, both seat orders")
    t.add_argument("--bots", required=True, help="comma-separated bots")
    t.add_argument("--games", type=_positive_int, default=10, help="seeds per pair, each played in both seat orders")
    t.add_argument("--seed", type=_seed, default=1)
    t.add_argument("--rounds", type=_positive_int, default=3)
    t.add_argument("--workers", type=_positive_int, default=None, help="worker processes (default: all cores)")
    t.add_argument("--json", action="store_true", help="print the full report as JSON")
    t.add_argument("--no-progress", action="store_true", help="no progress bar")
    t.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run the matches on a Dask cluster: its scheduler's address, or 'local' "
                        "for a LocalCluster of this machine (default: $DASK_SCHEDULER_ADDRESS, "
                        "else local processes); needs the [cluster] extra")
    _add_rules_options(t)
    _add_fault_options(t)

    lg = sub.add_parser("league", **fmt, help="many bots, Swiss or sampled pairings, ratings with "
                                               "uncertainty, resumable")
    lg.add_argument("--bots", required=True,
                    help="a directory of bot files (every class defining act in its *.py files, "
                         "every *.npz policy) or comma-separated bots")
    lg.add_argument("--rounds", type=_positive_int, required=True,
                    help="league rounds: each bot meets one opponent a round")
    lg.add_argument("--out", required=True, metavar="FILE",
                    help="JSON results file, written after every round; an existing one of the "
                         "same league is resumed (and extended to --rounds)")
    lg.add_argument("--pairing", choices=("swiss", "sampled"), default="swiss",
                    help="swiss: neighbours in the ratings so far; sampled: random")
    lg.add_argument("--games", type=_positive_int, default=2,
                    help="seeds per pairing, each played in both seat orders")
    lg.add_argument("--seed", type=_seed, default=1)
    lg.add_argument("--match-rounds", type=_positive_int, default=3, help="rounds of each match")
    lg.add_argument("--bootstrap", type=_non_negative_int, default=200,
                    help="bootstrap resamples for the Bradley-Terry intervals")
    lg.add_argument("--workers", type=_positive_int, default=None,
                    help="worker processes (default: all cores)")
    lg.add_argument("--scheduler", default=None, metavar="ADDRESS",
                    help="run the matches on a Dask cluster (as for tournament)")
    lg.add_argument("--json", action="store_true", help="print the results as JSON")
    lg.add_argument("--no-progress", action="store_true", help="no progress bar")
    _add_rules_options(lg)
    _add_fault_options(lg)

    r = sub.add_parser("replay", **fmt, help="check a replay or render it to a GIF")
    r.add_argument("file")
    what = r.add_mutually_exclusive_group(required=True)
    what.add_argument("--check", action="store_true", help="re-simulate and confirm the identical outcome")
    what.add_argument("--gif", metavar="OUT", help="render the match to an animated GIF")
    r.add_argument("--every", type=_positive_int, default=2, help="draw every n-th frame (GIF)")
    r.add_argument("--size", type=_positive_int, default=480, help="GIF side in pixels")

    b = sub.add_parser("sandbox", **fmt, help="show what confines an isolated bot on this machine, "
                                              "by running a probe bot that tries each attack")
    b.add_argument("--json", action="store_true", help="print the findings as JSON")

    p = sub.add_parser("play", **fmt, help="you at the keyboard against a bot (needs the [viz] extra)")
    p.add_argument("--p2", default="chaser", help="the bot to play against")
    p.add_argument("--seed", type=_seed, default=0)
    p.add_argument("--rounds", type=_positive_int, default=5)
    p.add_argument("--fps", type=_positive_int, default=60)
    _add_rules_options(p)

    tr = sub.add_parser("train", **fmt, help="train a policy with PPO and save it as .npz "
                                             "(needs the [rl] extra: JAX and optax)")
    tr.add_argument("--opponent", default="random",
                    help="the opponent it trains against: a compiled bot of the vector env "
                         "(spacewar.envs.OPPONENTS) or a policy .npz")
    tr.add_argument("--minutes", type=_positive_float, default=10.0, help="wall-clock budget")
    tr.add_argument("--out", default="policy.npz", help="the policy file to write (checked first)")
    tr.add_argument("--seed", type=_seed, default=0,
                    help="seeds the network, the sampled actions and the matches")
    tr.add_argument("--envs", type=_positive_int, default=512, help="matches played side by side")
    tr.add_argument("--steps", type=lambda text: _int(text, 1, 2**62), default=None,
                    help="stop after this many frames over all matches (reproducible); "
                         "None: when the minutes are up")
    tr.add_argument("--no-progress", action="store_true", help="no progress bar")
    return parser


def _describe_match(result, timing):
    from .seats import FAULT_KINDS

    p1, p2 = result["bots"]
    a, b = result["score"]
    if all(result.get("forfeits", [False, False])):
        head = f"no winner: both {p1} and {p2} forfeited"
    elif result["forfeit"]:
        head = f"{result['winner']} wins: {result['forfeit']} forfeited"
    elif result["winner"] is None:
        head = f"draw {a}-{b} between {p1} and {p2}"
    else:
        loser = p2 if result["winner_seat"] == 0 else p1
        head = f"{result['winner']} beats {loser} {max(a, b)}-{min(a, b)}"
    lines = [head,
             f"  score {p1} {a} - {b} {p2}, {result['rounds']} rounds, {result['steps']} frames, "
             f"seed {result['seed']}, mode {result['rules']['mode']}"]
    for seat, name in enumerate((p1, p2)):
        f = result["faults"][seat]
        if f["total"]:
            kinds = ", ".join(f"{k} {f[k]}" for k in FAULT_KINDS if f.get(k))
            lines.append(f"  faults of {name} (seat {seat + 1}): {f['total']} ({kinds}); "
                         f"first: {f['examples'][0]['message']}")
    if timing is not None:
        lines.append(f"  {timing['frames_per_second']:.0f} frames/s with bots")
    return "\n".join(lines)


def _cmd_bots(args):
    from .bots import BUILTIN, BotLoadError, load_bot_class

    for name in sorted(BUILTIN):
        try:
            module = sys.modules[load_bot_class(name).__module__]
            summary = (module.__doc__ or "").strip().splitlines()[0]
        except (BotLoadError, IndexError) as exc:
            summary = f"(unavailable: {exc})"
        print(f"{name:<10}{summary}")
    print("Other bots: package.module:Class or path/to/file.py:Class")
    return 0


def _cmd_match(args):
    from .match import play_match
    from . import replay as replay_io

    if args.replay:
        check_output_path(args.replay, "replay")  # before the match, not after it
    _check_policy_files((args.p1, args.p2))
    result, rep, timing = play_match(
        args.p1, args.p2, seed=args.seed, rounds=args.rounds, rules=_rules_from(args),
        limits=_limits_from(args), max_faults=args.max_faults, isolation=args.isolation,
        record=bool(args.replay))
    if args.replay:
        replay_io.save(args.replay, rep)
    if args.json:
        print(json.dumps(result, sort_keys=True, indent=2))
    else:
        print(_describe_match(result, timing))
        if args.replay:
            print(f"  replay written to {args.replay}")
    return 0


def _check_policy_files(specs):
    """A policy file named on the command line that cannot be played is an error now (exit 2,
    with the field at fault), not a forfeit after the match starts."""
    from .bots import BotLoadError, is_policy_file
    from .policy import Policy, PolicyError

    for spec in specs:
        if is_policy_file(spec):
            try:
                Policy.load(spec)
            except PolicyError as exc:
                raise BotLoadError(str(exc)) from None


def _cmd_tournament(args):
    from .tournament import format_table, run_tournament

    bots = [b.strip() for b in args.bots.split(",") if b.strip()]
    _check_policy_files(bots)
    report, stats = run_tournament(
        bots, games=args.games, seed=args.seed, rounds=args.rounds, rules=_rules_from(args),
        workers=args.workers, progress=not args.no_progress and not args.json,
        limits=_limits_from(args), max_faults=args.max_faults, isolation=args.isolation,
        scheduler=args.scheduler)
    if args.json:
        print(json.dumps(report, sort_keys=True, indent=2))
    else:
        n = len(report["matches"])
        print(f"Round robin: {len(bots)} bots, {args.games} seeds per pair in both seat orders, "
              f"{n} matches of {args.rounds} rounds, seed {args.seed}, mode {args.mode}")
        print(format_table(report))
        print(f"{stats['frames']} frames played; {stats['frames'] / max(stats['match_seconds'], 1e-9):.0f} "
              "frames/s per worker with bots")
    return 0


def _cmd_league(args):
    import os

    from .bots import bots_in
    from .league import format_table, run_league

    if os.path.isdir(args.bots):
        bots, skipped = bots_in(args.bots)
        for path, reason in skipped.items():
            print(f"spacewar league: skipped {path}: {reason}", file=sys.stderr)
    else:
        bots = [b.strip() for b in args.bots.split(",") if b.strip()]
    _check_policy_files(bots)

    def report_round(results):
        if not args.json and not args.no_progress:
            from tqdm import tqdm

            tqdm.write(f"round {results['rounds_played']} of {args.rounds} saved to {args.out}",
                       file=sys.stderr)

    results = run_league(
        bots, args.rounds, args.out, games=args.games, pairing=args.pairing, seed=args.seed,
        match_rounds=args.match_rounds, rules=_rules_from(args), workers=args.workers,
        progress=not args.no_progress and not args.json, limits=_limits_from(args),
        max_faults=args.max_faults, isolation=args.isolation, scheduler=args.scheduler,
        bootstrap=args.bootstrap, on_round=report_round)
    if args.json:
        print(json.dumps(results, sort_keys=True, indent=1))
    else:
        matches = sum(len(r["matches"]) for r in results["rounds"])
        print(f"League: {len(bots)} bots, {results['rounds_played']} {args.pairing} rounds, "
              f"{matches} matches of {args.match_rounds} rounds, seed {args.seed}; "
              f"results in {args.out}")
        print(format_table(results))
    return 0


def _cmd_replay(args):
    from . import replay as replay_io

    data = replay_io.load(args.file)
    if args.check:
        ok, details = replay_io.check(data)
        r = details["replayed"]
        if ok:
            print(f"OK: {args.file} replays identically: score {r['score'][0]}-{r['score'][1]}, "
                  f"{r['rounds']} rounds, {r['steps']} frames, final state {r['final_state_sha256'][:16]}")
            if details.get("unchecked"):
                print(f"  not re-derivable from a replay, so not compared: "
                      f"{', '.join(details['unchecked'])}")
            if details.get("signature") == "verified":
                print("  signed with this user's key: the bots and the fault record are as "
                      "they were recorded")
            else:
                print(f"  WARNING: {details.get('signature')}: the bots' names and the fault "
                      "record cannot be verified (only a replay signed with this user's key, "
                      f"{replay_io.key_path()}, can vouch for them)")
            return 0
        print(f"MISMATCH: {args.file}: {json.dumps(details['mismatches'], sort_keys=True)}")
        return 1
    from .render import render_gif

    check_output_path(args.gif, "gif")
    render_gif(data, args.gif, every=args.every, size=args.size)
    print(f"wrote {args.gif}")
    return 0


def _cmd_sandbox(args):
    from .sandbox_probe import format_findings, probe

    findings = probe()
    if args.json:
        print(json.dumps(findings, sort_keys=True, indent=2))
    else:
        print(format_findings(findings))
    return 0 if findings["ok"] else 1


def _cmd_play(args):
    from .play import play

    summary = play(p2=args.p2, rules=_rules_from(args), seed=args.seed, rounds=args.rounds,
                   fps=args.fps)
    print(summary)
    return 0


def _cmd_train(args):
    from .train import TrainConfig, train

    config = TrainConfig(opponent=args.opponent, minutes=args.minutes, steps=args.steps,
                         seed=args.seed, envs=args.envs)
    result = train(config, args.out, progress=not args.no_progress)
    print(f"wrote {args.out}: {result['frames']:,} frames, {result['updates']} updates, "
          f"{result['episodes']} episodes in {result['seconds']:.0f} s; win rate "
          f"{result['recent_win_rate']:.0%} over the last finished episodes (sampled actions)")
    return 0


COMMANDS = {"train": _cmd_train, "bots": _cmd_bots, "match": _cmd_match, "tournament": _cmd_tournament, "league": _cmd_league,
            "replay": _cmd_replay, "play": _cmd_play, "sandbox": _cmd_sandbox}


def main(argv=None):
    args = build_parser().parse_args(argv)
    from .bots import BotLoadError
    from .replay import ReplayError
    from engine.cluster import CodeMismatch, SchedulerUnreachable

    try:
        return COMMANDS[args.command](args)
    except (BotLoadError, ReplayError, ValueError, CodeMismatch, SchedulerUnreachable) as exc:
        print(f"spacewar {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except ImportError as exc:
        print(f"spacewar {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
