"""The replay player page, read back in Python: its frames are the re-simulation's scene to
within the stated quantum, it carries its own data and code under a policy that loads
nothing, strangers' names are text in it, and the notebook form wraps the same page.
(The same page driven in a real browser: tests/spacewar/test_player_browser.py.)"""
import base64
import html.parser
import json
import zlib

import pytest

from spacewar import replay as replay_io
from spacewar.arena.match import play_match
from spacewar.cli import main
from spacewar.view import html_page, player_page
from spacewar.view.player_page import QUANTUM, Player

#: names a stranger may give a bot (its file or class name), each an attack on a page
HOSTILE_NAMES = [
    "<script>alert(1)</script>",
    '"><img src=x onerror=alert(1)>',
    "</script><script>alert(2)</script>",
    "\u202egnp.exe\u202c left-to-right override",
    "x" * 5000,
    "&lt;b&gt; &amp; \u2028 \u2029 <!-- -->",
]


@pytest.fixture(scope="module")
def match(tmp_path_factory):
    """A 2-round match's result and its replay as saved and read back (so signed)."""
    result, replay, _ = play_match("chaser", "sniper", seed=7, rounds=2, record=True)
    path = tmp_path_factory.mktemp("player") / "match.json"
    with pytest.MonkeyPatch.context() as patch:  # the run's key (conftest's replay_key)
        patch.setenv("SPACEWAR_REPLAY_KEY_FILE",
                     str(tmp_path_factory.getbasetemp() / "replay-key"))
        replay_io.save(path, replay)
    return result, replay_io.load(path)


