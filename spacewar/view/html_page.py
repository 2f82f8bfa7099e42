"""A self-contained HTML page: its scripts and styles inline, its data in the page, and a
Content-Security-Policy that lets it load nothing at all from anywhere, not even its own
inline code unless that code is the one it was written with.

Every page the project writes (the replay player, the league and tournament pages) is built
here, so each holds to the same rules:

- **Nothing from the network.** The policy is ``default-src 'none'``: no script, style, image,
  font, frame or connection from any address; the page's own ``<script>`` and ``<style>``
  elements run only because their SHA-256 hashes are listed (``script-src 'sha256-...'``,
  never ``'unsafe-inline'``: a script an attacker managed to put into the page has another
  hash and does not run). Images only from ``data:`` URLs (none are needed today). A page
  opened from a file or any static server works, because it fetches nothing: a browser
  refuses ``fetch()`` from ``file://``, so the data rides inside the page.
- **Strangers' text is data.** Bot names, module paths, fault messages and bot output are
  written into the page only (a) as escaped HTML text (``text``), or (b) inside a JSON data
  block (``data_block``: ``<script type="application/json">``, which a browser never runs)
  with ``<``, ``>``, ``&`` and the two JavaScript line separators escaped, so that no string
  can close the block; the page's script puts them on screen with ``textContent`` (never
  ``innerHTML``) or on a canvas with ``fillText``, where no text is markup.
- **Written whole or not at all** (``write_page``: ``engine.atomic``), and the path checked
  before any work (``check_page_path``).

The policy (W3C, "Content Security Policy Level 3", hash sources); the JSON escaping follows
the HTML standard's rules for the content of a ``script`` element ("restrictions for contents
of script elements": no ``</script`` and no ``<!--`` inside).
"""
import base64
import hashlib
import html
import json

from engine.atomic import atomic_write, check_output_path

from spacewar.faults import printable

#: the page's text encoding (declared in the page and used to hash its inline code)
ENCODING = "utf-8"


def text(value):
    """``value`` as HTML text: ``& < > " '`` escaped, so it is shown, never parsed as markup."""
    return html.escape(str(value), quote=True)


#: characters that print as nothing though they are letters or symbols (a blank Braille
#: pattern, the Hangul fillers, the Mongolian vowel separator): shown escaped, so a name
#: cannot push a score out of sight with them
BLANK_LOOKING = frozenset("\u2800\u115f\u1160\u3164\uffa0\u180e")
#: the most characters of a stranger's name shown where it shares a line with other facts
NAME_CHARACTERS = 48
FIRST_STRONG_ISOLATE, POP_DIRECTORY_ISOLATE = "\u2068", "\u2069"


def visible(value):
    """``value`` with every character that would not show as itself escaped: controls and
    format characters (``spacewar.faults.printable``) and the blank-looking ones."""
    return "".join(f"\\u{ord(c):04x}" if c in BLANK_LOOKING else c
                   for c in printable(str(value)))


def display_name(name, limit=NAME_CHARACTERS):
    """A stranger's name as a page shows it among other text: control, format and
    blank-looking characters escaped (``spacewar.faults.printable``), cut to ``limit``
    characters (an ellipsis marks the cut), and isolated with U+2068 ... U+2069 (Unicode
    Bidirectional Algorithm, UAX #9, "isolates"), so that right-to-left letters in it cannot
    reorder the score or the other name beside it."""
    pieces = [visible(c) for c in str(name)]  # an escape stays whole: a name is cut between
    if sum(map(len, pieces)) > limit:
        kept, used = [], 0
        for piece in pieces:
            if used + len(piece) > limit - 1:
                break
            kept.append(piece)
            used += len(piece)
        pieces = kept + ["\u2026"]
    shown = "".join(pieces)
    return FIRST_STRONG_ISOLATE + shown + POP_DIRECTORY_ISOLATE


def source_hash(code):
    """The CSP hash source of an inline script's or style's exact text: ``'sha256-<base64>'``."""
    digest = hashlib.sha256(code.encode(ENCODING)).digest()
    return "'sha256-" + base64.b64encode(digest).decode("ascii") + "'"


def json_text(value):
    """``value`` as JSON that may sit inside a ``<script type="application/json">`` element:
    ``<``, ``>`` and ``&`` as ``\\u003c`` ``\\u003e`` ``\\u0026`` (so no ``</script>`` or
    ``<!--`` can appear), and U+2028, U+2029 escaped; ``JSON.parse`` reads it back unchanged.
    NaN and infinities are refused (JSON has none)."""
    raw = json.dumps(value, ensure_ascii=False, allow_nan=False, separators=(",", ":"))
    for char, escaped in (("&", "\\u0026"), ("<", "\\u003c"), (">", "\\u003e"),
                          ("\u2028", "\\u2028"), ("\u2029", "\\u2029")):
        raw = raw.replace(char, escaped)
    return raw


def data_block(element_id, value):
    """A JSON data block the page's script reads with
    ``JSON.parse(document.getElementById(element_id).textContent)``."""
    return (f'<script type="application/json" id="{text(element_id)}">'
            f"{json_text(value)}</script>")


def policy(scripts, styles):
    """The Content-Security-Policy of a page whose only code is ``scripts`` and ``styles``
    (their exact texts): nothing from anywhere else."""
    script_src = " ".join(source_hash(s) for s in scripts) or "'none'"
    style_src = " ".join(source_hash(s) for s in styles) or "'none'"
    return ("default-src 'none'; "
            f"script-src {script_src}; style-src {style_src}; img-src data:; "
            "base-uri 'none'; form-action 'none'")


def page(title, body, scripts=(), styles=(), data=None):
    """A whole HTML document: ``title`` (plain text, escaped here), ``body`` (HTML the caller
    built with ``text`` for every stranger's string), ``scripts`` and ``styles`` (code texts,
    inlined and hashed into the policy), ``data`` ({element id: value}: JSON data blocks
    placed before the scripts)."""
    scripts, styles = list(scripts), list(styles)
    blocks = "".join(data_block(k, v) for k, v in (data or {}).items())
    style_tags = "".join(f"<style>{s}</style>" for s in styles)
    script_tags = "".join(f"<script>{s}</script>" for s in scripts)
    for code in scripts + styles:
        lowered = code.lower()
        if "</script" in lowered or "</style" in lowered or "<!--" in lowered:
            raise ValueError("a page's own code may not contain </script, </style or <!--")
    return ("<!DOCTYPE html>\n"
            f'<html lang="en"><head><meta charset="{ENCODING}">'
            f'<meta http-equiv="Content-Security-Policy" content="{text(policy(scripts, styles))}">'
            '<meta name="viewport" content="width=device-width, initial-scale=1">'
            '<meta name="referrer" content="no-referrer">'
            f"<title>{text(title)}</title>{style_tags}</head>"
            f"<body>{body}{blocks}{script_tags}</body></html>\n")


def check_page_path(path):
    """``path`` checked before any work (``engine.atomic.check_output_path`` with the ``html``
    kind): its directory must exist, and an existing file there must be an HTML page."""
    return check_output_path(path, "html")


def write_page(path, document):
    """Write ``document`` (a page's text) at ``path`` atomically: whole or not at all."""
    path = check_page_path(path)
    atomic_write(path, lambda f: f.write(document.encode(ENCODING)), "wb")
    return path


def package_text(name):
    """The text of a file shipped beside this module (the pages' scripts and styles)."""
    from importlib import resources

    return resources.files("spacewar.view").joinpath("assets", name).read_text(ENCODING)
