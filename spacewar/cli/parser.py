"""The ``spacewar`` command's parser: its subcommands and their options (``spacewar --help``)."""
import argparse

from engine import compile_ahead

from spacewar.cli.options import (KeysHelpFormatter, add_fault_options, add_rules_options,
                                  add_window_options, gif_size, int_in, non_negative_int,
                                  positive_float, positive_int, seed_number, speed_factor)


def add_window_commands(sub):
    """``play`` (people at the keyboard, or bots) and ``watch`` (two bots), in a window."""
    from spacewar.view.keys import play_epilog, watch_epilog

    p = sub.add_parser("play", formatter_class=KeysHelpFormatter, epilog=play_epilog(),
                       help="fly at the keyboard against a bot or a second person "
                            "(needs the [viz] extra)")
    p.add_argument("--p1", default="human",
                   help="seat 1, the needle: 'human' or a bot (a built-in name, "
                        "package.module:Class or path/to/file.py:Class)")
    p.add_argument("--p2", default="chaser", help="seat 2, the wedge: 'human' or a bot")
    add_window_options(p, "the match's seed: the same seed, bots and keys give the same match")
    add_rules_options(p)
    add_fault_options(p)

    w = sub.add_parser("watch", formatter_class=KeysHelpFormatter, epilog=watch_epilog(),
                       help="watch two bots play in a window, with pause, slow motion and "
                            "fast forward (needs the [viz] extra)")
    w.add_argument("--p1", default="chaser", help="seat 1, the needle: a bot")
    w.add_argument("--p2", default="sniper", help="seat 2, the wedge: a bot")
    w.add_argument("--speed", type=speed_factor, default=1.0,
                   help="speed to start at: 1/8, 1/4, 1/2, 1, 2, 4 or 8 times real time")
    add_window_options(p=w, seed_help="the match's seed: the match is the one "
                                       "'spacewar match' plays with the same seed and bots")
    add_rules_options(w)
    add_fault_options(w)


def add_replay_command(sub):
    from spacewar.view.keys import replay_epilog

    r = sub.add_parser("replay", formatter_class=KeysHelpFormatter, epilog=replay_epilog(),
                       help="check a replay, render it to a GIF or a web page, or scrub it in a "
                           "window")
    r.add_argument("file", help="the replay file (JSON)")
    what = r.add_mutually_exclusive_group(required=True)
    what.add_argument("--check", action="store_true", help="re-simulate and confirm the identical outcome")
    what.add_argument("--gif", metavar="OUT", help="render the match to an animated GIF")
    what.add_argument("--html", metavar="OUT",
                      help="write one self-contained web page that plays the match (play, "
                           "pause, speeds, single frames, a scrub bar; no network)")
    what.add_argument("--view", action="store_true",
                      help="show it in a window: pause, step, slow motion, fast forward and "
                           "rewind, every frame re-simulated exactly (needs the [viz] extra)")
    r.add_argument("--every", type=positive_int, default=2, help="draw every n-th frame (GIF)")
    r.add_argument("--size", type=gif_size, default=480,
                   help="GIF side in pixels, 64 to 4096 (each frame takes about 8 bytes a "
                        "pixel: 128 MiB at 4096)")
    r.add_argument("--fps", type=lambda text: int_in(text, 1, 1000), default=60,
                   help="game frames a second at normal speed (--view)")
    r.add_argument("--speed", type=speed_factor, default=1.0,
                   help="speed to start at: 1/8, 1/4, 1/2, 1, 2, 4 or 8 (--view)")
    r.add_argument("--window-size", type=lambda text: int_in(text, 128, 8192), default=720,
                   metavar="PIXELS", help="side of the square window (--view)")


def add_pages_options(p):
    """``--html DIR`` and ``--replays DIR`` of ``tournament`` and ``league``."""
    p.add_argument("--html", metavar="DIR", default=None,
                   help="write the standings, head-to-head matrix, a page a bot and a page a "
                        "match (its player) into DIR, made if missing and checked before any "
                        "match; the replays go to DIR/replays unless --replays is given")
    p.add_argument("--replays", metavar="DIR", default=None,
                   help="keep every match's replay in DIR (made if missing, checked before any "
                        "match): match-00001-seed-S.json (tournament), "
                        "round-001-match-0001-seed-S.json (league)")


