"""Confinement of a bot's process, with what the operating system gives.

Two halves. The match side (``launch_prefix``) starts the bot host under util-linux's
``unshare`` when this machine allows it: a new user namespace (the bot holds no capability
outside it), PID namespace (it sees and can signal only its own processes, and when its first
process dies the kernel kills every other one), network namespace (no interface but a downed
loopback), IPC, UTS and mount namespaces with a private /proc. ``--kill-child`` and a
parent-death signal (``PR_SET_PDEATHSIG``) tie the whole tree to the match process: if the
match dies, so does the bot, whatever it started.

The bot side (``confine``), run by ``spacewar.sandbox.bothost`` before the bot's module is imported:

- a size-limited tmpfs as its only writable directory (inside its mount namespace);
- resource limits (``setrlimit``): address space, CPU seconds, open files, file size, no core
  files, and one process (``RLIMIT_NPROC``: no fork, no thread);
- Landlock: reads only beneath the Python installation, the project's packages, shared
  libraries and the bot's own files; writes only in the scratch directory; no TCP; no signal
  or abstract UNIX socket beyond its own domain;
- seccomp (through ``pyseccomp``, a binding to libseccomp): ``socket``, process creation,
  ``ptrace`` and the other calls a bot never needs fail with EPERM;
- every capability dropped (bounding set, effective, permitted, inheritable) and
  ``no_new_privs`` set.

Each layer is applied where the machine has it and reported by name; ``spacewar sandbox``
prints which ones hold here (``docs/game.md``, "Running untrusted bots").
"""
import ctypes
import errno
import functools
import os
import resource
import shutil
import signal
import subprocess
import sys

UNSHARE_FLAGS = ("--user", "--map-root-user", "--pid", "--fork", "--kill-child", "--net",
                 "--ipc", "--uts", "--mount-proc")
_PR_SET_PDEATHSIG, _PR_CAPBSET_DROP = 1, 24
_MS_NOSUID, _MS_NODEV, _MS_NOEXEC = 2, 4, 8
_SCRATCH_INODES = 4096  # files and directories a bot's scratch tmpfs may hold
_PAGE = 4096  # bytes of the smallest piece of a tmpfs a file takes

#: system calls a bot never needs (each fails with EPERM); missing ones on an arch are skipped
DENIED_SYSCALLS = (
    "socket", "fork", "vfork", "clone", "clone3", "execve", "execveat", "ptrace", "process_vm_readv",
    "process_vm_writev", "kcmp", "pidfd_open", "pidfd_getfd", "pidfd_send_signal", "bpf",
    "perf_event_open", "userfaultfd", "io_uring_setup", "io_uring_enter", "io_uring_register",
    "mount", "umount2", "move_mount", "fsopen", "fsmount", "open_tree", "pivot_root", "chroot",
    "unshare", "setns", "keyctl", "add_key", "request_key", "init_module", "finit_module",
    "delete_module", "kexec_load", "kexec_file_load", "reboot", "swapon", "swapoff", "acct",
    "quotactl", "mknod", "mknodat", "setuid", "setgid", "setreuid", "setregid", "setresuid",
    "setresgid", "setgroups",
    # leaving its session or process group
    "setsid", "setpgid",
    # metadata, which Landlock does not cover: a bot holding root's user id would own every file
    "chmod", "fchmod", "fchmodat", "fchmodat2", "chown", "fchown", "lchown", "fchownat",
    "utime", "utimes", "utimensat", "futimesat", "setxattr", "lsetxattr", "fsetxattr",
    "removexattr", "lremovexattr", "fremovexattr",
    # growing a file past RLIMIT_FSIZE (FALLOC_FL_KEEP_SIZE), watching directories it cannot read
    "fallocate", "inotify_init", "inotify_init1", "inotify_add_watch", "fanotify_init",
    "fanotify_mark", "flock",
    # System V IPC: detached shared memory escapes RLIMIT_AS
    "shmget", "shmat", "shmdt", "shmctl", "msgget", "msgsnd", "msgrcv", "msgctl", "semget",
    "semop", "semtimedop", "semctl", "ipc",
)
#: prctl options a bot may not use: clearing its parent-death signal would let it outlive the match
DENIED_PRCTL = (_PR_SET_PDEATHSIG,)
#: ioctl types (the request's second byte) refused whole: the file-system ioctls ('f': inode
#: flags, fs-verity, encryption policies; 'v': inode versions; 'X': FS_IOC_FSSETXATTR, freeze;
#: 0x94: clone and dedupe ranges), which neither Landlock nor permissions stop for a file's
#: owner; a terminal's 'T' ioctls (isatty) stay allowed
DENIED_IOCTL_TYPES = (0x66, 0x76, 0x58, 0x94)
#: fcntl commands that lock or lease files or watch directories (F_SETLK, F_SETLKW,
#: F_OFD_SETLK, F_OFD_SETLKW, F_SETLEASE, F_NOTIFY): they would hold up other processes
DENIED_FCNTL = (6, 7, 37, 38, 1024, 1026)