class PageParts(html.parser.HTMLParser):
    """Every element of a page, its attributes, and the text of its script elements."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.elements, self.scripts, self._script = [], [], None

    def handle_starttag(self, tag, attrs):
        self.elements.append((tag, dict(attrs)))
        if tag == "script":
            self._script = [dict(attrs), ""]

    def handle_data(self, data):
        if self._script is not None:
            self._script[1] += data

    def handle_endtag(self, tag):
        if tag == "script" and self._script is not None:
            self.scripts.append(tuple(self._script))
            self._script = None


def parts(document):
    parser = PageParts()
    parser.feed(document)
    parser.close()
    return parser


def page_data(document):
    """The page's data block, read as the page's script reads it."""
    (data,) = [json.loads(text) for attrs, text in parts(document).scripts
               if attrs.get("id") == "spacewar-replay"]
    return data


def test_every_frame_is_the_scene_of_the_re_simulation_within_one_quantum(match):
    _, replay = match
    expected = {}
    encoded, tables, round_starts = player_page.frames(
        replay, on_snapshot=lambda k, snap, prims: expected.__setitem__(k, prims))
    assert len(encoded) == replay["frames"] + 1 == len(expected)
    colours, texts = list(tables.colours), list(tables.texts)
    half = 0.5 / QUANTUM
    kinds = set()
    for k in range(0, len(encoded), 7):
        got = [player_page.decode_primitive(code, colours, texts) for code in encoded[k]]
        assert len(got) == len(expected[k])
        for mine, theirs in zip(got, expected[k]):
            kinds.add(mine[0])
            assert mine[0] == theirs[0]
            for a, b in zip(_numbers(mine), _numbers(theirs)):
                assert abs(a - b) <= half + 1e-12, (k, mine, theirs)
            assert _others(mine) == _others(theirs)
    assert {"dot", "poly", "line", "text"} <= kinds
    # the rounds start where the re-simulation's round counter moves on
    assert round_starts[0] == 0 and len(round_starts) == replay["result"]["rounds"]


#: for each primitive kind, which of its fields are coordinates (pixels; stored rounded to
#: the quantum) and which must come back exactly (colours, widths, strings, alignment)
FIELDS = {"dot": ("xyr", "c"), "ring": ("xyr", "cw"), "poly": ("p", "cw"), "fill": ("p", "c"),
          "line": ("xyxy", "cw"), "text": ("xy", "tcap")}


def _numbers(prim):
    coords, _ = FIELDS[prim[0]]
    values = prim[1:1 + len(coords)]
    if coords == "p":
        return [float(c) for point in values[0] for c in point]
    numbers = [float(v) for v in values]
    if prim[0] == "text":
        numbers.append(float(prim[6]))  # the font's pixels
    return numbers


def _others(prim):
    coords, _ = FIELDS[prim[0]]
    rest = prim[1 + len(coords):]
    if prim[0] == "text":
        rest = rest[:3]  # text, colour, align (the font's pixels are a coordinate)
    return [tuple(v) if isinstance(v, (list, tuple)) else v for v in rest]


def test_the_page_carries_its_frames_compressed_and_they_unpack_to_the_encoding(match):
    _, replay = match
    document = player_page.page_html(replay)
    data = page_data(document)
    encoded, _, round_starts = player_page.frames(replay)
    assert json.loads(zlib.decompress(base64.b64decode(data["frames"]))) == encoded
    assert data["count"] == len(encoded) and data["round_starts"] == round_starts
    assert data["quantum"] == QUANTUM and data["size"] == player_page.SIZE
    assert data["signature"] == replay_io.signature_status(replay) == "verified"


def test_the_page_loads_nothing_and_runs_only_its_own_code_by_hash(match):
    _, replay = match
    document = player_page.page_html(replay)
    page = parts(document)
    (policy,) = [a["content"] for tag, a in page.elements
                 if tag == "meta" and a.get("http-equiv") == "Content-Security-Policy"]
    assert "'unsafe-inline'" not in policy and "'unsafe-eval'" not in policy
    rules = dict(rule.strip().split(" ", 1) for rule in policy.split(";"))
    assert rules["default-src"] == "'none'"
    code = [text for attrs, text in page.scripts if "type" not in attrs]
    assert len(code) == 1 and rules["script-src"] == html_page.source_hash(code[0])
    styles = document.split("<style>")[1].split("</style>")[0]
    assert rules["style-src"] == html_page.source_hash(styles)
    # no element of the page names anything outside it
    for tag, attrs in page.elements:
        for name in ("src", "href", "action", "data", "srcset"):
            assert name not in attrs, (tag, attrs)


def _with_names(replay, names, signature="drop"):
    """``replay`` with other bots' names, its digest dropped (a dict, not a file); its
    signature dropped, kept as it was (now forged) or moved to another key."""
    other = json.loads(json.dumps(replay))
    other["bots"] = list(names)
    other["result"]["bots"] = list(names)
    other.pop(replay_io.DIGEST_FIELD, None)
    if signature == "drop":
        other.pop(replay_io.SIGNATURE_FIELD, None)
    elif signature == "other key":
        other[replay_io.SIGNATURE_FIELD]["key"] = "0123456789abcdef"
    return other


@pytest.mark.parametrize("name", HOSTILE_NAMES)
def test_a_hostile_name_is_text_in_the_page_never_markup(match, name):
    _, replay = match
    document = player_page.page_html(_with_names(replay, [name, "idle"]))
    page = parts(document)
    clean = parts(player_page.page_html(_with_names(replay, ["a", "idle"])))
    # the same elements and attributes as with a plain name: nothing came from the name
    assert [(t, sorted(a)) for t, a in page.elements] == \
        [(t, sorted(a)) for t, a in clean.elements]
    assert not any(k.startswith("on") for _, a in page.elements for k in a)
    data = page_data(document)
    assert data["names"][0] == html_page.display_name(name)  # escaped, cut, isolated
    assert data["full_names"][0] == html_page.visible(name)[:player_page.FULL_NAME_CHARACTERS]
    assert "\u202e" not in document and "</script><script>alert" not in document
    assert data["signature"] == "unsigned"


def test_a_name_cannot_reorder_hide_or_push_away_the_score(match):
    """Right-to-left letters reversed the score beside a name; blank-looking letters pushed
    it out of sight (both found by a red team): a name is isolated, cut and escaped."""
    _, replay = match
    rtl, pad = "Evil\u05d5", "EVIL  3" + "\u2800" * 120
    data = page_data(player_page.page_html(_with_names(replay, [rtl, pad])))
    first, second = data["names"]
    assert first == "\u2068" + rtl + "\u2069"  # isolated: it cannot reorder what is beside it
    assert second.startswith("\u2068EVIL  3\\u2800") and second.endswith("\u2026\u2069")
    assert len(second) <= html_page.NAME_CHARACTERS + 2
    cut = html_page.display_name("a" * 46 + "\x07" + "b" * 10)
    assert cut == "\u2068" + "a" * 46 + "\u2026\u2069"  # cut between escapes, not inside one
    assert "\u2800" not in json.dumps(data, ensure_ascii=False)


def test_the_result_shown_is_the_replays_own_whatever_the_file_claims(match):
    _, replay = match
    claims = _with_names(replay, ["chaser", "sniper"])
    claims["result"]["score"] = [9, 0]
    claims["result"]["winner_seat"] = 0
    claims["result"]["winner"] = "chaser"
    data = page_data(player_page.page_html(claims))
    honest = page_data(player_page.page_html(_with_names(replay, ["chaser", "sniper"])))
    assert data["result"] == honest["result"] and "9" not in data["result"]
    assert data["warning"].startswith("the file's recorded result differs from its replay")
    assert "score" in data["warning"] and honest["warning"] == ""


def test_a_malformed_signature_is_forged_not_a_crash(match):
    _, replay = match
    odd = json.loads(json.dumps(replay))
    odd.pop(replay_io.DIGEST_FIELD)
    odd[replay_io.SIGNATURE_FIELD]["hmac_sha256"] = "\u00e9"  # compare_digest refuses it
    assert replay_io.signature_status(odd) == "forged"
    assert page_data(player_page.page_html(odd))["signature"] == "forged"


def test_a_replay_too_long_for_a_page_is_refused_before_it_is_simulated(match, monkeypatch):
    _, replay = match
    monkeypatch.setattr(player_page, "MAX_FRAMES", replay["frames"])
    with pytest.raises(replay_io.ReplayError, match="a player page holds at most"):
        player_page.page_html(replay)


@pytest.mark.parametrize("how, status", [("drop", "unsigned"), ("keep", "forged"),
                                         ("other key", "other key")])
def test_the_page_says_what_the_signature_is(match, how, status):
    _, replay = match
    data = page_data(player_page.page_html(_with_names(replay, ["chaser", "tampered"], how)))
    assert data["signature"] == status
    assert data["signature_text"] == player_page.SIGNATURE_TEXT[status]


def test_the_notebook_player_is_the_same_page_in_a_sandboxed_frame(match):
    result, replay = match
    player = Player((result, replay, {}))  # play_match's own return value
    frame = parts(player._repr_html_())
    ((tag, attrs),) = frame.elements
    assert tag == "iframe" and attrs["sandbox"] == "allow-scripts"  # no same-origin
    assert attrs["srcdoc"] == player.html() == player_page.page_html(replay)
    with pytest.raises(ValueError, match="record=True"):
        Player((result, None, {}))  # play_match without its replay
    with pytest.raises(ValueError, match="width"):
        Player(replay, width=10)
    with pytest.raises(TypeError, match="replay must be"):
        Player(42)


def test_the_command_writes_the_page_and_refuses_a_bad_path_first(match, tmp_path, capsys):
    _, replay = match
    path = tmp_path / "match.json"
    replay_io.save(path, replay)
    before = path.read_bytes()
    out = tmp_path / "match.html"
    assert main(["replay", str(path), "--html", str(out)]) == 0
    assert "replay verified" in capsys.readouterr().out
    assert page_data(out.read_text())["count"] == replay["frames"] + 1
    # over the replay itself, or into a missing directory: refused, nothing written
    assert main(["replay", str(path), "--html", str(path)]) == 2
    assert path.read_bytes() == before
    assert main(["replay", str(path), "--html", str(tmp_path / "no" / "x.html")]) == 2
    source = tmp_path / "bot.py"  # any other text file, a bot's source say: not a page
    source.write_text("class Bot:\n    pass\n")
    assert main(["replay", str(path), "--html", str(source)]) == 2
    assert source.read_text() == "class Bot:\n    pass\n"
    assert main(["replay", str(path), "--html", str(out)]) == 0  # a page: replaced
    assert "error" in capsys.readouterr().err


def test_a_strangers_replay_is_read_within_the_bounds_of_every_strangers_file(tmp_path):
    huge = tmp_path / "huge.json"
    huge.write_text("[" * 100000 + "]" * 100000)
    with pytest.raises(replay_io.ReplayError):
        player_page.write_player(str(huge), tmp_path / "out.html")
    assert not (tmp_path / "out.html").exists()
