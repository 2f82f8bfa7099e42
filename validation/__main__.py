"""``python -m validation report --out DIR [--quick]`` | ``python -m validation bench ...`` |
``python -m validation advise --problem NAME --error E [--t-end T]`` |
``python -m validation compile-times -- COMMAND ...`` | ``python -m validation theta-table
[--n N]``"""
import argparse
import importlib
import sys

#: the modules each command needs beyond the core install, and the extra that has them (the
#: bench's sections declare theirs: ``bench_needs``)
NEEDS = {"report": ("rebound", "matplotlib"), "bench": ("rebound",), "advise": (),
         "compile-times": (), "theta-table": ()}
EXTRA = "validation"


def _bench_sections(rest):
    """The sections ``bench``'s ``--only`` names in ``rest`` (None: every section)."""
    for i, arg in enumerate(rest):
        if arg == "--only" and i + 1 < len(rest):
            return set(rest[i + 1].split(","))
        if arg.startswith("--only="):
            return set(arg.split("=", 1)[1].split(","))
    return None


def bench_needs(sections=None):
    """The modules the bench's ``sections`` (words of ``--only``; None: every section) need,
    as the sections declare them."""
    from .bench.registry import MODULES

    return tuple(dict.fromkeys(name for module in MODULES
                               if sections is None or module.NAME in sections
                               for name in module.NEEDS))


def missing_modules(command, rest=()):
    """The modules ``command`` (with its arguments ``rest``) needs that cannot be imported."""
    needs = NEEDS[command]
    if command == "bench":
        needs = bench_needs(_bench_sections(list(rest)))
    missing = []
    for name in needs:
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
    sub = parser.add_subparsers(dest="command",
                                metavar="{report,bench,advise,compile-times,theta-table}")
    sub.add_parser("report", add_help=False,
                   help="orbits, energy drift, work-precision and hard cases: DIR/report.md")
    sub.add_parser("bench", add_help=False, help="benchmarks")
    sub.add_parser("advise", add_help=False,
                   help="the cheapest integrator and step for a validation problem "
                        "(engine.advise)")
    sub.add_parser("compile-times", add_help=False,
                   help="what a command compiles from an empty cache, function by function")
    sub.add_parser("theta-table", add_help=False,
                   help="the tree's theta against error and cost (docs/engine.md)")
    if not argv or argv[0] not in NEEDS:
        parser.parse_args(argv)  # prints usage / help, or the error for an unknown command
        parser.print_help()
        return 2
    command, rest = argv[0], argv[1:]
    missing = [] if {"-h", "--help"} & set(rest) else missing_modules(command, rest)
    if missing:
        print(_missing_message(command, missing), file=sys.stderr)
        return 2
    if command == "report":
        from . import report
        return report.main(rest)
    if command == "advise":
        from . import advise
        return advise.main(rest)
    if command == "compile-times":
        from . import compile_times
        return compile_times.main(rest)
    if command == "theta-table":
        from . import theta_table
        return theta_table.main(rest)
    from . import bench  # written separately; imported only when asked for
    return bench.main(rest)


if __name__ == "__main__":
    sys.exit(main())
