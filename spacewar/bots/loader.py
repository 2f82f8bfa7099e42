"""How a bot specification becomes a bot: looked up (``locate``: a built-in name, a policy
file, a file or a module, the rules in ``spacewar.bots``' text), its source read without running
it (``declares_act_batch``, ``bots_in``), and, where a bot may run, its class loaded
(``load_bot_class``) and made (``make_bot``). Pure Python: no numba, no engine."""
import importlib
import importlib.machinery
import importlib.util
import inspect
import io
import os
import stat
import sys
import tokenize

from spacewar.builtin_bots import BUILTIN_BOTS

#: name -> "module:Class" of the built-in bots (``spacewar.builtin_bots``, the one list)
BUILTIN = {name: f"{module}:{cls}" for name, module, cls in BUILTIN_BOTS}


class BotLoadError(ValueError):
    """A bot specification that cannot be loaded (the message says why)."""


def available():
    """Names of the built-in bots."""
    return sorted(BUILTIN)


def is_policy_file(spec):
    """Whether ``spec`` names a trained policy file (``*.npz``, see ``spacewar.policy``)."""
    return isinstance(spec, str) and spec.lower().endswith(".npz")


def is_builtin(spec):
    """A built-in bot, or a policy file: data that our own code (``spacewar.policy``) reads
    without pickle and validates, so it plays in this process like a built-in bot."""
    return isinstance(spec, str) and (spec in BUILTIN or is_policy_file(spec))


def split_spec(spec):
    if not isinstance(spec, str) or not spec:
        raise BotLoadError(f"bot must be a name or 'module:Class' string, got {spec!r}")
    target = BUILTIN.get(spec, spec)
    if ":" not in target:
        raise BotLoadError(f"unknown bot {spec!r}; available: {', '.join(available())} "
                           "(or give package.module:Class or path/to/file.py:Class)")
    where, class_name = target.rsplit(":", 1)
    if not class_name.isidentifier():
        raise BotLoadError(f"{class_name!r} in bot {spec!r} is not a class name")
    return where, class_name


def is_file_spec(where):
    return where.endswith(".py") or os.sep in where or "/" in where


def locate(spec):
    """Where a bot's code lives, found without running any of it.

    Returns ``(read_dirs, list_dirs, search_path)``: what its process must be able to read,
    the directories it must be able to list to import it, and for a ``module:Class`` bot the
    directory its top-level module was found in, which its process imports it from
    (``import_top_level``), else None. The lookup order is the module docstring's. Raises
    ``BotLoadError`` for a specification that cannot name a bot: unknown name, missing file,
    module not found, a module in the current directory named like a standard-library one.
    Whether the module imports, and has the class, is learnt in the bot's own process.
    """
    if is_policy_file(spec):
        path = os.path.abspath(spec)
        if not os.path.isfile(path):
            raise BotLoadError(f"policy file {spec!r} does not exist")
        return [path], [], None
    where, _ = split_spec(spec)
    if is_builtin(spec):
        return [], [], None
    if is_file_spec(where):
        path = os.path.abspath(where)
        if not os.path.isfile(path):
            raise BotLoadError(f"bot file {where!r} does not exist")
        return [path], [], None  # the file alone: its directory may hold other people's bots
    top = where.split(".")[0]
    if not all(part.isidentifier() for part in where.split(".")):
        raise BotLoadError(f"{where!r} in bot {spec!r} is not a module name")
    # a module in the current directory (as ``python -m`` would find it), else an installed one;
    # finding a top-level module's spec runs none of its code
    found = importlib.machinery.PathFinder.find_spec(top, [os.getcwd()])
    local = found is not None
    if local and top in sys.stdlib_module_names:
        raise BotLoadError(f"the bot module {top!r} in the current directory has the name of a "
                           f"standard-library module, which it cannot replace in the bot's "
                           f"process: rename it, or name the file instead "
                           f"(e.g. ./{top}.py:Class)")
    if found is None:
        try:
            found = importlib.util.find_spec(top)
        except (ImportError, ValueError):
            found = None
    if found is None:
        raise BotLoadError(f"cannot import module {where!r} for bot {spec!r}: "
                           f"no module named {top!r} in the current directory or on sys.path")
    if found.submodule_search_locations:
        roots = list(found.submodule_search_locations)
    elif found.origin:
        roots = [found.origin]
    else:
        raise BotLoadError(f"module {top!r} for bot {spec!r} has no files to load")
    parents = sorted({os.path.dirname(os.path.abspath(r)) for r in roots})
    # a namespace package found on sys.path may have portions in several directories: the
    # bot's process finds them all on its own path, as it always has
    home = parents[0] if local or found.origin is not None else None
    return roots, parents, home