def build_parser():
    parser = argparse.ArgumentParser(
        prog="spacewar", description="Spacewar! (1962) on an N-body engine, for bots.")
    sub = parser.add_subparsers(dest="command", required=True)
    fmt = {"formatter_class": argparse.ArgumentDefaultsHelpFormatter}

    sub.add_parser("bots", **fmt, help="list the built-in bots")

    m = sub.add_parser("match", **fmt, help="play one match between two bots")
    m.add_argument("--p1", required=True, help="bot: a built-in name, package.module:Class or path/to/file.py:Class")
    m.add_argument("--p2", required=True, help="the other bot")
    m.add_argument("--seed", type=seed_number, default=0,
                   help="the match's seed: the same seed and bots give the same match")
    m.add_argument("--rounds", type=positive_int, default=5,
                   help="rounds to play (a round ends when a ship dies or at the time limit)")
    m.add_argument("--json", action="store_true", help="print the result as JSON")
    m.add_argument("--replay", metavar="FILE", help="record the match to a JSON replay file")
    add_rules_options(m)
    add_fault_options(m)

    t = sub.add_parser("tournament", **fmt, help="round robin between bots, both seat orders")
    t.add_argument("--bots", required=True, help="comma-separated bots")
    t.add_argument("--games", type=positive_int, default=10, help="seeds per pair, each played in both seat orders")
    t.add_argument("--seed", type=seed_number, default=1,
                   help="the tournament's seed: every match's seed is derived from it")
    t.add_argument("--rounds", type=positive_int, default=3, help="rounds of each match")
    t.add_argument("--workers", type=positive_int, default=None, help="worker processes (default: all cores)")
    t.add_argument("--json", action="store_true", help="print the full report as JSON")
    t.add_argument("--no-progress", action="store_true", help="no progress bar")
    t.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run the matches on a Dask cluster: its scheduler's address, or 'local' "
                        "for a LocalCluster of this machine (default: $DASK_SCHEDULER_ADDRESS, "
                        "else local processes); needs the [cluster] extra")
    t.add_argument("--bootstrap", type=non_negative_int, default=200,
                   help="bootstrap resamples of the matches for the ratings' 95%% intervals "
                        "(seeded by --seed; 0: none)")
    add_pages_options(t)
    add_rules_options(t)
    add_fault_options(t)

    lg = sub.add_parser("league", **fmt, help="many bots, Swiss or sampled pairings, ratings with "
                                               "uncertainty, resumable")
    lg.add_argument("--bots", required=True,
                    help="a directory of bot files (every class defining act in its *.py files, "
                         "every *.npz policy) or comma-separated bots")
    lg.add_argument("--rounds", type=positive_int, required=True,
                    help="league rounds: each bot meets one opponent a round")
    lg.add_argument("--out", required=True, metavar="FILE",
                    help="JSON results file, written after every round; an existing one of the "
                         "same league is resumed (and extended to --rounds)")
    lg.add_argument("--pairing", choices=("swiss", "sampled"), default="swiss",
                    help="swiss: neighbours in the ratings so far; sampled: random")
    lg.add_argument("--games", type=positive_int, default=2,
                    help="seeds per pairing, each played in both seat orders")
    lg.add_argument("--seed", type=seed_number, default=1,
                    help="the league's seed: pairings and every match's seed derive from it")
    lg.add_argument("--match-rounds", type=positive_int, default=3, help="rounds of each match")
    lg.add_argument("--bootstrap", type=non_negative_int, default=200,
                    help="bootstrap resamples for the Bradley-Terry intervals")
    lg.add_argument("--workers", type=positive_int, default=None,
                    help="worker processes (default: all cores)")
    lg.add_argument("--scheduler", default=None, metavar="ADDRESS",
                    help="run the matches on a Dask cluster (as for tournament)")
    lg.add_argument("--json", action="store_true", help="print the results as JSON")
    lg.add_argument("--no-progress", action="store_true", help="no progress bar")
    lg.add_argument("--trust-results", action="store_true",
                    help="resume a results file that is not verified by your signing key "
                         "(unsigned, another organizer's, or edited); its records are still "
                         "checked, and the results and the table say it was resumed so")
    add_pages_options(lg)
    add_rules_options(lg)
    add_fault_options(lg)

    add_replay_command(sub)

    b = sub.add_parser("sandbox", **fmt, help="show what confines an isolated bot on this machine, "
                                              "by running a probe bot that tries each attack")
    b.add_argument("--json", action="store_true", help="print the findings as JSON")

    add_window_commands(sub)

    tr = sub.add_parser("train", **fmt, help="train a policy with PPO and save it as .npz "
                                             "(needs the [rl] extra: JAX and optax)")
    tr.add_argument("--opponent", default="random",
                    help="the opponent it trains against: a compiled bot of the vector env "
                         "(spacewar.learn.envs.OPPONENTS) or a policy .npz")
    tr.add_argument("--minutes", type=positive_float, default=10.0, help="wall-clock budget")
    tr.add_argument("--out", default="policy.npz", help="the policy file to write (checked first)")
    tr.add_argument("--seed", type=seed_number, default=0,
                    help="seeds the network, the sampled actions and the matches")
    tr.add_argument("--envs", type=positive_int, default=512, help="matches played side by side")
    tr.add_argument("--steps", type=lambda text: int_in(text, 1, 2**62), default=None,
                    help="stop after this many frames over all matches (reproducible); "
                         "None: when the minutes are up")
    tr.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_author_commands(sub, fmt)
    return parser


def add_author_commands(sub, fmt):
    """The ``new-bot`` and ``check`` subcommands: a bot author's first steps."""
    from spacewar.bots import available

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
    c.add_argument("--games", type=positive_int, default=None,
                   help="seeds played against each opponent, each from both seats; None: 1, "
                        "or 10 for a batch bot, whose 2 x games matches against an opponent "
                        "are played at once as in a tournament of that many games")
    c.add_argument("--seed", type=seed_number, default=0,
                   help="the first seed; game g plays seed + g")
    c.add_argument("--rounds", type=positive_int, default=1, help="rounds of each match")
    c.add_argument("--opponents", default=",".join(available()),
                   help="comma-separated opponents: built-in names or any bot specification")
    c.add_argument("--json", action="store_true", help="print the report as JSON")
    c.add_argument("--no-progress", action="store_true",
                   help="do not list the matches on stderr as they are played")
    add_rules_options(c)
    add_fault_options(c)

    a = sub.add_parser("compile", **fmt,
                       help="compile the game's kernels ahead, one process per core (a first "
                            "match or tournament then starts at once; CI runs it)")
    compile_ahead.add_arguments(a)
