"""A replay as one self-contained web page that plays the match (``spacewar replay FILE --html
OUT.html``), and the same page in a notebook (``Player``).

**Where the frames come from.** The replay is re-simulated here, in Python
(``spacewar.replay.simulate``), and every frame is turned into the drawing primitives of
``spacewar.view.scene.scene``, the very description the GIF (``spacewar.view.gif``) and the
pygame window paint: the ships, torpedoes, star, explosions, hyperspace flashes, and the HUD
(names and scores, round, mode, fuel, torpedoes, hyperspace jumps, charges in the electric
mode). The page only paints them on a canvas. So there is no second copy of the physics or
of the HUD's layout in JavaScript: the HUD is laid out once, in ``scene``, and the page shows
what the GIF shows. Shipping primitives costs more bytes than shipping the state (about 100
bytes a frame compressed against perhaps 30), but a layout written twice drifts apart.

**How they are stored.** Each primitive's coordinates are rounded to ``1 / QUANTUM`` of a
pixel of a ``SIZE`` x ``SIZE`` scene (1/8 of a pixel of 720), colours and strings become
indices into small tables, the fixed star field is sent once, and the frames' JSON is
compressed with zlib (deflate) and base64-encoded into the page, where the browser's own
``DecompressionStream("deflate")`` unpacks it. Measured: a 5-round match of 1,786 frames
(chaser against sniper) is a 266 kB page, about 149 bytes a frame.

**What the page shows besides the canvas**: play and pause, speeds 1/8x to 8x, single frames
back and forward, a scrub bar to any frame with the round boundaries marked, the bots' names,
the result and the replay's signature status (``spacewar.replay.signature_status``: verified,
unsigned, signed with another key, forged), with keys: Space, ``,`` and ``.`` (or the arrow
keys), ``[`` and ``]``, ``1``, Home and End. The result shown is the one re-derived from the
replay (``spacewar.replay.check``), with a warning where the file's recorded result differs:
a file can claim any score, not make its frames play another. Every stranger's string (the
names) is shown as text, never as markup, escaped, cut and isolated
(``spacewar.view.html_page.display_name``: control, direction-override and blank-looking
characters visible, right-to-left letters kept from reordering the score beside them);
``spacewar.view.html_page`` holds those rules and the page's Content-Security-Policy. A
replay of more than ``MAX_FRAMES`` frames is refused before it is simulated.

``Player`` is the notebook form: ``_repr_html_`` gives the page inside
``<iframe sandbox="allow-scripts" srcdoc=...>`` (a notebook drops a page's own policy and the
scripts of saved output; the sandboxed frame keeps the page apart from the notebook).
"""
import base64
import html
import json
import math
import os
import zlib

from spacewar.view import html_page
from spacewar.view.look import DEFAULT_NAMES
from spacewar.view.scene import Effects, frame_snapshot, scene, starfield_primitives

SIZE = 720  # pixels of the scene the primitives are laid out for (the window's default)
QUANTUM = 8  # coordinates are stored in 1/QUANTUM pixel steps
FPS = 60  # game frames a second at 1x (the 1962 game's pace)
#: the most frames a page holds (a replay is re-simulated and laid out whole: about 200 bytes
#: a frame in the page, 0.2 ms a frame to make; the longest real matches here are 60,001)
MAX_FRAMES = 250_001
#: the most characters of a name kept for its tooltip
FULL_NAME_CHARACTERS = 1000
#: primitive kinds in the order of their codes in the page's data
KINDS = ("dot", "ring", "poly", "fill", "line", "text")
ALIGNS = {"left": 0, "centre": 1, "right": 2}
#: what the page says of each signature status
SIGNATURE_TEXT = {
    "verified": "signed with this computer's key: the bots and fault record are as recorded",
    "unsigned": "unsigned: the play and the score are the replay's own, but who played and "
                "the fault record cannot be verified",
    "other key": "signed with another key: cannot be verified here",
    "forged": "FORGED: its signature does not match its content",
}


def _q(value):
    """A coordinate in stored steps (an int)."""
    return int(round(value * QUANTUM))


