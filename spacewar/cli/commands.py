"""What each ``spacewar`` subcommand does with its parsed arguments (``COMMANDS``); heavy
modules are imported inside each, so ``--help`` and a bot's start stay light."""
import json
import sys

from engine import compile_ahead
from engine.atomic import check_output_path

from spacewar.cli.options import limits_from, rules_from
from spacewar.faults import printable


def _describe_match(result, timing):
    """A match's result as text, every line escaped (``seats.printable``): the bots' names
    are submissions' file names, and their fault messages their own words."""
    from spacewar.faults import FAULT_KINDS, printable

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
    from spacewar.bots import BUILTIN, BotLoadError, load_bot_class

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
    from spacewar.arena.match import play_match
    from spacewar import replay as replay_io

    if args.replay:
        check_output_path(args.replay, "replay")  # before the match, not after it
    _check_policy_files((args.p1, args.p2))
    result, rep, timing = play_match(
        args.p1, args.p2, seed=args.seed, rounds=args.rounds, rules=rules_from(args),
        limits=limits_from(args), max_faults=args.max_faults, isolation=args.isolation,
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
    from spacewar.bots import BotLoadError, is_policy_file
    from spacewar.bots.policy import Policy, PolicyError

    for spec in specs:
        if is_policy_file(spec):
            try:
                Policy.load(spec)
            except PolicyError as exc:
                raise BotLoadError(str(exc)) from None


def _pages_and_replays(args):
    """``(pages directory or None, replays directory or None)`` of ``--html`` and
    ``--replays``, the pages' directory checked before any match is played; with pages and
    no ``--replays`` the replays are kept in the pages' ``replays`` directory."""
    if args.html is None:
        return None, args.replays
    from spacewar.view.league_pages import check_pages_dir, default_replays

    pages = check_pages_dir(args.html)
    return pages, default_replays(pages) if args.replays is None else args.replays


def _write_pages(args, results, pages, replays):
    from spacewar.view.league_pages import write_pages

    summary = write_pages(pages, results, replays, workers=getattr(args, "workers", None))
    without = summary["replays_missing"] + summary["replays_refused"]
    notes = (f"; {without} matches without their replay" if without else "") + (
        f"; {summary['player_refused']} replays too long for a player page"
        if summary["player_refused"] else "")
    print(f"wrote {summary['index']}: {summary['bot_pages']} bot pages, "
          f"{summary['match_pages']} match pages, {summary['bytes'] / 1e6:.1f} MB in "
          f"{summary['seconds']:.1f} s{notes}", file=sys.stderr if args.json else sys.stdout)


def _cmd_tournament(args):
    from spacewar.arena.tournament import format_table, run_tournament

    bots = [b.strip() for b in args.bots.split(",") if b.strip()]
    _check_policy_files(bots)
    pages, replays = _pages_and_replays(args)
    report, stats = run_tournament(
        bots, games=args.games, seed=args.seed, rounds=args.rounds, rules=rules_from(args),
        workers=args.workers, progress=not args.no_progress and not args.json,
        limits=limits_from(args), max_faults=args.max_faults, isolation=args.isolation,
        scheduler=args.scheduler, bootstrap=args.bootstrap, replays=replays)
    if args.json:
        print(json.dumps(report, sort_keys=True, indent=2))
    else:
        n = len(report["matches"])
        print(f"Round robin: {len(bots)} bots, {args.games} seeds per pair in both seat orders, "
              f"{n} matches of {args.rounds} rounds, seed {args.seed}, mode {args.mode}")
        print(format_table(report))
        print(f"{stats['frames']} frames played; {stats['frames'] / max(stats['match_seconds'], 1e-9):.0f} "
              "frames/s per worker with bots")
    if pages is not None:
        _write_pages(args, report, pages, replays)
    return 0


def _cmd_league(args):
    import os

    from spacewar.bots import bots_in
    from spacewar.arena.league import format_standings, run_league
    from spacewar.faults import printable

    if os.path.isdir(args.bots):
        bots, skipped = bots_in(args.bots)
        for path, reason in skipped.items():
            print(f"spacewar league: skipped {printable(path)}: {reason}", file=sys.stderr)
    else:
        bots = [b.strip() for b in args.bots.split(",") if b.strip()]
    _check_policy_files(bots)
    pages, replays = _pages_and_replays(args)

    def report_round(results):
        if not args.json and not args.no_progress:
            from tqdm import tqdm

            tqdm.write(f"round {results['rounds_played']} of {args.rounds} saved to {args.out}",
                       file=sys.stderr)

    results = run_league(
        bots, args.rounds, args.out, games=args.games, pairing=args.pairing, seed=args.seed,
        match_rounds=args.match_rounds, rules=rules_from(args), workers=args.workers,
        progress=not args.no_progress and not args.json, limits=limits_from(args),
        max_faults=args.max_faults, isolation=args.isolation, scheduler=args.scheduler,
        bootstrap=args.bootstrap, on_round=report_round, trust_results=args.trust_results,
        replays=replays)
    if args.json:
        print(json.dumps(results, sort_keys=True, indent=1))
    else:
        matches = sum(len(r["matches"]) for r in results["rounds"])
        print(f"League: {len(bots)} bots, {results['rounds_played']} {args.pairing} rounds, "
              f"{matches} matches of {args.match_rounds} rounds, seed {args.seed}; "
              f"results in {args.out}")
        print(format_standings(results))
    if pages is not None:
        _write_pages(args, results, pages, replays)
    return 0


def _cmd_replay(args):
    from spacewar import replay as replay_io

    if args.html:
        from spacewar.view.html_page import check_page_path

        check_page_path(args.html)  # before the replay is read: never over the replay itself
    data = replay_io.load(args.file)
    if args.html:
        from spacewar.view.player_page import write_player

        summary = write_player(data, args.html)
        print(f"wrote {printable(args.html)}: {summary['frames']} frames, "
              f"{summary['bytes'] / 1e3:.0f} kB, replay {summary['signature']}")
        return 0
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
    from spacewar.view.gif import render_gif

    check_output_path(args.gif, "gif")
    render_gif(data, args.gif, every=args.every, size=args.size)
    print(f"wrote {args.gif}")
    return 0


def _view_replay(data, args):
    from spacewar.view.replay_view import view_replay

    summary = view_replay(data, fps=args.fps, scale=args.window_size, speed=args.speed)
    end = {True: "the final state is the recorded one", False: "the final state DIFFERS "
           "from the recording", None: "the end was not reached"}[summary["recorded_end"]]
    print(f"left the replay at frame {summary['frame']} of {summary['total']}; {end}")
    return 0


def _cmd_sandbox(args):
    from spacewar.sandbox.probe import format_findings, probe

    findings = probe()
    if args.json:
        print(json.dumps(findings, sort_keys=True, indent=2))
    else:
        print(format_findings(findings))
    return 0 if findings["ok"] else 1


def _in_window(command, run, *args):
    """Run a window command; no display is one line on stderr and exit status 2."""
    from spacewar.view.window import NoDisplayError

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
    from spacewar.view.live import format_summary, play, watch

    _check_policy_files([spec for spec in (args.p1, args.p2) if spec.strip().lower() != "human"])
    options = dict(rules=rules_from(args), seed=args.seed, rounds=args.rounds, fps=args.fps,
                   scale=args.window_size, limits=limits_from(args),
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
    from spacewar.learn.train import TrainConfig, train

    config = TrainConfig(opponent=args.opponent, minutes=args.minutes, steps=args.steps,
                         seed=args.seed, envs=args.envs)
    result = train(config, args.out, progress=not args.no_progress)
    print(f"wrote {args.out}: {result['frames']:,} frames, {result['updates']} updates, "
          f"{result['episodes']} episodes in {result['seconds']:.0f} s; win rate "
          f"{result['recent_win_rate']:.0%} over the last finished episodes (sampled actions)")
    return 0


def _cmd_new_bot(args):
    import shlex

    from spacewar.author.new_bot import write_starter

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
    from spacewar.cli.compile_tasks import TASKS

    compile_ahead.main(args, TASKS)
    return 0


def _cmd_check(args):
    from spacewar.author.check import check_bot
    from spacewar.faults import printable

    def show(match):
        again = " (the same match again)" if match.get("repeat") else ""
        print(f"  vs {printable(match['opponent'])}, seat {match['seat'] + 1}, "
              f"seed {match['seed']}: "
              f"{match['outcome']} {match['score'][0]}-{match['score'][1]}{again}",
              file=sys.stderr)

    report = check_bot(args.bot, opponents=args.opponents, games=args.games, seed=args.seed,
                       rounds=args.rounds, rules=rules_from(args), limits=limits_from(args),
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