# -- the match's side ------------------------------------------------------------------------
NOBODY = 65534  # the unprivileged user a bot runs as when the match was started by root


def _works(command):
    try:
        done = subprocess.run(command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, timeout=20)
    except (OSError, subprocess.SubprocessError):
        return False
    return done.returncode == 0


def _as_nobody():
    # a change of user clears the parent-death signal: --pdeathsig sets it again afterwards
    return [shutil.which("setpriv"), f"--reuid={NOBODY}", f"--regid={NOBODY}", "--clear-groups",
            "--pdeathsig=KILL", "--"]


def _unshare():
    return [shutil.which("unshare"), *UNSHARE_FLAGS, "--"]


@functools.lru_cache(maxsize=None)
def launch_plan():
    """How a bot is started here: ``(prefix words, user, namespaces)``, found once by trying.

    Started by root, a bot runs as ``nobody`` when that user can run this Python and read the
    project (root ignores some limits and owns files); otherwise it keeps root's user id
    outside its user namespace, with no capability at all. It gets its namespaces wherever
    ``unshare`` may create them.
    """
    if not sys.platform.startswith("linux") or shutil.which("unshare") is None:
        return (), None, False
    check = [sys.executable, "-s", "-B", "-c", "import numpy, spacewar.sandbox.bothost"]
    nobody = (os.geteuid() == 0 and shutil.which("setpriv") is not None
              and _works(_as_nobody() + check))
    plans = []
    if nobody:
        plans += [(_as_nobody() + _unshare(), "nobody", True)]
    plans += [(_unshare(), "root" if os.geteuid() == 0 else "caller", True)]
    if nobody:
        plans += [(_as_nobody(), "nobody", False)]
    for prefix, user, namespaces in plans:
        if _works(prefix + check):
            return tuple(prefix), user, namespaces
    return (), "root" if os.geteuid() == 0 else "caller", False


def namespace_init():
    """The trusted first process of a bot's PID namespace: ``sh`` starting the bot host and
    waiting for it. The bot cannot touch it, and when it dies (its parent-death signal, set by
    ``unshare --kill-child``) the kernel kills everything in the namespace."""
    if not namespaces_available() or not os.path.exists("/bin/sh"):
        return []
    return ["/bin/sh", "-c", '"$@" & wait $!', "sh"]


def namespaces_available():
    """Whether a bot gets its own user, PID, network, IPC, UTS and mount namespaces here."""
    return launch_plan()[2]


def launch_prefix():
    """The command words that start a bot host (as nobody, in namespaces) where possible."""
    return list(launch_plan()[0])


def bot_uid():
    """The user id a bot's files must belong to (None: the caller's own)."""
    return NOBODY if launch_plan()[1] == "nobody" else None


def die_with_parent():
    """``preexec_fn`` for the bot's first process: SIGKILL it when the match's thread dies."""
    parent = os.getppid()
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:  # the parent died before the death signal was armed
        os._exit(1)


