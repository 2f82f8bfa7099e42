"""The ``spacewar`` command: bots, match, tournament, league, replay, play, watch, train,
new-bot, check."""
import argparse
import json
import math
import sys

from engine import compile_ahead
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


class _KeysHelpFormatter(argparse.RawDescriptionHelpFormatter,
                         argparse.ArgumentDefaultsHelpFormatter):
    """Defaults shown after each option, and the epilog's table of keys kept as written."""


def _speed(text):
    """A viewer speed: one of ``keys.SPEEDS``, written as a number or a fraction (1/8)."""
    from .keys import SPEEDS, speed_label

    try:
        if "/" in text:
            top, bottom = text.split("/", 1)
            value = float(top) / float(bottom)
        else:
            value = float(text)
    except (ValueError, ZeroDivisionError):
        value = None
    if value not in SPEEDS:
        raise argparse.ArgumentTypeError(
            f"must be one of {', '.join(speed_label(s)[:-1] for s in SPEEDS)}, got {text!r}")
    return value


def _add_window_options(p, seed_help):
    p.add_argument("--seed", type=_seed, default=0, help=seed_help)
    p.add_argument("--rounds", type=_positive_int, default=5, help="rounds to play")
    p.add_argument("--fps", type=lambda text: _int(text, 1, 1000), default=60,
                   help="game frames a second at normal speed")
    p.add_argument("--window-size", type=lambda text: _int(text, 128, 8192), default=720,
                   metavar="PIXELS", help="side of the square window")
    p.add_argument("--replay", metavar="FILE",
                   help="record the match to a JSON replay file (checked before it starts; "
                        "view it with: spacewar replay FILE --view)")
    p.add_argument("--json", action="store_true",
                   help="print the summary as JSON instead of a table")


def _add_window_commands(sub):
    """``play`` (people at the keyboard, or bots) and ``watch`` (two bots), in a window."""
    from .keys import play_epilog, watch_epilog

    p = sub.add_parser("play", formatter_class=_KeysHelpFormatter, epilog=play_epilog(),
                       help="fly at the keyboard against a bot or a second person "
                            "(needs the [viz] extra)")
    p.add_argument("--p1", default="human",
                   help="seat 1, the needle: 'human' or a bot (a built-in name, "
                        "package.module:Class or path/to/file.py:Class)")
    p.add_argument("--p2", default="chaser", help="seat 2, the wedge: 'human' or a bot")
    _add_window_options(p, "the match's seed: the same seed, bots and keys give the same match")
    _add_rules_options(p)
    _add_fault_options(p)

    w = sub.add_parser("watch", formatter_class=_KeysHelpFormatter, epilog=watch_epilog(),
                       help="watch two bots play in a window, with pause, slow motion and "
                            "fast forward (needs the [viz] extra)")
    w.add_argument("--p1", default="chaser", help="seat 1, the needle: a bot")
    w.add_argument("--p2", default="sniper", help="seat 2, the wedge: a bot")
    w.add_argument("--speed", type=_speed, default=1.0,
                   help="speed to start at: 1/8, 1/4, 1/2, 1, 2, 4 or 8 times real time")
    _add_window_options(p=w, seed_help="the match's seed: the match is the one "
                                       "'spacewar match' plays with the same seed and bots")
    _add_rules_options(w)
    _add_fault_options(w)


def _gif_size(text):
    """``--size``: a GIF side the renderer accepts, refused with the reason before any work."""
    from .paint_pil import MAX_SIZE, MIN_SIZE

    try:
        return _int(text, MIN_SIZE, MAX_SIZE)
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(f"{exc} (pixels a side: each frame takes about 8 "
                                         f"bytes a pixel, 128 MiB at {MAX_SIZE})") from None


