"""The bench's results as text (what ``python -m validation bench`` prints) and as Markdown
(``docs/performance.md``): the machine, the targets against this run's figures, and each
section's part in the sections' order."""
from . import registry
from .registry import chosen

HOW_THE_TARGETS_ARE_MET = """How the engine gets there (the figures are this run's, in the tables below):

- **Direct sum.** From `pairwise.PARALLEL_MIN` (12) bodies on, the active particles are copied
  into contiguous coordinate arrays (each block padded to an odd number of cache lines) and
  the pair sum takes each pair once, in register tiles: four sources are held in registers
  while one pass over the targets below them, vectorised by LLVM, adds the four pulls into
  each target's accumulator and gathers the four reactions in scalar sums. (Writing the
  reaction into the other body inside the loop, the obvious form, does not vectorise; the
  engine used to visit each pair from both ends instead.) The pair triangle is cut into four
  row ranges of equal work with their own accumulators, added in a fixed order, so the result
  is the same to the bit on any number of threads; from `pairwise.THREADS_MIN` (192) bodies
  the ranges are spread over all cores. Section 1's last columns hold the kernel against the
  both-ends loop, side by side.
- **Five bodies.** A scene that is one open-space `NBodyGravity` term on fewer than 12 bodies
  runs a fused executor (`engine/integrators/fused_gravity.py`): the same drift/kick sequence and
  the same pair loop on an interleaved (n, 3) copy of the state, gravity inlined, finiteness
  checked once per 64 steps (a failed block is re-run step by step to stop at the last finite
  state). It is bit-identical to the general executor, without what that one pays per step:
  the force-table call with its array arguments, the strided (dim, n) indexing and the
  per-step save and check. Section 2 holds it against a plain hand-written numba loop.
- **Single precision, optional.** `NBodyGravity(precision="float32")` runs the same kernel on
  float32 copies of the coordinates, in a frame centred on the bodies' mean position and
  scaled by a power of two to their extent (any units: SI distances would overflow r^3 in
  float32 otherwise), with twice the lanes per instruction of float64; section 1's float32
  columns time it, and the tests check its forces against the float64 ones.
  State, small-N loop and energies stay float64.
- **Start-up.** A first run compiles what it uses and nothing else: its integrator, and the
  kernels of the force terms its scene declares (the force table calls them through their
  addresses, so no integrator carries ten force kernels inlined; a kernel is compiled for one
  signature, when a scene first declares its term; a function called from compiled code with a
  constant is compiled once for the constant's type, not once per constant). Each compiled
  function is cached under a key of the sources it is built from, so an edit recompiles only
  what is built from the edited file (section 5's cold figures are the first run after an
  install; after an edit of one force module a run recompiles that module's kernels at most).
  `python -m engine` compiles its integrators in one process per core on its first run, and
  `python -m engine compile` / `spacewar compile` fill the cache ahead (CI runs them). The
  tables under section 5 list what each command compiles, function by function.
- **What compiling costs now** (measured on this machine on 2026-12-05, one process,
  `python -m validation compile-times`; the tables below). The tour compiles for 56 s of CPU
  (275 s before this work), the first match for 25 s (57 s). numba links a compiled callee's
  code into every caller and optimises and emits it again there, up the whole chain: the
  Wisdom-Holman kernels therefore call their operators (steps loop, kick, lazy corrector,
  drift, the drift's fallback) through addresses made in Python for the scene's mode and
  scheme (`engine/address_calls.py`, as the force table calls its kernels), so each operator
  is compiled once and a scene compiles only the ones it uses (a Kepler problem: 62 s of
  Wisdom-Holman and drift code before, 14 s now); IAS15 runs in one kernel without
  reference counting.
  What is left is mostly numba's own front end, not LLVM's optimiser: with LLVM's
  optimisation off (`NUMBA_OPT=0`) the tour still compiles for 48 s, and typing, inlining and
  lowering each integrator's loop is what remains. The game's frame (`spacewar.game.core.step_match`,
  10 s) is compiled once and inlined by LLVM into its three callers. What each command compiled
  and never used before this work is gone: all ten force kernels inlined into every integrator
  (four copies in the Wisdom-Holman kick), the fused-gravity executor in scenes that cannot
  take it, numba's formatting of shape errors in `rk4` and `rk45`, a second specialisation per
  constant argument."""


def targets(r):
    """The performance targets against this run's figures: (target, measured, met) rows, section
    by section."""
    return [row for module in _in_targets_order(chosen(r)) for row in module.targets(r)]


def _in_targets_order(modules):
    """``modules`` in the sections' order, but each section ``TARGETS_BEFORE`` names just
    before the section it names."""
    order = [module.NAME for module in registry.MODULES]
    for name, before in registry.TARGETS_BEFORE.items():
        order.remove(name)
        order.insert(order.index(before), name)
    return sorted(modules, key=lambda module: order.index(module.NAME))


def format_report(r):
    lines = [f"machine: {r['machine']['cpu']}, {r['machine']['cores']} cores, numba "
             f"{r['machine']['numba']} ({r['machine']['numba_threads']} threads), numpy "
             f"{r['machine']['numpy']}, REBOUND {r['machine'].get('rebound', '-')}"]
    for module in chosen(r):
        lines += module.text(r)
    if targets(r):
        lines.append("\ntargets:")
        for name, measured, met in targets(r):
            lines.append(f"  {'met' if met else 'GAP':<4} {name}: {measured}")
    return "\n".join(lines)


def format_markdown(r, command):
    """The results as the body of ``docs/performance.md``."""
    m = r["machine"]
    out = ["# Performance", "",
           f"Measured with `{command}` on {m['cpu']} ({m.get('llvm_cpu', '?')}), {m['cores']} cores, "
           f"Python {m['python']}, numpy {m['numpy']}, numba {m['numba']} ({m['numba_threads']} "
           f"threads), REBOUND {m.get('rebound', '-')}. Every ratio is the median of per-repetition "
           "ratios measured side by side in the same run.", ""]
    if targets(r):
        out += ["## Targets, and where we stand", "", "| target | measured | status |",
                "|---|---|---|"]
        out += [f"| {name} | {measured} | {'met' if met else '**gap**'} |"
                for name, measured, met in targets(r)]
        out += ["", HOW_THE_TARGETS_ARE_MET, ""]
    for module in chosen(r):
        out += module.markdown(r)
    return "\n".join(out)