def import_top_level(spec, directory):
    """Import the top-level module of the ``module:Class`` bot ``spec`` from exactly
    ``directory`` (the bot's own process does this with ``locate``'s ``search_path``), so that
    it is the very module the match found, wherever the process's own ``sys.path`` would look:
    the current directory of the match, or a ``PYTHONPATH`` entry the bot's clean environment
    does not have. The directory is first on ``sys.path`` while that import runs, and last
    afterwards (so that it shadows nothing the bot imports later, while a namespace package's
    portions, looked up on ``sys.path``, stay found). Raises
    ``BotLoadError`` when the import fails, or when a module of that name is already loaded
    from elsewhere (one the bot's host itself uses)."""
    where, _ = split_spec(spec)
    if is_builtin(spec) or is_file_spec(where):
        return None
    top = where.split(".")[0]
    module = sys.modules.get(top)
    if module is None:
        sys.path.insert(0, directory)
        try:
            module = importlib.import_module(top)
        except ImportError as exc:
            raise BotLoadError(f"cannot import module {top!r} for bot {spec!r} from "
                               f"{directory!r}: {exc}") from exc
        except Exception as exc:
            raise BotLoadError(f"importing {top!r} failed: {type(exc).__name__}: {exc}") from exc
        finally:
            if directory in sys.path:
                sys.path.remove(directory)
            sys.path.append(directory)
    if not _loaded_from(module, directory):
        raise BotLoadError(f"module {top!r} for bot {spec!r} is already loaded from "
                           f"{_module_location(module)!r}, not from {directory!r}: "
                           "give your bot's module another name")
    return module


def _module_location(module):
    """Where a loaded module's code is: its file, or its package directories."""
    file = getattr(module, "__file__", None)
    if file:
        return os.path.abspath(file)
    return ", ".join(os.path.abspath(p) for p in getattr(module, "__path__", ()))


def _loaded_from(module, directory):
    """Whether ``module`` (top-level) was loaded from a file or package in ``directory``
    (for a namespace package: whether one of its portions is there)."""
    directory = os.path.abspath(directory)

    def inside(place):
        return os.path.commonpath([os.path.abspath(place), directory]) == directory

    file = getattr(module, "__file__", None)
    if file:
        return inside(file)
    return any(inside(p) for p in getattr(module, "__path__", ()))


MAX_SOURCE_BYTES = 1 << 20  # a bot's source read for act_batch; a larger one plays as act


def declares_act_batch(spec):
    """Whether the class a bot specification names defines ``act_batch`` in its own body
    (a ``def`` or an assignment at the class's top level), read from its source file without
    running any of it. Such a bot from a file plays all its matches of a pairing in one
    confined process, one call per frame (``spacewar.arena.batch_match``); any other, one match at a
    time. Only the source is read (tokenized: no parser recursion, nothing evaluated), so a
    class that gets ``act_batch`` from a base class or at run time is not seen as one; a
    file that is not a regular file, cannot be read or tokenized (the first error token
    ends the reading: the tokenizer can take time quadratic in a broken line), or is over
    ``MAX_SOURCE_BYTES``, is not either."""
    if not isinstance(spec, str) or is_builtin(spec):
        return False
    try:
        where, class_name = split_spec(spec)
        path = os.path.abspath(where) if is_file_spec(where) else _module_source(where)
    except (BotLoadError, OSError, ImportError, ValueError):
        return False
    if path is None or not path.endswith(".py"):
        return False
    data = _read_source(path)  # None for a FIFO, a device, a directory, an oversized file
    if data is None:
        return False
    try:
        return _class_body_defines(data, class_name, "act_batch")
    except Exception:  # anything the tokenizer or a codec cookie raises: not a batch bot
        return False