def _add_replay_command(sub):
    from .keys import replay_epilog

    r = sub.add_parser("replay", formatter_class=_KeysHelpFormatter, epilog=replay_epilog(),
                       help="check a replay, render it to a GIF or scrub it in a window")
    r.add_argument("file", help="the replay file (JSON)")
    what = r.add_mutually_exclusive_group(required=True)
    what.add_argument("--check", action="store_true", help="re-simulate and confirm the identical outcome")
    what.add_argument("--gif", metavar="OUT", help="render the match to an animated GIF")
    what.add_argument("--view", action="store_true",
                      help="show it in a window: pause, step, slow motion, fast forward and "
                           "rewind, every frame re-simulated exactly (needs the [viz] extra)")
    r.add_argument("--every", type=_positive_int, default=2, help="draw every n-th frame (GIF)")
    r.add_argument("--size", type=_gif_size, default=480,
                   help="GIF side in pixels, 64 to 4096 (each frame takes about 8 bytes a "
                        "pixel: 128 MiB at 4096)")
    r.add_argument("--fps", type=lambda text: _int(text, 1, 1000), default=60,
                   help="game frames a second at normal speed (--view)")
    r.add_argument("--speed", type=_speed, default=1.0,
                   help="speed to start at: 1/8, 1/4, 1/2, 1, 2, 4 or 8 (--view)")
    r.add_argument("--window-size", type=lambda text: _int(text, 128, 8192), default=720,
                   metavar="PIXELS", help="side of the square window (--view)")


def build_parser():
    parser = argparse.ArgumentParser(
        prog="spacewar", description="Spacewar! (1962) on an N-body engine, for bots.")
    sub = parser.add_subparsers(dest="command", required=True)
    fmt = {"formatter_class": argparse.ArgumentDefaultsHelpFormatter}

    sub.add_parser("bots", **fmt, help="list the built-in bots")

    m = sub.add_parser("match", **fmt, help="play one match between two bots")
    m.add_argument("--p1", required=True, help="bot: a built-in name, package.module:Class or path/to/file.py:Class")
    m.add_argument("--p2", required=True, help="the other bot")
    m.add_argument("--seed", type=_seed, default=0,
                   help="the match's seed: the same seed and bots give the same match")
    m.add_argument("--rounds", type=_positive_int, default=5,
                   help="rounds to play (a round ends when a ship dies or at the time limit)")
    m.add_argument("--json", action="store_true", help="print the result as JSON")
    m.add_argument("--replay", metavar="FILE", help="record the match to a JSON replay file")
    _add_rules_options(m)
    _add_fault_options(m)

    t = sub.add_parser("tournament", **fmt, help="round robin between bots, both seat orders")
    t.add_argument("--bots", required=True, help="comma-separated bots")
    t.add_argument("--games", type=_positive_int, default=10, help="seeds per pair, each played in both seat orders")
    t.add_argument("--seed", type=_seed, default=1,
                   help="the tournament's seed: every match's seed is derived from it")
    t.add_argument("--rounds", type=_positive_int, default=3, help="rounds of each match")
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
    lg.add_argument("--seed", type=_seed, default=1,
                    help="the league's seed: pairings and every match's seed derive from it")
    lg.add_argument("--match-rounds", type=_positive_int, default=3, help="rounds of each match")
    lg.add_argument("--bootstrap", type=_non_negative_int, default=200,
                    help="bootstrap resamples for the Bradley-Terry intervals")
    lg.add_argument("--workers", type=_positive_int, default=None,
                    help="worker processes (default: all cores)")
    lg.add_argument("--scheduler", default=None, metavar="ADDRESS",
                    help="run the matches on a Dask cluster (as for tournament)")
    lg.add_argument("--json", action="store_true", help="print the results as JSON")
    lg.add_argument("--no-progress", action="store_true", help="no progress bar")
    lg.add_argument("--trust-results", action="store_true",
                    help="resume a results file that is not verified by your signing key "
                         "(unsigned, another organizer's, or edited); its records are still "
                         "checked, and the results and the table say it was resumed so")
    _add_rules_options(lg)
    _add_fault_options(lg)

    _add_replay_command(sub)

    b = sub.add_parser("sandbox", **fmt, help="show what confines an isolated bot on this machine, "
                                              "by running a probe bot that tries each attack")
    b.add_argument("--json", action="store_true", help="print the findings as JSON")

    _add_window_commands(sub)

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
    _add_author_commands(sub, fmt)
    return parser


