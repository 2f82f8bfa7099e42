"""What a command compiles, and how long each function takes: ``python -m validation compile-times``.

    python -m validation compile-times [--out FILE.json] [--top N] -- engine
    python -m validation compile-times -- spacewar match --p1 chaser --p2 sniper --rounds 1
    python -m validation compile-times -- pytest -q tests/engine

runs ``python -m MODULE ARGS`` in a child process with an empty compiled-code cache (a
temporary ``NUMBA_CACHE_DIR``) and compiling ahead switched off (``NBODY_COMPILE_AHEAD=0``:
every compilation in the one process, where numba's ``numba:compile`` events are seen), and
prints each compiled function with its number of specialisations and its compile seconds,
*exclusive* of the functions compiled inside its compilation (a callee first reached while its
caller is typed is compiled then; an inlined function is part of its caller's time). The
seconds are the process's CPU seconds (numba compiles on the calling thread), so another load on
the machine does not inflate them. Processes the command itself starts (a confined bot, a
tournament's workers) are not seen.
"""
import argparse
import collections
import json
import os
import runpy
import subprocess
import sys
import tempfile
import time

from engine.atomic import atomic_write, check_output_path


def _child(module, args, out):
    """In the child: run ``python -m module args`` and write every compilation to ``out``."""
    from numba.core import event

    records, stack = [], []

    class Listener(event.Listener):
        def on_start(self, ev):
            stack.append([time.process_time(), 0.0])

        def on_end(self, ev):
            start, inner = stack.pop()
            total = time.process_time() - start
            if stack:
                stack[-1][1] += total
            f = ev.data["dispatcher"].py_func
            records.append({"function": f"{f.__module__}.{f.__qualname__}",
                            "signature": str(ev.data["args"]), "seconds": total - inner,
                            "nested": bool(stack)})

    event.register("numba:compile", Listener())
    sys.argv = [module] + list(args)
    start = time.perf_counter()
    code = 0
    try:
        runpy.run_module(module, run_name="__main__", alter_sys=True)
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    finally:
        atomic_write(out, json.dumps({"wall_seconds": time.perf_counter() - start,
                                      "exit_code": code, "records": records}))


def measure(command, cache_dir=None):
    """Run ``python -m command[0] command[1:]`` cold (in ``cache_dir``, else an empty temporary
    directory) and return ``{"wall_seconds", "exit_code", "records"}``."""
    with tempfile.TemporaryDirectory() as scratch:
        out = os.path.join(scratch, "compiles.json")
        env = {**os.environ, "NUMBA_CACHE_DIR": cache_dir or os.path.join(scratch, "cache"),
               "NBODY_COMPILE_AHEAD": "0"}
        subprocess.run([sys.executable, "-m", "validation.compile_times", "--child", out,
                        *command], env=env, check=False)
        with open(out, encoding="utf-8") as f:
            return json.load(f)


def summarise(measured, command, note=""):
    """The measurement as kept: the command, its wall and compile seconds, and one row per
    function ``[name, specialisations, compile seconds]``, the longest first."""
    rows = collections.defaultdict(lambda: [0, 0.0])
    for record in measured["records"]:
        row = rows[record["function"]]
        row[0] += 1
        row[1] += record["seconds"]
    functions = sorted(([name, n, round(s, 3)] for name, (n, s) in rows.items()),
                       key=lambda r: -r[2])
    return {"command": list(command), "note": note, "exit_code": measured["exit_code"],
            "wall_seconds": round(measured["wall_seconds"], 2),
            "compilations": len(measured["records"]),
            "compile_seconds": round(sum(r[2] for r in functions), 2), "functions": functions}


def format_table(summary, top=30):
    """A summary as Markdown: the totals, then the ``top`` functions."""
    functions = summary["functions"]
    lines = [f"{summary['compilations']} compilations of {len(functions)} functions: "
             f"{summary['compile_seconds']:.1f} s of compiling (CPU) in "
             f"{summary['wall_seconds']:.1f} s", "",
             "| function | specialisations | compile s |", "|---|---|---|"]
    for name, n, seconds in functions[:top]:
        lines.append(f"| `{name}` | {n} | {seconds:.2f} |")
    if len(functions) > top:
        rest = sum(r[2] for r in functions[top:])
        lines.append(f"| {len(functions) - top} others | | {rest:.2f} |")
    return "\n".join(lines)


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["--child"]:
        _child(argv[2], argv[3:], argv[1])
        return 0
    if "--" not in argv:
        argv = argv + ["--"] if argv else ["--help"]
    split = argv.index("--") if "--" in argv else len(argv)
    parser = argparse.ArgumentParser(
        prog="python -m validation compile-times",
        usage="%(prog)s [--out FILE.json] [--top N] [--note TEXT] -- MODULE [ARGS ...]",
        description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", help="write the measurement as JSON here")
    parser.add_argument("--top", type=int, default=30, help="rows of the table")
    parser.add_argument("--note", default="", help="a line kept with the measurement")
    args = parser.parse_args(argv[:split])
    command = argv[split + 1:]
    if not command:
        parser.error("give the command after --, e.g. -- engine")
    if args.out:
        check_output_path(args.out, "json")
    summary = summarise(measure(command), command, args.note)
    print(format_table(summary, args.top))
    if args.out:
        atomic_write(args.out, json.dumps(summary, indent=1) + "\n")
    return summary["exit_code"]


if __name__ == "__main__":
    sys.exit(main())