class _Tables:
    """Colours and strings by index, in order of first use."""

    def __init__(self):
        self.colours, self.texts = {}, {}

    def colour(self, rgb):
        return self.colours.setdefault(tuple(int(c) for c in rgb), len(self.colours))

    def text(self, value):
        return self.texts.setdefault(value, len(self.texts))


def encode_primitive(prim, tables):
    """One ``scene`` primitive as a short list of ints: its kind's code, then its numbers
    (coordinates in 1/QUANTUM pixels; colours and strings as table indices)."""
    kind = prim[0]
    if kind == "dot":
        _, x, y, r, rgb = prim
        return [0, _q(x), _q(y), _q(r), tables.colour(rgb)]
    if kind == "ring":
        _, x, y, r, rgb, width = prim
        return [1, _q(x), _q(y), _q(r), tables.colour(rgb), int(width)]
    if kind == "poly":
        _, points, rgb, width = prim
        return [2, tables.colour(rgb), int(width)] + [_q(c) for point in points for c in point]
    if kind == "fill":
        _, points, rgb = prim
        return [3, tables.colour(rgb)] + [_q(c) for point in points for c in point]
    if kind == "line":
        _, x0, y0, x1, y1, rgb, width = prim
        return [4, _q(x0), _q(y0), _q(x1), _q(y1), tables.colour(rgb), int(width)]
    if kind == "text":
        _, x, y, value, rgb, align, pixels = prim
        return [5, _q(x), _q(y), tables.text(value), tables.colour(rgb), ALIGNS[align],
                _q(pixels)]
    raise ValueError(f"unknown drawing primitive {kind!r}")


def decode_primitive(code, colours, texts):
    """``encode_primitive`` undone, coordinates in pixels: what the page paints (for tests)."""
    kind = KINDS[code[0]]
    px = [c / QUANTUM for c in code]
    if kind == "dot":
        return ("dot", px[1], px[2], px[3], tuple(colours[code[4]]))
    if kind == "ring":
        return ("ring", px[1], px[2], px[3], tuple(colours[code[4]]), code[5])
    if kind == "poly":
        return ("poly", list(zip(px[3::2], px[4::2])), tuple(colours[code[1]]), code[2])
    if kind == "fill":
        return ("fill", list(zip(px[2::2], px[3::2])), tuple(colours[code[1]]))
    if kind == "line":
        return ("line", px[1], px[2], px[3], px[4], tuple(colours[code[5]]), code[6])
    align = {v: k for k, v in ALIGNS.items()}[code[5]]
    return ("text", px[1], px[2], texts[code[3]], tuple(colours[code[4]]), align, px[6])


def shown_names(replay):
    """The two bots' names as the page shows them: escaped, cut to ``NAME_CHARACTERS`` and
    isolated (``spacewar.view.html_page.display_name``)."""
    return [html_page.display_name(n) for n in _names(replay)]


def _names(replay):
    return replay.get("bots") or replay.get("result", {}).get("bots") or DEFAULT_NAMES


def replayed_result(replay):
    """``(result, mismatched fields, signature status)``: the result re-derived from the
    replay alone (``spacewar.replay.check``: score, winner, forfeits from the recorded faults),
    the fields where the file's recorded result says otherwise, and the signature's status
    (``spacewar.replay.signature_status``, as the check found it). The page shows the re-derived
    one: a file can claim any result, but not make its frames play another."""
    from spacewar.replay import check

    _, details = check(replay)
    return details["replayed"], sorted(details["mismatches"]), details["signature"]


def result_text(result, names):
    """One line saying how the match ended."""
    score = result.get("score") or [0, 0]
    forfeits = result.get("forfeits") or [False, False]
    seat = result.get("winner_seat")
    line = f"{names[0]} {score[0]} - {score[1]} {names[1]}"
    if all(forfeits):
        return f"no winner: both forfeited ({line})"
    if seat in (0, 1):
        how = ", the other forfeited" if any(forfeits) else ""
        return f"{names[seat]} wins{how} ({line})"
    return f"a draw ({line})"