def _add_author_commands(sub, fmt):
    """The ``new-bot`` and ``check`` subcommands: a bot author's first steps."""
    from .bots import available

    n = sub.add_parser("new-bot", **fmt, help="write a commented starter bot that runs as it is")
    n.add_argument("name", metavar="NAME",
                   help="the bot's name, a Python identifier: NAME.py holds class Name "
                        "(hunter -> Hunter, my_bot -> MyBot)")
    n.add_argument("--out", metavar="PATH", default=None,
                   help="the .py file to write, or an existing directory to write NAME.py in; "
                        "never overwritten; None: NAME.py in the current directory")

    c = sub.add_parser("check", **fmt,
                       help="check a bot before a tournament: it loads, has no faults, answers "
                            "within the budget, plays a seed the same way twice; exit 1 if not")
    c.add_argument("bot", metavar="BOT",
                   help="the bot: path/to/file.py:Class, package.module:Class or a built-in name")
    c.add_argument("--games", type=_positive_int, default=None,
                   help="seeds played against each opponent, each from both seats; None: 1, "
                        "or 10 for a batch bot, whose 2 x games matches against an opponent "
                        "are played at once as in a tournament of that many games")
    c.add_argument("--seed", type=_seed, default=0,
                   help="the first seed; game g plays seed + g")
    c.add_argument("--rounds", type=_positive_int, default=1, help="rounds of each match")
    c.add_argument("--opponents", default=",".join(available()),
                   help="comma-separated opponents: built-in names or any bot specification")
    c.add_argument("--json", action="store_true", help="print the report as JSON")
    c.add_argument("--no-progress", action="store_true",
                   help="do not list the matches on stderr as they are played")
    _add_rules_options(c)
    _add_fault_options(c)

    a = sub.add_parser("compile", **fmt,
                       help="compile the game's kernels ahead, one process per core (a first "
                            "match or tournament then starts at once; CI runs it)")
    compile_ahead.add_arguments(a)


def _describe_match(result, timing):
    """A match's result as text, every line escaped (``seats.printable``): the bots' names
    are submissions' file names, and their fault messages their own words."""
    from .faults import FAULT_KINDS, printable

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
    return "\n".join(printable(line) for line in lines)


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
    from .bots.policy import Policy, PolicyError

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
    from .league import format_standings, run_league
    from .faults import printable

    if os.path.isdir(args.bots):
        bots, skipped = bots_in(args.bots)
        for path, reason in skipped.items():
            print(f"spacewar league: skipped {printable(path)}: {reason}", file=sys.stderr)
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
        bootstrap=args.bootstrap, on_round=report_round, trust_results=args.trust_results)
    if args.json:
        print(json.dumps(results, sort_keys=True, indent=1))
    else:
        matches = sum(len(r["matches"]) for r in results["rounds"])
        print(f"League: {len(bots)} bots, {results['rounds_played']} {args.pairing} rounds, "
              f"{matches} matches of {args.match_rounds} rounds, seed {args.seed}; "
              f"results in {args.out}")
        print(format_standings(results))
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
    if args.view:
        return _in_window("replay", _view_replay, data, args)
    from .gif import render_gif

    check_output_path(args.gif, "gif")
    render_gif(data, args.gif, every=args.every, size=args.size)
    print(f"wrote {args.gif}")
    return 0


def _view_replay(data, args):
    from .viewer import view_replay

    summary = view_replay(data, fps=args.fps, scale=args.window_size, speed=args.speed)
    end = {True: "the final state is the recorded one", False: "the final state DIFFERS "
           "from the recording", None: "the end was not reached"}[summary["recorded_end"]]
    print(f"left the replay at frame {summary['frame']} of {summary['total']}; {end}")
    return 0


def _cmd_sandbox(args):
    from .sandbox_probe import format_findings, probe

    findings = probe()
    if args.json:
        print(json.dumps(findings, sort_keys=True, indent=2))
    else:
        print(format_findings(findings))
    return 0 if findings["ok"] else 1


