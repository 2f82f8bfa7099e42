"""Landlock (Linux 5.13+): a process takes away its own rights to files, TCP and signals.

The kernel's interface is three system calls (``landlock_create_ruleset``,
``landlock_add_rule``, ``landlock_restrict_self``; see the kernel's
Documentation/userspace-api/landlock.rst and landlock(7)). A ruleset names the rights it
*handles*; once the process restricts itself, every handled right is denied except where a
rule grants it beneath a directory, and the restriction is inherited and cannot be undone.
Each ABI version adds rights: 2 file renames across directories (REFER), 3 truncation, 4 TCP
bind and connect, 5 device ioctls, 6 scopes (abstract UNIX sockets and signals to processes
outside the domain).

Called through ctypes: the one PyPI binding is a pre-release that covers file rights only, and
the bot sandbox needs the TCP and scope rights too.
"""
import ctypes
import os

# system call numbers: the same on every architecture (added after the syscall table unification)
_CREATE_RULESET, _ADD_RULE, _RESTRICT_SELF = 444, 445, 446
_CREATE_RULESET_VERSION = 1
_RULE_PATH_BENEATH = 1
_PR_SET_NO_NEW_PRIVS = 38

# file-system rights, by the ABI version that introduced them
EXECUTE, WRITE_FILE, READ_FILE, READ_DIR = 1 << 0, 1 << 1, 1 << 2, 1 << 3
REMOVE_DIR, REMOVE_FILE, MAKE_CHAR, MAKE_DIR = 1 << 4, 1 << 5, 1 << 6, 1 << 7
MAKE_REG, MAKE_SOCK, MAKE_FIFO, MAKE_BLOCK, MAKE_SYM = 1 << 8, 1 << 9, 1 << 10, 1 << 11, 1 << 12
REFER, TRUNCATE, IOCTL_DEV = 1 << 13, 1 << 14, 1 << 15
_FS_BY_ABI = {1: (1 << 13) - 1, 2: (1 << 14) - 1, 3: (1 << 15) - 1, 5: (1 << 16) - 1}
# network rights (ABI 4) and scopes (ABI 6)
NET_BIND_TCP, NET_CONNECT_TCP = 1 << 0, 1 << 1
SCOPE_ABSTRACT_UNIX_SOCKET, SCOPE_SIGNAL = 1 << 0, 1 << 1

READ_ONLY_DIR = EXECUTE | READ_FILE | READ_DIR
READ_ONLY_FILE = EXECUTE | READ_FILE
FILE_RIGHTS = EXECUTE | WRITE_FILE | READ_FILE | TRUNCATE | IOCTL_DEV  # the rights a file can hold


class _RulesetAttr(ctypes.Structure):
    _fields_ = [("handled_access_fs", ctypes.c_uint64), ("handled_access_net", ctypes.c_uint64),
                ("scoped", ctypes.c_uint64)]


class _PathBeneathAttr(ctypes.Structure):
    _pack_ = 1
    _fields_ = [("allowed_access", ctypes.c_uint64), ("parent_fd", ctypes.c_int32)]


def _libc():
    return ctypes.CDLL(None, use_errno=True)


def abi_version():
    """The kernel's Landlock ABI version, or 0 where there is no Landlock."""
    try:
        version = _libc().syscall(_CREATE_RULESET, None, ctypes.c_size_t(0),
                                  ctypes.c_uint32(_CREATE_RULESET_VERSION))
    except (OSError, AttributeError):
        return 0
    return max(int(version), 0)


def fs_rights(abi):
    """Every file-system right the ABI version knows."""
    return _FS_BY_ABI[max(v for v in _FS_BY_ABI if v <= abi)]


def restrict(read_dirs=(), read_files=(), list_dirs=(), write_dirs=(), write_files=()):
    """Restrict this process (and all it starts) to the given paths; return the ABI used.

    ``read_dirs``: read and execute beneath; ``read_files``: read and execute that file;
    ``list_dirs``: list the directory (not read its files); ``write_dirs``: everything beneath;
    ``write_files``: read and write that file (e.g. /dev/null). All TCP is denied from ABI 4
    on, signals and abstract UNIX sockets beyond this domain from ABI 6 on. Paths that do not
    exist are skipped. Raises ``OSError`` if the kernel refuses.
    """
    abi = abi_version()
    if abi < 1:
        raise OSError("Landlock is not available in this kernel")
    libc = _libc()
    handled = fs_rights(abi)
    attr = _RulesetAttr(handled_access_fs=handled,
                        handled_access_net=(NET_BIND_TCP | NET_CONNECT_TCP) if abi >= 4 else 0,
                        scoped=(SCOPE_ABSTRACT_UNIX_SOCKET | SCOPE_SIGNAL) if abi >= 6 else 0)
    size = 8 if abi < 4 else (16 if abi < 6 else 24)
    ruleset = libc.syscall(_CREATE_RULESET, ctypes.byref(attr), ctypes.c_size_t(size),
                           ctypes.c_uint32(0))
    if ruleset < 0:
        raise OSError(ctypes.get_errno(), "landlock_create_ruleset failed")
    try:
        grants = [(p, READ_ONLY_DIR) for p in read_dirs] + [(p, READ_ONLY_FILE) for p in read_files]
        grants += [(p, READ_DIR) for p in list_dirs] + [(p, handled) for p in write_dirs]
        grants += [(p, READ_FILE | WRITE_FILE | TRUNCATE | IOCTL_DEV) for p in write_files]
        for path, rights in grants:
            _grant(libc, ruleset, path, rights & handled)
        if libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_NO_NEW_PRIVS) failed")
        if libc.syscall(_RESTRICT_SELF, ruleset, ctypes.c_uint32(0)) != 0:
            raise OSError(ctypes.get_errno(), "landlock_restrict_self failed")
    finally:
        os.close(ruleset)
    return abi


def _grant(libc, ruleset, path, rights):
    try:
        fd = os.open(path, os.O_PATH | os.O_CLOEXEC)
    except OSError:
        return  # a path this machine does not have
    try:
        if not os.path.isdir(path):
            rights &= FILE_RIGHTS
        rule = _PathBeneathAttr(allowed_access=rights, parent_fd=fd)
        if libc.syscall(_ADD_RULE, ruleset, ctypes.c_int(_RULE_PATH_BENEATH), ctypes.byref(rule),
                        ctypes.c_uint32(0)) != 0:
            raise OSError(ctypes.get_errno(), f"landlock_add_rule failed for {path!r}")
    finally:
        os.close(fd)