def _class_body_defines(source, class_name, attribute):
    """Whether the last top-level ``class class_name`` of ``source`` (bytes) defines
    ``attribute`` at its body's own level (``def attribute``, ``async def attribute``,
    ``attribute = ...``, ``attribute: ... = ...``)."""
    found = False
    depth = 0  # indentation level
    body = None  # the indentation level of the class's body while inside it
    line = []  # the significant tokens of the current logical line so far
    for token in tokenize.tokenize(io.BytesIO(source).readline):
        kind, text = token.type, token.string
        if kind == tokenize.ERRORTOKEN:
            return False  # not Python; going on could take time quadratic in a line
        if kind == tokenize.INDENT:
            depth += 1
            continue
        if kind == tokenize.DEDENT:
            depth -= 1
            if body is not None and depth < body:
                body = None
            continue
        if kind in (tokenize.NEWLINE, tokenize.ENDMARKER):
            if depth == 0 and line[:2] == ["class", class_name]:
                body, found = 1, False  # a later class of that name replaces an earlier one
            elif body is not None and depth == body and _defines(line, attribute):
                found = True
            line = []
            continue
        if kind in (tokenize.NL, tokenize.COMMENT, tokenize.ENCODING):
            continue
        if len(line) < 4:
            line.append(text)
    return found


def _defines(line, attribute):
    if line[:1] == ["async"]:
        line = line[1:]
    return line[:2] == ["def", attribute] or (line[:1] == [attribute] and line[1:2] in
                                              (["="], [":"]))