def _in_window(command, run, *args):
    """Run a window command; no display is one line on stderr and exit status 2."""
    from .viewer import NoDisplayError

    try:
        return run(*args)
    except NoDisplayError as exc:
        print(f"spacewar {command}: {exc}", file=sys.stderr)
        return 2


def _cmd_play(args):
    return _in_window("play", _play_in_window, args, False)


def _cmd_watch(args):
    return _in_window("watch", _play_in_window, args, True)


def _play_in_window(args, watching):
    from .play import format_summary, play, watch

    _check_policy_files([spec for spec in (args.p1, args.p2) if spec.strip().lower() != "human"])
    options = dict(rules=_rules_from(args), seed=args.seed, rounds=args.rounds, fps=args.fps,
                   scale=args.window_size, limits=_limits_from(args),
                   max_faults=args.max_faults, isolation=args.isolation, record_to=args.replay)
    if watching:
        summary = watch(args.p1, args.p2, speed=args.speed, **options)
    else:
        summary = play(args.p2, p1=args.p1, **options)
    if args.json:
        print(json.dumps(summary, sort_keys=True, indent=2))
    else:
        print(format_summary(summary))
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


def _cmd_new_bot(args):
    import shlex

    from .starter import write_starter

    try:
        path, spec = write_starter(args.name, args.out)
    except FileExistsError as exc:
        print(f"spacewar new-bot: error: {exc}", file=sys.stderr)
        return 2
    bot = shlex.quote(spec)
    print(f"wrote {path}: a starter bot (class {spec.rsplit(':', 1)[1]}) that turns towards the "
          "enemy, fires when lined up and keeps clear of the star")
    print("next, try:")
    print(f"  spacewar match --p1 {bot} --p2 idle")
    print(f"  spacewar match --p1 {bot} --p2 chaser --replay game.json")
    print("  spacewar replay game.json --gif game.gif")
    print(f"  spacewar check {bot}")
    print(f"then make it yours: the conventions are at the top of {path}, and more is in the "
          "section 'Writing a bot' of the project's docs/game.md")
    return 0


def _cmd_compile(args):
    from .compile_ahead import TASKS

    compile_ahead.main(args, TASKS)
    return 0


def _cmd_check(args):
    from .checker import check_bot
    from .faults import printable

    def show(match):
        again = " (the same match again)" if match.get("repeat") else ""
        print(f"  vs {printable(match['opponent'])}, seat {match['seat'] + 1}, "
              f"seed {match['seed']}: "
              f"{match['outcome']} {match['score'][0]}-{match['score'][1]}{again}",
              file=sys.stderr)

    report = check_bot(args.bot, opponents=args.opponents, games=args.games, seed=args.seed,
                       rounds=args.rounds, rules=_rules_from(args), limits=_limits_from(args),
                       max_faults=args.max_faults, isolation=args.isolation,
                       on_match=None if args.json or args.no_progress else show)
    if args.json:
        print(json.dumps(report.to_dict(), sort_keys=True, indent=2))
    else:
        print(report.format())
    return 0 if report.passed else 1


COMMANDS = {"train": _cmd_train, "bots": _cmd_bots, "match": _cmd_match, "tournament": _cmd_tournament, "league": _cmd_league,
            "replay": _cmd_replay, "play": _cmd_play, "watch": _cmd_watch, "sandbox": _cmd_sandbox,
            "new-bot": _cmd_new_bot, "check": _cmd_check, "compile": _cmd_compile}


def main(argv=None):
    args = build_parser().parse_args(argv)
    from .bots import BotLoadError
    from .replay import ReplayError
    from .faults import printable
    from engine.cluster import CodeMismatch, SchedulerUnreachable

    try:
        return COMMANDS[args.command](args)
    except (BotLoadError, ReplayError, ValueError, CodeMismatch, SchedulerUnreachable,
            ImportError) as exc:
        # an error may quote a submission's file name or words: shown escaped
        print(f"spacewar {args.command}: error: {printable(str(exc))}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
