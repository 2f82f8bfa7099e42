"""``python -m validation report --out DIR [--quick]`` | ``python -m validation bench ...`` |
``python -m validation advise --problem NAME --error E [--t-end T]``"""
import argparse
import importlib
import sys

#: the modules each command needs beyond the core install, and the extra that has them
NEEDS = {"report": ("rebound", "matplotlib"), "bench": ("rebound",), "advise": ()}
EXTRA = "validation"


def missing_modules(command):
    """The modules ``command`` needs that cannot be imported here."""
    missing = []
    for name in NEEDS[command]:
        try:
            importlib.import_module(name)
        except ImportError:
            missing.append(name)
    return missing


def _missing_message(command, missing):
    return (f"python -m validation {command} needs {' and '.join(missing)}, from the "
            f"[{EXTRA}] extra: pip install 'nbody-spacewar[{EXTRA}]' (in a checkout: "
            f"pip install -e '.[{EXTRA}]')")


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = argparse.ArgumentParser(
        prog="python -m validation",
        description="Validation of the engine against REBOUND and closed forms, and benchmarks.")
    sub = parser.add_subparsers(dest="command", metavar="{report,bench,advise}")
    sub.add_parser("report", add_help=False,
                   help="orbits, energy drift, work-precision and hard cases: DIR/report.md")
    sub.add_parser("bench", add_help=False, help="benchmarks")
    sub.add_parser("advise", add_help=False,
                   help="the cheapest integrator and step for a validation problem "
                        "(engine.advise)")
    if not argv or argv[0] not in ("report", "bench", "advise"):
        parser.parse_args(argv)  # prints usage / help, or the error for an unknown command
        parser.print_help()
        return 2
    command, rest = argv[0], argv[1:]
    missing = [] if {"-h", "--help"} & set(rest) else missing_modules(command)
    if missing:
        print(_missing_message(command, missing), file=sys.stderr)
        return 2
    if command == "report":
        from . import report
        return report.main(rest)
    if command == "advise":
        from . import advise
        return advise.main(rest)
    from . import bench  # written separately; imported only when asked for
    return bench.main(rest)


if __name__ == "__main__":
    sys.exit(main())
