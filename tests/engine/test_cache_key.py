"""Compiled code is keyed on the sources each function is built from (``engine.cache``).

An edit to a module recompiles exactly the functions built from it, and the results follow the
edit; an edit to a module a run does not use recompiles nothing it uses. Shown on a copy of the
engine in a fresh compiled-code directory, each run in a process of its own that lists what it
compiled (numba's compilation events) and prints its results.
"""
import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from engine import cache, integrators
from engine.forces import registry
from engine.integrators import splitting

ROOT = Path(__file__).resolve().parents[2]
FORCE_FILES = {Path(entry.module.__file__).name for entry in registry.entries()}


def _files(function):
    return {Path(path).name for path in cache.dependencies(function)[0]}


def test_the_integrators_are_built_from_no_force_module():
    """The force table calls the kernels through their addresses, so no integrator carries a
    force kernel's code (an edit to a force module leaves them compiled), except the fused
    executors of mutual gravity alone (``fused_gravity``), which are gravity's own."""
    executors = [splitting.advance_general, integrators.euler.advance,
                 integrators.runge_kutta.advance, integrators.dormand_prince.advance_counted,
                 integrators.ias15.advance, integrators.janus.run_lattice_general]
    for executor in executors:
        files = _files(executor)
        assert {"dispatch.py", "calls.py"} <= files, executor
        assert files & FORCE_FILES <= {"gravity.py"}, (executor, files & FORCE_FILES)
    # the Wisdom-Holman kernels call their operators through addresses: the kicks name the
    # force table, and none of them a force module
    from numba.core.registry import CPUDispatcher

    compiled = [f for f in vars(integrators.wisdom_holman).values()
                if isinstance(f, CPUDispatcher)]
    assert any({"dispatch.py", "calls.py"} <= _files(f) for f in compiled)
    for f in compiled:
        assert _files(f) & FORCE_FILES <= {"gravity.py"}, (f, _files(f) & FORCE_FILES)
    assert not _files(splitting.advance_general) & FORCE_FILES
    assert not _files(integrators.janus.run_lattice_general) & FORCE_FILES
    # nothing outside the project's packages (numba and numpy are versioned by numba's key)
    assert all(Path(p).is_relative_to(ROOT / "engine") for p in cache.dependencies(
        splitting.advance_general)[0])


def test_a_kernel_is_built_from_its_own_module_and_what_it_calls():
    from engine.forces import drag, gravity

    assert _files(drag.accumulate) & FORCE_FILES == {"drag.py"}
    # gravity's kernel calls the large-N pair kernels: their module is a source of it
    assert {"gravity.py", "pairwise.py"} <= _files(gravity.accumulate)
    assert "drag.py" not in _files(gravity.accumulate)


def test_the_stamp_follows_the_plain_globals_frozen_in(monkeypatch):
    """A global read by compiled code is a constant in its machine code: its value is part of
    the key (the game's bots are compiled for how numpy's dot rounds here, a global)."""
    from engine.integrators import splitting as module

    before = cache.dependency_stamp(module.advance)
    assert cache.dependency_stamp(module.advance) == before
    monkeypatch.setattr(module, "_W1", module._W1 + 1.0)  # read by no compiled function
    assert cache.dependency_stamp(module.advance) == before
    from engine.integrators import common

    monkeypatch.setattr(common, "OK", -7)  # read by the executors
    assert cache.dependency_stamp(module.advance_general) != before


_RUN = textwrap.dedent("""
    import json, sys
    from numba.core import event

    compiled = set()

    class Listener(event.Listener):
        def on_start(self, ev):
            pass

        def on_end(self, ev):
            f = ev.data["dispatcher"].py_func
            if f.__module__.startswith("engine"):
                compiled.add(f"{f.__module__}.{f.__qualname__}")

    event.register("numba:compile", Listener())
    from engine import Simulation, forces

    finals = []
    for mu in (1.0, 2.0):
        sim = Simulation(dim=2, integrator="leapfrog", dt=0.01)
        sim.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 1.0))
        sim.add_force(forces.PointMass(mu=mu))
        sim.step(100)
        finals.append(sim.pos[0].tolist() + [sim.energy()])
    print(json.dumps({"compiled": sorted(compiled), "finals": finals}))
""")


