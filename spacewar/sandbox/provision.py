"""What a confined bot's process is given before it starts: its environment (the project on its
``PYTHONPATH``, one thread, its scratch directory as home and temp), this checkout's compiled
code to copy into its own cache, and the sweep of directories left by a match process killed
without cleaning up."""
import functools
import os
import shutil
import tempfile

# the checkout (or site directory) holding the ``spacewar`` and ``engine`` packages
PROJECT_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def bot_environment(scratch):
    env = {"PATH": "/usr/bin:/bin", "HOME": scratch, "TMPDIR": scratch, "LANG": "C.UTF-8",
           "PYTHONHASHSEED": "0", "PYTHONNOUSERSITE": "1", "PYTHONDONTWRITEBYTECODE": "1",
           "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
           "NUMBA_NUM_THREADS": "1", "NUMBA_CACHE_DIR": os.path.join(scratch, "numba")}
    for key in ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE"):  # keep numpy working on this CPU
        if key in os.environ:
            env[key] = os.environ[key]
    if "SPACEWAR_BOT_TAG" in os.environ:  # lets a caller find its bots' processes (tests do)
        env["SPACEWAR_BOT"] = os.environ["SPACEWAR_BOT_TAG"]
    # the bot's host imports the very project this match runs (a checkout run in place beside
    # another installed copy would otherwise start the installed one, which it may not read)
    env["PYTHONPATH"] = PROJECT_ROOT
    return env


@functools.lru_cache(maxsize=None)
def compiled_code_dirs():
    """The directories of this checkout's compiled game and engine code, as ``(source,
    destination relative to the bot's cache, modules)``, the game's first (what a bot most
    likely runs). A package's cache directory also holds the code compiled for every other
    checkout of the same sources (numba names a subdirectory after each source directory's
    absolute path): only this checkout's subdirectories are the bot's to copy. And a
    subdirectory keeps the code of modules since moved or removed (numba names each file after
    its module, ``core.step_all-120.py311.1.nbc``): ``modules`` names the ones the source
    directory still has, the only files copied."""
    from engine.cache import cache_dir

    try:  # numba's own naming of the subdirectories (not public: a later numba may move it)
        from numba.core.caching import _CacheLocator
    except ImportError:
        return []  # nothing copied: a bot compiles what it uses
    found = []
    for package in ("spacewar", "engine"):
        base = cache_dir(package)
        for source_dir in _package_dirs(os.path.join(PROJECT_ROOT, package)):
            sub = _CacheLocator.get_suitable_cache_subpath(os.path.join(source_dir, "x.py"))
            modules = tuple(sorted(name[:-3] for name in os.listdir(source_dir)
                                   if name.endswith(".py")))
            try:
                cached = os.listdir(os.path.join(base, sub))
            except OSError:
                continue
            if any(cache_file_module(name) in modules for name in cached):
                found.append((os.path.join(base, sub), os.path.join(os.path.basename(base), sub),
                              modules))
    return found


def cache_file_module(name):
    """The module a numba cache file was compiled from: its name up to the first dot."""
    return name.split(".", 1)[0]


def _package_dirs(root):
    """``root`` and its subpackage directories, in a fixed order."""
    found = [root]
    for name in sorted(os.listdir(root)):
        path = os.path.join(root, name)
        if os.path.isfile(os.path.join(path, "__init__.py")):
            found.extend(_package_dirs(path))
    return found


DIR_PREFIX = "spacewar-bot-"


def sweep_bot_directories():
    """Remove the directories of seats whose match process died without cleaning up (a match
    killed by SIGKILL leaves its bots' directories: they are named after its pid)."""
    sweep_stale_directories(DIR_PREFIX)


def sweep_stale_directories(prefix):
    """Remove this user's directories ``<tmp>/<prefix><pid>-*`` whose process ``pid`` no longer
    runs (left by a process killed by SIGKILL, which cleans nothing up); another user's, or a
    live process's, are left alone."""
    base = tempfile.gettempdir()
    try:
        names = os.listdir(base)
    except OSError:
        return
    for name in names:
        if not name.startswith(prefix):
            continue
        pid = name[len(prefix):].split("-", 1)[0]
        if not pid.isdigit() or int(pid) == os.getpid():
            continue
        path = os.path.join(base, name)
        try:
            if os.lstat(path).st_uid != os.geteuid():
                continue  # another user's: not ours to judge
            os.kill(int(pid), 0)
        except ProcessLookupError:
            shutil.rmtree(path, ignore_errors=True)
        except OSError:
            pass  # gone already, or a live process of another user