def frames(replay, size=SIZE, on_snapshot=None, sink=None):
    """Re-simulate ``replay`` and lay out every frame: ``(encoded frames, tables, round
    starts)``: each frame's primitives (``encode_primitive``; the star field left out, it is
    the same every frame), the colour and string tables, the first frame of each round.
    With ``sink`` (a callable taking each frame's encoding) the frames go there as they come
    and the list returned is empty, so memory does not grow with the match.
    ``on_snapshot(index, snapshot, prims)`` (optional) sees each frame's ``frame_snapshot``
    and its primitives as drawn, for tests."""
    from spacewar.replay import simulate

    if replay["frames"] + 1 > MAX_FRAMES:
        from spacewar.replay import ReplayError

        raise ReplayError(f"the replay has {replay['frames']} frames: a player page holds at "
                          f"most {MAX_FRAMES - 1} (about {MAX_FRAMES * 200 // 10**6} MB)")
    names = shown_names(replay)
    rounds = replay.get("rounds")
    tables = _Tables()
    effects = Effects()
    encoded, round_starts = [], []
    state = {"round": None, "count": 0}

    def on_frame(game):
        snap = frame_snapshot(game)
        effects.update(snap)
        if snap["round"] != state["round"] and not snap.get("over"):
            round_starts.append(state["count"])
            state["round"] = snap["round"]
        prims = scene(snap, size, effects=effects, names=names, rounds=rounds, starfield=False)
        if on_snapshot is not None:
            on_snapshot(state["count"], snap, prims)
        frame = [encode_primitive(p, tables) for p in prims]
        if sink is None:
            encoded.append(frame)
        else:
            sink(frame)
        state["count"] += 1

    simulate(replay, on_frame)
    return encoded, tables, round_starts


class _Packer:
    """The frames' JSON list, deflated as it comes (``zlib.compressobj``)."""

    def __init__(self):
        self.squeeze = zlib.compressobj(9)
        self.parts = [self.squeeze.compress(b"[")]
        self.count = 0

    def add(self, frame):
        text = ("," if self.count else "") + json.dumps(frame, separators=(",", ":"))
        self.parts.append(self.squeeze.compress(text.encode("ascii")))
        self.count += 1

    def finish(self):
        self.parts.append(self.squeeze.compress(b"]"))
        self.parts.append(self.squeeze.flush())
        return b"".join(self.parts)


def document_data(replay, size=SIZE):
    """The page's data: everything it shows, plain JSON (the frames compressed inside)."""
    names = shown_names(replay)
    packer = _Packer()
    _, tables, round_starts = frames(replay, size, sink=packer.add)
    packed = packer.finish()
    result, differs, status = replayed_result(replay)
    starfield = [encode_primitive(p, tables) for p in starfield_primitives(size)]
    return {
        "format": "spacewar-player", "version": 1, "size": size, "quantum": QUANTUM,
        "fps": FPS, "count": packer.count, "names": names,
        "full_names": [html_page.visible(n)[:FULL_NAME_CHARACTERS] for n in _names(replay)],
        "result": result_text(result, names),
        "warning": (f"the file's recorded result differs from its replay ({', '.join(differs)})"
                    if differs else ""),
        "signature": status,
        "signature_text": SIGNATURE_TEXT[status], "round_starts": round_starts,
        "rounds": replay.get("rounds"), "seed": str(replay.get("seed")),
        "mode": (replay.get("rules") or {}).get("mode", "classic"),
        "colours": [list(c) for c in tables.colours], "texts": list(tables.texts),
        "starfield": starfield, "frames": base64.b64encode(packed).decode("ascii"),
    }


def page_html(replay, title=None, size=SIZE):
    """The whole player page for ``replay`` (a replay dict already read and validated)."""
    return _page(replay, title, size)[0]