def _read_source(path):
    """A bot file's bytes (at most ``MAX_SOURCE_BYTES``), or None for anything that is not a
    readable regular file of that size (opened non-blocking: a FIFO is never waited on)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        with os.fdopen(fd, "rb", closefd=False) as f:
            data = f.read(MAX_SOURCE_BYTES + 1)
    except OSError:
        return None
    finally:
        os.close(fd)
    return data if len(data) <= MAX_SOURCE_BYTES else None


def _top_level_classes(source):
    """The names of the top-level ``class`` statements of ``source`` (bytes), in order,
    read with the tokenizer (nothing parsed or run; the first error token ends the reading)."""
    names, depth, line = [], 0, []
    for token in tokenize.tokenize(io.BytesIO(source).readline):
        kind, text = token.type, token.string
        if kind == tokenize.ERRORTOKEN:
            break
        if kind == tokenize.INDENT:
            depth += 1
        elif kind == tokenize.DEDENT:
            depth -= 1
        elif kind in (tokenize.NEWLINE, tokenize.ENDMARKER):
            if depth == 0 and len(line) >= 2 and line[0] == "class" and line[1].isidentifier():
                names.append(line[1])
            line = []
        elif kind not in (tokenize.NL, tokenize.COMMENT, tokenize.ENCODING) and len(line) < 2:
            line.append(text)
    return list(dict.fromkeys(names))


def bots_in(directory):
    """The bots of a directory of submissions: ``(specs, skipped)``.

    ``specs``: ``path/file.py:Class`` for every top-level class of every ``*.py`` file that
    defines ``act`` or ``act_batch`` in its own body, and every ``*.npz`` policy file, sorted
    by path then class. Found by reading the sources with the tokenizer: none of their code
    runs here (a class that gets ``act`` from a base class is not found; name it on the command
    line instead). ``skipped``: ``{path: reason}`` for the ``*.py`` files with no such class, or
    that cannot be read (not a regular file, over ``MAX_SOURCE_BYTES``, not Python)."""
    if not os.path.isdir(directory):
        raise BotLoadError(f"bots directory {directory!r} is not a directory")
    specs, skipped = [], {}
    for name in sorted(os.listdir(directory)):
        path = os.path.join(directory, name)
        if name.lower().endswith(".npz") and os.path.isfile(path):
            specs.append(path)
            continue
        if not name.endswith(".py") or name.startswith("."):
            continue
        source = _read_source(path)
        if source is None:
            skipped[path] = f"not a regular file of at most {MAX_SOURCE_BYTES} bytes"
            continue
        try:
            found = [c for c in _top_level_classes(source)
                     if _class_body_defines(source, c, "act")
                     or _class_body_defines(source, c, "act_batch")]
        except Exception as exc:  # whatever the tokenizer or a codec cookie raises
            skipped[path] = f"cannot be read as Python ({type(exc).__name__})"
            continue
        if not found:
            skipped[path] = "no top-level class defining act or act_batch"
        specs += [f"{path}:{c}" for c in found]
    return specs, skipped


def _module_source(where):
    """The source file of module ``where`` (dotted), found as ``locate`` finds it, without
    importing anything."""
    parts = where.split(".")
    if not all(part.isidentifier() for part in parts):
        return None
    found = importlib.machinery.PathFinder.find_spec(parts[0], [os.getcwd()])
    if found is None:
        found = importlib.util.find_spec(parts[0])
    for part in parts[1:]:
        if found is None or not found.submodule_search_locations:
            return None
        found = importlib.machinery.PathFinder.find_spec(part,
                                                         list(found.submodule_search_locations))
    return None if found is None else found.origin


def check_one_spelling_each(specs):
    """Raise ``BotLoadError`` naming both spellings when two of ``specs`` name the same bot
    (``bot_identity``): ``a.py:X``, ``./a.py:X``, its absolute path, a symlink or a hard link
    to it are one entrant, who would otherwise enter twice. Two files with the same bytes
    (twins) are two entrants, and so are two classes of one file."""
    seen = {}
    for spec in specs:
        identity, shown = bot_identity(spec)
        if identity in seen:
            raise BotLoadError(f"each bot may enter once: {seen[identity]!r} and {spec!r} are "
                               f"the same bot ({shown})")
        seen[identity] = spec


def bot_identity(spec):
    """``(identity, description)`` of the bot ``spec`` names, whatever its spelling: for a
    bot from a file (a policy file, or a module found as a source file) the file itself, by
    device and inode, and the class; otherwise its ``module:Class`` (a built-in name is its
    module spelled out). Nothing is imported or run."""
    if is_policy_file(spec):
        path, class_name = spec, None
    else:
        where, class_name = split_spec(spec)
        target = BUILTIN.get(spec, spec)
        try:
            path = where if is_file_spec(where) else _module_source(target.rsplit(":", 1)[0])
        except (ImportError, ValueError):
            path = None
        if path is None:
            return ("module", target), target
    try:
        info = os.stat(path)
    except (OSError, ValueError):
        return ("path", os.path.abspath(path), class_name), absolute_spec(spec)
    shown = f"file {os.path.realpath(path)!r}" + ("" if class_name is None
                                                 else f", class {class_name!r}")
    return ("file", info.st_dev, info.st_ino, class_name), shown


def absolute_spec(spec):
    """``spec`` with a bot file's path made absolute (a bot's process starts elsewhere)."""
    if is_policy_file(spec):
        return os.path.abspath(spec)
    where, class_name = split_spec(spec)
    if not is_builtin(spec) and is_file_spec(where):
        return f"{os.path.abspath(where)}:{class_name}"
    return spec


def _import_from_file(path, class_name):
    if not os.path.isfile(path):
        raise BotLoadError(f"bot file {path!r} does not exist")
    module_name = "spacewar_user_bot_" + str(abs(hash(os.path.abspath(path))))
    module = sys.modules.get(module_name)
    if module is None:
        spec = importlib.util.spec_from_file_location(module_name, path)
        if spec is None or spec.loader is None:
            raise BotLoadError(f"cannot import bot file {path!r}")
        module = importlib.util.module_from_spec(spec)
        sys.modules[module_name] = module
        try:
            spec.loader.exec_module(module)
        except Exception as exc:
            del sys.modules[module_name]
            raise BotLoadError(f"importing {path!r} failed: {type(exc).__name__}: {exc}") from exc
    return getattr(module, class_name, None), path


def load_bot_class(spec):
    """The bot class named by ``spec`` (a built-in name, ``module:Class`` or ``file.py:Class``)."""
    where, class_name = split_spec(spec)
    if is_file_spec(where):
        cls, origin = _import_from_file(where, class_name)
    else:
        try:
            module = importlib.import_module(where)
        except ImportError as exc:
            raise BotLoadError(f"cannot import module {where!r} for bot {spec!r}: {exc}") from exc
        except Exception as exc:
            raise BotLoadError(f"importing {where!r} failed: {type(exc).__name__}: {exc}") from exc
        cls, origin = getattr(module, class_name, None), where
    if cls is None:
        raise BotLoadError(f"{origin!r} has no class {class_name!r}")
    if not callable(getattr(cls, "act", None)) and not callable(getattr(cls, "act_batch", None)):
        raise BotLoadError(f"{spec!r} is not a bot: it has neither act(self, obs) nor "
                           "act_batch(self, obs) (spacewar.bots.batch)")
    return cls


def make_bot(spec, seed=None):
    """An instance of the bot ``spec``, given ``seed`` if its constructor takes one."""
    if is_policy_file(spec):
        from spacewar.bots.policy import PolicyBot, PolicyError

        try:
            return PolicyBot(spec, seed=seed)
        except PolicyError as exc:
            raise BotLoadError(str(exc)) from None
    cls = load_bot_class(spec)
    try:
        params = inspect.signature(cls).parameters
    except (TypeError, ValueError):
        params = {}
    try:
        if "seed" in params:
            return cls(seed=seed)
        return cls()
    except Exception as exc:
        raise BotLoadError(f"creating bot {spec!r} failed: {type(exc).__name__}: {exc}") from exc
