"""Section 5: start-up, ``import engine`` plus a first step and whole commands, with a warm and
with a cold numba cache; and the stored measurements of what each command compiles."""
import json
import os
import subprocess
import sys
import tempfile
import time

NAME = "startup"
KEYS = ("startup", "compile_times")
NEEDS = ()


def run(quick):
    return {"startup": bench_startup(quick), "compile_times": stored_compile_times()}


_STARTUP = """
import time
t0 = time.perf_counter()
import engine
from engine import Simulation, forces
sim = Simulation(dim=3, integrator="leapfrog", dt=0.01)
sim.add_many(mass=[1.0, 1e-3], pos=[(0, 0, 0), (1, 0, 0)], vel=[(0, 0, 0), (0, 1, 0)])
sim.add_force(forces.NBodyGravity())
sim.step(1)
print(time.perf_counter() - t0)
"""


#: the commands whose start-up is tracked, by name: ``python -m`` module and arguments (the
#: tournament is the README's first command, played in full: quick runs leave it out)
STARTUP_COMMANDS = {
    "python -m engine": ("engine",),
    "spacewar match": ("spacewar", "match", "--p1", "chaser", "--p2", "sniper", "--rounds", "1"),
    "README tournament": ("spacewar", "tournament", "--bots", "idle,random,chaser,sniper",
                          "--games", "10", "--seed", "1", "--no-progress"),
}


def _shown(name):
    """A start-up command as a user types it."""
    argv = STARTUP_COMMANDS[name]
    return "python -m engine" if argv == ("engine",) else " ".join(argv)


def _wall_seconds(argv, env):
    start = time.perf_counter()
    subprocess.run(argv, env=env, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def bench_startup(quick=False):
    """Start-up from an empty compiled-code cache (a first run after install, an upgrade or
    an edit of everything) and warm (the same command again): ``import engine`` plus a first
    step, and each of ``STARTUP_COMMANDS`` as a whole process, each in a cache of its own."""
    def run(env):
        out = subprocess.run([sys.executable, "-c", _STARTUP], env=env, capture_output=True,
                             text=True, check=True)
        return float(out.stdout.strip().splitlines()[-1])

    env = dict(os.environ)
    with tempfile.TemporaryDirectory() as cold:
        env["NUMBA_CACHE_DIR"] = cold
        cold_s = run(env)
        warm_s = run(env)  # the same (now filled) cache
    commands = {}
    for name, argv in STARTUP_COMMANDS.items():
        if quick and name == "README tournament":
            continue
        with tempfile.TemporaryDirectory() as cold:
            env["NUMBA_CACHE_DIR"] = cold
            full = [sys.executable, "-m", *argv]
            commands[name] = {"cold_seconds": _wall_seconds(full, env),
                              "warm_seconds": _wall_seconds(full, env)}
    return {"cold_cache_seconds": cold_s, "warm_cache_seconds": warm_s, "commands": commands}


#: measurements of ``python -m validation compile-times --out``, shown with the start-up
COMPILE_TIMES_DIR = os.path.join(
    os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "docs",
    "compile_times")


def stored_compile_times():
    """``{file name: measurement}`` of the compile-time measurements kept in the docs (each
    made by ``python -m validation compile-times --out docs/compile_times/NAME.json -- ...``;
    they take a cold run of the command, the test suite's a whole run, so the bench shows the
    stored ones rather than measuring them again)."""
    found = {}
    try:
        names = sorted(n for n in os.listdir(COMPILE_TIMES_DIR) if n.endswith(".json"))
    except OSError:
        return found
    for name in names:
        with open(os.path.join(COMPILE_TIMES_DIR, name), encoding="utf-8") as f:
            found[name[:-5]] = json.load(f)
    return found


def compile_time_markdown(stored):
    """Markdown lines for the stored compile-time measurements: one row per command with its
    totals after and before the change (``NAME.json`` and ``NAME.before.json``), then each
    command's longest compiles after it, and before it."""
    from ..compile_times import format_table

    after = {k: v for k, v in stored.items() if not k.endswith(".before")}
    if not after:
        return []

    def totals(m):
        return (f"{m['compile_seconds']:.1f} s in {len(m['functions'])} functions "
                f"({m['compilations']} compilations)")

    out = ["### What each command compiles, from an empty cache", "",
           "CPU seconds of compiling in one process (`python -m validation compile-times`; "
           "compiling ahead off), exclusive of the callees compiled inside each function.", "",
           "| command | before | after |", "|---|---|---|"]
    for name, m in after.items():
        before = stored.get(name + ".before")
        out.append(f"| `python -m {' '.join(m['command'])}` | "
                   f"{totals(before) if before else 'not measured'} | {totals(m)} |")
    out.append("")
    for name, m in after.items():
        out += [f"#### `python -m {' '.join(m['command'])}`", "", m.get("note", ""), "",
                format_table(m, top=25), ""]
        before = stored.get(name + ".before")
        if before:
            out += [f"Before ({before.get('note', '')}):", "", format_table(before, top=10), ""]
    return out


def text(r):
    lines = []
    if "startup" not in r:
        return lines
    s = r["startup"]
    lines.append(f"\n5. start-up (import engine + first step): warm cache "
                 f"{s['warm_cache_seconds']:.2f} s, cold cache {s['cold_cache_seconds']:.1f} s")
    for name, row in s.get("commands", {}).items():
        lines.append(f"   {name}: warm {row['warm_seconds']:.2f} s, cold "
                     f"{row['cold_seconds']:.1f} s (+{row['cold_seconds'] - row['warm_seconds']:.1f} s)")
    return lines


def markdown(r):
    out = []
    if "startup" in r:
        s = r["startup"]
        out += ["## 5. Start-up", "",
                "From an empty compiled-code cache (cold: the first run after install or an "
                "upgrade) and again with the cache it filled (warm), each a whole process.", "",
                "| command | warm s | cold s | cold - warm s |", "|---|---|---|---|",
                f"| `import engine` and a first step | {s['warm_cache_seconds']:.2f} | "
                f"{s['cold_cache_seconds']:.1f} | "
                f"{s['cold_cache_seconds'] - s['warm_cache_seconds']:.1f} |"]
        for name, row in s.get("commands", {}).items():
            out.append(f"| `{_shown(name)}` | "
                       f"{row['warm_seconds']:.2f} | {row['cold_seconds']:.1f} | "
                       f"{row['cold_seconds'] - row['warm_seconds']:.1f} |")
        out.append("")
    return out + compile_time_markdown(r.get("compile_times", {}))


def targets(r):
    return []