# -- the bot's side --------------------------------------------------------------------------
def confine(config):
    """Apply every layer this machine has, in the order each needs; return their names.

    A layer the machine offers but that cannot be applied (Landlock refused, a seccomp filter
    that does not load) raises: the bot then does not start, rather than start less confined.
    ``config`` keys: ``scratch`` (directory), ``scratch_mb``, ``memory_mb``, ``cpu_seconds``,
    ``max_files``, ``file_mb``, ``read_dirs``, ``read_files``, ``list_dirs``,
    ``namespaces`` (whether the launcher gave namespaces).
    """
    layers = []
    libc = ctypes.CDLL(None, use_errno=True) if sys.platform.startswith("linux") else None
    # first of all: finding libseccomp runs ldconfig, which the limits and Landlock forbid
    seccomp = _load_seccomp() if libc is not None else None
    if libc is not None:
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        layers.append("parent-death signal")
    if config.get("user") == "nobody":
        layers.append(f"user nobody ({os.getuid()} here, {NOBODY} outside)")
    elif config.get("user") == "root":
        layers.append("root's user id outside its namespace (nobody could not start this Python in one)")
    if config.get("namespaces"):
        layers.append("namespaces (user, pid, net, ipc, uts, mount)")
        if _mount_scratch(libc, config["scratch"], config["scratch_mb"]):
            layers.append(f"scratch tmpfs {config['scratch_mb']} MiB")
    _copy_compiled_code(config.get("numba_cache"), config["scratch"],
                        budget_bytes=int(config["scratch_mb"]) * (1 << 20) // 2,
                        budget_files=_SCRATCH_INODES // 4)
    os.chdir(config["scratch"])
    _limit_resources(config)
    layers.append("rlimits")
    if libc is not None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # an over-long write fails, not the bot
        _drop_bounding_set(libc)
        from spacewar.sandbox import landlock

        if landlock.abi_version() >= 1:  # offered by the kernel: it must hold, or no bot runs
            abi = landlock.restrict(read_dirs=config["read_dirs"],
                                    read_files=config["read_files"],
                                    list_dirs=config["list_dirs"],
                                    write_dirs=[config["scratch"]],
                                    write_files=["/dev/null"])
            layers.append(f"landlock abi {abi}")
        if seccomp is not None:
            _seccomp(seccomp)  # libseccomp is here: its filter must load, or no bot runs
            layers.append("seccomp")
        if _drop_capabilities(libc):
            layers.append("no capabilities")
    return layers


def _copy_compiled_code(pairs, scratch, budget_bytes, budget_files):
    """A copy of this checkout's compiled game and engine code in the scratch directory
    (numba loads its cache only from a writable directory), so a bot using the game's or the
    engine's kernels does not compile them.

    ``pairs`` are ``(source directory, destination relative to scratch/numba)``, or with a
    third item the modules whose files to copy (numba names each file after its module: the
    others are code of modules since moved or removed). A directory is copied whole or not at
    all, and only while the copies stay within the budgets (a
    share of the scratch tmpfs's bytes and inodes: the bot's own files need the rest). Each
    file is written under a temporary name and renamed, data files before the index: a copy
    cut short by a full disk leaves no truncated file for numba to trip over (an index entry
    whose data file is missing only means a compile)."""
    used_bytes = used_files = 0
    for source, relative, *modules in pairs or ():
        try:
            names = sorted(os.listdir(source), key=lambda n: (n.endswith(".nbi"), n))
            if modules:
                names = [n for n in names if n.split(".", 1)[0] in modules[0]]
            # a tmpfs charges whole pages: count each file's size rounded up to one
            size = sum(-(-os.path.getsize(os.path.join(source, n)) // _PAGE) * _PAGE
                       for n in names)
        except OSError:
            continue
        if used_bytes + size > budget_bytes or used_files + len(names) + 1 > budget_files:
            continue
        used_bytes, used_files = used_bytes + size, used_files + len(names) + 1
        target = os.path.join(scratch, "numba", relative)
        try:
            os.makedirs(target, exist_ok=True)
            for name in names:
                _copy_whole(os.path.join(source, name), os.path.join(target, name))
        except OSError:
            return  # no room after all: the bot compiles what it uses


def _copy_whole(source, target):
    part = target + ".part"
    try:
        shutil.copyfile(source, part)
        os.replace(part, target)
    except OSError:
        try:
            os.unlink(part)
        except OSError:
            pass
        raise


def _mount_scratch(libc, path, size_mb):
    """A private tmpfs over the scratch directory: bounded in size and inodes, no exec."""
    options = f"size={int(size_mb)}m,nr_inodes={_SCRATCH_INODES},mode=0700".encode()
    flags = _MS_NOSUID | _MS_NODEV | _MS_NOEXEC
    return libc.mount(b"tmpfs", os.fsencode(path), b"tmpfs", flags, options) == 0


def _limit_resources(config):
    mib = 1 << 20
    limits = [(resource.RLIMIT_AS, int(config["memory_mb"]) * mib),
              (resource.RLIMIT_FSIZE, int(config["file_mb"]) * mib),
              (resource.RLIMIT_CORE, 0),
              (resource.RLIMIT_NOFILE, int(config["max_files"]))]
    if hasattr(resource, "RLIMIT_NPROC"):
        limits.append((resource.RLIMIT_NPROC, 1))
    for which, value in limits:
        _lower(which, value, value)
    cpu = int(config["cpu_seconds"])
    _lower(resource.RLIMIT_CPU, cpu, cpu + 1)  # SIGXCPU at the soft limit, SIGKILL a second later


def _lower(which, soft, hard):
    old_soft, old_hard = resource.getrlimit(which)
    if old_hard != resource.RLIM_INFINITY:
        hard = min(hard, old_hard)
    resource.setrlimit(which, (min(soft, hard), hard))


def _drop_bounding_set(libc):
    for cap in range(64):
        if libc.prctl(_PR_CAPBSET_DROP, cap, 0, 0, 0) != 0 and ctypes.get_errno() == errno.EINVAL:
            break  # past the last capability this kernel knows


class _CapHeader(ctypes.Structure):
    _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]


class _CapData(ctypes.Structure):
    _fields_ = [("effective", ctypes.c_uint32), ("permitted", ctypes.c_uint32),
                ("inheritable", ctypes.c_uint32)]


def _drop_capabilities(libc):
    header = _CapHeader(version=0x20080522, pid=0)  # _LINUX_CAPABILITY_VERSION_3
    data = (_CapData * 2)()
    return libc.capset(ctypes.byref(header), data) == 0


def _load_seccomp():
    """The ``pyseccomp`` module with libseccomp loaded, or None where either is missing."""
    try:
        import pyseccomp

        pyseccomp.SyscallFilter(pyseccomp.ALLOW)
    except (ImportError, RuntimeError, OSError, AttributeError):
        return None
    return pyseccomp


def _seccomp(pyseccomp):
    """Load the filter; raises OSError if it cannot be loaded."""
    try:
        rules = pyseccomp.SyscallFilter(pyseccomp.ALLOW)
        for name in DENIED_SYSCALLS:
            try:
                rules.add_rule(pyseccomp.ERRNO(errno.EPERM), name)
            except (RuntimeError, ValueError, OSError):
                continue  # not a system call on this architecture
        # the kernel reads these arguments as 32-bit ints: compare the low 32 bits only, or
        # prctl(0x100000001, 0) would pass as an option that is not PR_SET_PDEATHSIG
        low = 0xFFFFFFFF
        denied = [("prctl", 0, low, v) for v in DENIED_PRCTL]
        denied += [("ioctl", 1, 0xFF00, t << 8) for t in DENIED_IOCTL_TYPES]
        denied += [(call, 1, low, v) for call in ("fcntl", "fcntl64") for v in DENIED_FCNTL]
        for call, arg, mask, value in denied:
            try:
                rules.add_rule(pyseccomp.ERRNO(errno.EPERM), call,
                               pyseccomp.Arg(arg, pyseccomp.MASKED_EQ, mask, value))
            except (RuntimeError, ValueError, OSError):
                continue  # fcntl64 exists on 32-bit architectures only
        rules.load()
    except (RuntimeError, AttributeError) as exc:
        raise OSError(f"the seccomp filter could not be loaded: {exc}") from exc


def read_paths(extra_dirs=(), extra_files=()):
    """What a bot may read: the interpreter and its libraries, the project's packages, the
    system's shared libraries, then the bot's own files (``extra_*``)."""
    dirs, files = _installed_read_paths()
    return (sorted(d for d in {*dirs, *extra_dirs} if d),
            sorted({*files, *extra_files}))


@functools.lru_cache(maxsize=None)
def _installed_read_paths():
    """The part of ``read_paths`` that is the same for every bot (found once)."""
    import site
    import sysconfig

    import numpy

    import engine

    # the interpreter's own library directories, not its whole prefix (for a system Python
    # that would be all of /usr), and the executable itself
    dirs = {os.path.join(prefix, lib) for prefix in {sys.base_prefix, sys.exec_prefix}
            for lib in ("lib", "lib64")}
    dirs |= {sys.prefix, os.path.dirname(os.path.dirname(numpy.__file__))}
    paths = sysconfig.get_paths()
    dirs.update(paths[key] for key in ("stdlib", "platstdlib", "purelib", "platlib"))
    try:
        dirs.update(site.getsitepackages())
    except AttributeError:
        pass
    project = os.path.dirname(os.path.dirname(os.path.abspath(engine.__file__)))
    for package in ("engine", "spacewar"):  # what the bot's host imports, and the cache hashes
        dirs.add(os.path.join(project, package))
    dirs.update(("/lib", "/lib64", "/usr/lib", "/usr/lib64", "/usr/local/lib",
                 "/sys/devices/system/cpu"))
    files = {os.path.realpath(sys.executable), "/etc/ld.so.cache", "/dev/urandom",
             "/dev/random", "/dev/zero"}
    return frozenset(dirs), frozenset(files)