def _page(replay, title, size):
    """``(the page's text, its data)``."""
    data = document_data(replay, size)
    names = data["names"]
    title = title or f"Spacewar! {names[0]} vs {names[1]}"
    body = (
        '<main class="player">'
        '<header><h1 id="title"></h1><p id="result"></p>'
        '<p id="signature"></p><p id="warning"></p></header>'
        '<div class="stage"><canvas id="scope" width="1" height="1"></canvas></div>'
        '<div class="bar"><input id="scrub" type="range" min="0" max="0" value="0" '
        'aria-label="frame"><div id="marks"></div></div>'
        '<nav class="controls">'
        '<button id="back" type="button" title="one frame back (,)">&#9664;&#9646;</button>'
        '<button id="play" type="button" title="play or pause (Space)">play</button>'
        '<button id="forward" type="button" title="one frame forward (.)">&#9646;&#9654;</button>'
        '<button id="slower" type="button" title="slower ([)">slower</button>'
        '<span id="speed">1x</span>'
        '<button id="faster" type="button" title="faster (])">faster</button>'
        '<span id="clock"></span></nav>'
        '<p class="keys">Space play/pause &middot; , . one frame &middot; [ ] speed &middot; '
        '1 normal speed &middot; Home End ends &middot; drag the bar to any frame; '
        'marks are round starts</p>'
        "</main>")
    document = html_page.page(title, body, scripts=[html_page.package_text("player.js")],
                              styles=[html_page.package_text("player.css")],
                              data={"spacewar-replay": data})
    return document, data


def read_replay(replay):
    """A replay dict from a dict (validated) or a file (``spacewar.replay.load``: read within
    the bounds every stranger's file gets, nothing in it executed)."""
    from spacewar.replay import load, validate

    if isinstance(replay, (str, bytes, os.PathLike)):
        return load(replay)
    if isinstance(replay, dict):
        return validate(replay, "the replay")
    raise TypeError(f"replay must be a replay dict or a file path, got {type(replay).__name__}")


def write_player(replay, out_path, size=SIZE):
    """Write the player page of ``replay`` (a dict or a file) at ``out_path``; return a summary:
    ``path``, ``frames``, ``bytes``, ``signature``. The path is checked before the replay is
    simulated; the page is written atomically."""
    out_path = html_page.check_page_path(out_path)
    replay = read_replay(replay)
    document, data = _page(replay, None, size)
    html_page.write_page(out_path, document)
    return {"path": out_path, "frames": int(replay["frames"]) + 1,
            "bytes": os.path.getsize(out_path),
            "signature": data["signature"]}


class Player:
    """A replay that shows itself: in a notebook (``_repr_html_``), as a page (``html()``,
    ``save(path)``).

        from spacewar import play_match
        from spacewar.view.player_page import Player
        result, replay, timing = play_match("chaser", "sniper", seed=7, rounds=3, record=True)
        Player(replay)                     # the last line of a notebook cell: the player

    ``replay``: a replay dict, a replay file's path, or ``play_match``'s ``(result, replay,
    timing)``. ``width``: the frame's width in the notebook, pixels."""

    def __init__(self, replay, width=560):
        if isinstance(replay, tuple) and len(replay) == 3 and isinstance(replay[0], dict):
            if replay[1] is None:
                raise ValueError("this match was played without its replay: play it with "
                                 "play_match(..., record=True)")
            replay = replay[1]  # play_match's (result, replay, timing)
        if isinstance(width, bool) or not isinstance(width, int) or not 160 <= width <= 4096:
            raise ValueError(f"width must be an int in [160, 4096] pixels, got {width!r}")
        self.replay = read_replay(replay)
        self.width = width
        self._page = None

    def html(self):
        """The player page's text (made once)."""
        if self._page is None:
            self._page = page_html(self.replay)
        return self._page

    def save(self, path):
        """Write the page at ``path`` (as ``spacewar replay FILE --html``); return the path."""
        return html_page.write_page(path, self.html())  # checks the path first

    def _repr_html_(self):
        height = int(math.ceil(self.width * 1.32)) + 40
        return (f'<iframe sandbox="allow-scripts" width="{self.width}" height="{height}" '
                f'style="border:0" title="Spacewar! replay player" '
                f'srcdoc="{html.escape(self.html(), quote=True)}"></iframe>')

    def __repr__(self):
        names = shown_names(self.replay)
        return f"Player({names[0]!r} vs {names[1]!r}, {self.replay['frames']} frames)"
