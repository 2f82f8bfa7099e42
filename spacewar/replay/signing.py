"""Replays signed with a per-user key (HMAC-SHA256): where the key lives, ``sign`` and
``signature_status``."""
import hashlib
import hmac
import os
import secrets

from spacewar.replay.format import DIGEST_FIELD, ReplayError, canonical_json

SIGNATURE_FIELD = "signature"


def key_path():
    """The file of this user's replay-signing key: ``$SPACEWAR_REPLAY_KEY_FILE``, else
    ``$XDG_CONFIG_HOME/spacewar/replay-key`` (``~/.config``)."""
    explicit = os.environ.get("SPACEWAR_REPLAY_KEY_FILE")
    if explicit:
        return explicit
    base = os.environ.get("XDG_CONFIG_HOME") or os.path.join(os.path.expanduser("~"), ".config")
    return os.path.join(base, "spacewar", "replay-key")


def _key(create):
    """This user's 32-byte signing key (made on first use, mode 0600), or None."""
    path = key_path()
    try:
        with open(path) as f:
            return bytes.fromhex(f.read().strip())
    except FileNotFoundError:
        if not create:
            return None
    except (OSError, ValueError) as exc:
        raise ReplayError(f"the replay-signing key {path!r} is unreadable: {exc}") from None
    os.makedirs(os.path.dirname(path) or ".", mode=0o700, exist_ok=True)
    key = secrets.token_bytes(32)
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except FileExistsError:  # made meanwhile by another process: use that one
        return _key(create=False)
    with os.fdopen(fd, "w") as f:
        f.write(key.hex() + "\n")
    return key


def _key_id(key):
    return hashlib.sha256(b"spacewar replay key " + key).hexdigest()[:16]


def _mac(key, replay):
    body = {k: v for k, v in replay.items() if k not in (DIGEST_FIELD, SIGNATURE_FIELD)}
    return hmac.new(key, canonical_json(body).encode("ascii"), hashlib.sha256).hexdigest()


def sign(document):
    """The ``signature`` field for ``document`` (a dict of plain JSON data: a replay, or a
    league's results file; its own ``signature`` and ``content_sha256`` fields are left out):
    an HMAC-SHA256 of its canonical JSON with this user's key (``key_path()``, made on first
    use). ``signature_status`` checks it. TypeError or ValueError if it is not plain data."""
    key = _key(create=True)
    return {"key": _key_id(key), "hmac_sha256": _mac(key, document)}


def signature_status(replay):
    """``"verified"`` (signed with this user's key and unchanged since), ``"unsigned"``,
    ``"other key"`` (signed elsewhere: cannot be verified here) or ``"forged"``, for a replay
    or any document signed by ``sign``.

    The content digest catches accidents, but anyone can recompute it; the signature is an
    HMAC-SHA256 with a key only its owner has, so records the simulation cannot re-derive
    (which bot sat where, the fault record) are trustworthy only when it verifies.
    """
    sig = replay.get(SIGNATURE_FIELD)
    if sig is None:
        return "unsigned"
    if not isinstance(sig, dict) or not isinstance(sig.get("key"), str) \
            or not _is_hex_digest(sig.get("hmac_sha256")):
        return "forged"
    key = _key(create=False)
    if key is None or sig["key"] != _key_id(key):
        return "other key"
    return "verified" if hmac.compare_digest(sig["hmac_sha256"], _mac(key, replay)) else "forged"


def _is_hex_digest(value):
    """Whether ``value`` is a SHA-256 digest as ``_mac`` writes it: 64 lowercase hex digits
    (anything else cannot be ours, and ``hmac.compare_digest`` refuses non-ASCII text)."""
    return isinstance(value, str) and len(value) == 64 \
        and all(c in "0123456789abcdef" for c in value)
