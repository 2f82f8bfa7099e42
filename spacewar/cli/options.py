"""The command line's argument types (each refusing a bad value with a message naming it) and
the option groups several subcommands share: rules, faults and budgets, the window."""
import argparse
import math


from spacewar.rules import MODES, STARS, Rules


def rules_from(args):
    return Rules(mode=args.mode, star=args.star, star_kills=not args.star_teleports,
                 angular_momentum=args.angular_momentum, single_shot=args.single_shot)


def add_rules_options(p):
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


def add_fault_options(p):
    g = p.add_argument_group("bot budgets and fault isolation (see docs/game.md, "
                             "'Running untrusted bots')")
    g.add_argument("--budget-ms", type=positive_float, default=50.0,
                   help="time budget per action in ms; a slower answer is paid from the overage "
                        "bank, then dropped")
    g.add_argument("--overage-ms", type=non_negative_float, default=1000.0,
                   help="overage bank per match in ms, for answers over the budget")
    g.add_argument("--startup-s", type=positive_float, default=10.0,
                   help="start-up budget in s for a bot's import, construction and reset")
    g.add_argument("--bot-memory-mb", type=positive_int, default=1024,
                   help="address-space limit of an isolated bot's process in MiB")
    g.add_argument("--max-faults", type=positive_int, default=25,
                   help="faults (exception, timeout, invalid action) that forfeit a match")
    g.add_argument("--isolation", choices=("auto", "process"), default="auto",
                   help="auto: built-in bots in this process, every other bot in its own "
                        "confined process; process: built-in bots too")


def limits_from(args):
    from spacewar.sandbox.limits import Limits

    return Limits(budget=args.budget_ms / 1000.0, overage=args.overage_ms / 1000.0,
                  startup=args.startup_s, memory_mb=args.bot_memory_mb)


def finite_float(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite, got {text!r}")
    return value


def positive_float(text):
    value = finite_float(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text!r}")
    return value


def non_negative_float(text):
    value = finite_float(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text!r}")
    return value


def int_in(text, low, high):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer, got {text!r}") from None
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(f"must be in [{low}, {high}], got {text}")
    return value


def positive_int(text):
    return int_in(text, 1, 1_000_000)


def non_negative_int(text):
    return int_in(text, 0, 1_000_000)


def seed_number(text):
    return int_in(text, 0, 2**63 - 1)


class KeysHelpFormatter(argparse.RawDescriptionHelpFormatter,
                         argparse.ArgumentDefaultsHelpFormatter):
    """Defaults shown after each option, and the epilog's table of keys kept as written."""


def speed_factor(text):
    """A viewer speed: one of ``keys.SPEEDS``, written as a number or a fraction (1/8)."""
    from spacewar.view.keys import SPEEDS, speed_label

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


def add_window_options(p, seed_help):
    p.add_argument("--seed", type=seed_number, default=0, help=seed_help)
    p.add_argument("--rounds", type=positive_int, default=5, help="rounds to play")
    p.add_argument("--fps", type=lambda text: int_in(text, 1, 1000), default=60,
                   help="game frames a second at normal speed")
    p.add_argument("--window-size", type=lambda text: int_in(text, 128, 8192), default=720,
                   metavar="PIXELS", help="side of the square window")
    p.add_argument("--replay", metavar="FILE",
                   help="record the match to a JSON replay file (checked before it starts; "
                        "view it with: spacewar replay FILE --view)")
    p.add_argument("--json", action="store_true",
                   help="print the summary as JSON instead of a table")


def gif_size(text):
    """``--size``: a GIF side the renderer accepts, refused with the reason before any work."""
    from spacewar.view.paint_pil import MAX_SIZE, MIN_SIZE

    try:
        return int_in(text, MIN_SIZE, MAX_SIZE)
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(f"{exc} (pixels a side: each frame takes about 8 "
                                         f"bytes a pixel, 128 MiB at {MAX_SIZE})") from None
