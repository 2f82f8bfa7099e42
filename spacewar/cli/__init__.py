"""The ``spacewar`` command: bots, match, tournament, league, replay, play, watch, train,
new-bot, check."""
import sys

from spacewar.cli.commands import COMMANDS
from spacewar.cli.parser import build_parser

__all__ = ["main", "build_parser"]


def main(argv=None):
    args = build_parser().parse_args(argv)
    from spacewar.bots import BotLoadError
    from spacewar.replay import ReplayError
    from spacewar.faults import printable
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