def _run(tree, cache_dir):
    env = {**os.environ, "PYTHONPATH": str(tree), "NUMBA_CACHE_DIR": str(cache_dir)}
    env.pop("NUMBA_DISABLE_JIT", None)
    out = subprocess.run([sys.executable, "-c", _RUN], cwd=tree, env=env, capture_output=True,
                         text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def _edit(path, old=None, new=None):
    text = path.read_text()
    if old is None:
        path.write_text(text + "\n# an edit\n")
        return
    assert text.count(old) == 1, old
    path.write_text(text.replace(old, new))


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    base = tmp_path_factory.mktemp("checkout")
    shutil.copytree(ROOT / "engine", base / "engine",
                    ignore=shutil.ignore_patterns("__pycache__"))
    return base


def test_an_edit_recompiles_exactly_what_is_built_from_it(tree, tmp_path):
    cache_dir = tmp_path / "cache"
    first = _run(tree, cache_dir)
    assert "engine.integrators.splitting.advance_general" in first["compiled"]
    assert "engine.forces.point_mass.accumulate" in first["compiled"]
    # only the scene's own force kernels: not Drag's, not the pair kernels
    assert not [name for name in first["compiled"]
                if name.startswith("engine.forces.") and ".point_mass." not in name
                and not name.startswith("engine.forces.dispatch.")], first["compiled"]

    again = _run(tree, cache_dir)
    assert again == {"compiled": [], "finals": first["finals"]}

    # a module the run does not use: nothing recompiles
    _edit(tree / "engine" / "forces" / "drag.py")
    assert _run(tree, cache_dir) == again

    # the scene's force kernel: its module's kernels recompile, nothing else, and the results
    # follow the edit (the attractor's pull doubled: mu = 1 now moves as mu = 2 did)
    _edit(tree / "engine" / "forces" / "point_mass.py", "        s = mu / (r2 * math.sqrt(r2))",
          "        s = (2.0 * mu) / (r2 * math.sqrt(r2))")
    edited = _run(tree, cache_dir)
    assert set(edited["compiled"]) == {"engine.forces.point_mass.accumulate",
                                       "engine.forces.point_mass.potential"}
    np.testing.assert_array_equal(edited["finals"][0][:2], first["finals"][1][:2])

    # the integrators' shared drift and kick: every executor built from them recompiles, the
    # force kernels do not
    _edit(tree / "engine" / "integrators" / "common.py")
    shared = _run(tree, cache_dir)
    assert "engine.integrators.splitting.advance_general" in shared["compiled"]
    assert not [name for name in shared["compiled"] if name.startswith("engine.forces.")
                and not name.startswith("engine.forces.dispatch.")], shared["compiled"]
    assert shared["finals"] == edited["finals"]


def test_the_cache_directory(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    for package in cache.SOURCES:
        assert cache.cache_dir(package) == str(tmp_path / "numba" / cache.COMPILED)
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache.cache_dir("spacewar") == str(tmp_path / "xdg" / "nbody-spacewar" / cache.COMPILED)
    with pytest.raises(ValueError, match="'nope'"):
        cache.cache_dir("nope")


def test_earlier_versions_directories_are_pruned_when_unused_for_a_day(tmp_path):
    old, recent, ours = (tmp_path / name for name in ("numba-engine-0123", "numba-spacewar-4567p",
                                                     cache.COMPILED))
    for path in (old, recent, ours):
        path.mkdir()
    day_ago = os.path.getmtime(old) - cache.MIN_AGE - 10
    os.utime(old, (day_ago, day_ago))
    os.utime(ours, (day_ago, day_ago))
    cache.prune_legacy(str(tmp_path))
    assert not old.exists() and recent.exists() and ours.exists()


def test_a_function_numba_cannot_cache_runs_with_numbas_warning(tmp_path, monkeypatch):
    """A ctypes call puts a raw address in the code (a dynamic global): numba cannot cache
    it and says so, naming the file; the function still runs (the warning once named a file
    our locator did not keep, and raised AttributeError instead)."""
    import ctypes
    import warnings

    from numba.core.errors import NumbaWarning

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    labs = ctypes.CDLL(None).labs
    labs.argtypes, labs.restype = [ctypes.c_long], ctypes.c_long
    monkeypatch.setitem(globals(), "_LABS", labs)  # a global: numba pickles a closure's cells
    compiled = cache.jit()(_absolute)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert compiled(-7) == 7
    messages = [str(w.message) for w in caught if issubclass(w.category, NumbaWarning)]
    assert any('Cannot cache compiled function "_absolute"' in m for m in messages), messages
    assert any(w.filename == __file__ for w in caught)


def _absolute(x):
    return _LABS(x)  # noqa: F821 (set by the test above)


PARALLEL_MODULE = """
from numba import prange
from engine.cache import jit

@jit(parallel=True)
def total(x):
    s = 0.0
    for i in prange(x.shape[0]):
        s += x[i]
    return s

@jit()
def twice_total(x):
    return 2.0 * total(x)
"""


def test_a_caller_compiled_over_a_cached_parallel_callee_loads_in_a_fresh_process(tmp_path):
    """A function linking a ``prange`` kernel that was loaded from the cache (as when only the
    caller's sources changed) is cached; a new process loading that caller first must start
    numba's thread pool for it (numba forgets to: its code then aborted the process, "LLVM
    ERROR: Symbol not found: allocate_sched")."""
    (tmp_path / "parallel_pair.py").write_text(PARALLEL_MODULE)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
           "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)])}
    steps = ["import numpy as np, parallel_pair as m; print(m.total(np.ones(10)))",
             "import numpy as np, parallel_pair as m; m.total(np.ones(10)); "
             "print(m.twice_total(np.ones(10)))",
             "import numpy as np, parallel_pair as m; print(m.twice_total(np.ones(10)))"]
    outputs = []
    for script in steps:
        done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == 0, done.stderr[-2000:]
        outputs.append(done.stdout.strip())
    assert outputs == ["10.0", "20.0", "20.0"]
