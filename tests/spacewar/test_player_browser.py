"""The replay player page in a real headless Chromium (tests/browser.py): it loads with no
console error and no request, draws at each frame what the re-simulation says (the
primitives it painted, read back from the page, and the canvas's own pixels), its controls
work from clicks and keys, strangers' names stay text, its policy refuses any script but its
own, and the notebook's sandboxed frame plays it too."""
import math
import time

import pytest

from spacewar import replay as replay_io
from spacewar.arena.match import play_match
from spacewar.view.html_page import display_name, visible
from spacewar.view import player_page
from spacewar.view.look import SHIP_COLOURS
from spacewar.view.player_page import QUANTUM, SIZE, Player

pytestmark = pytest.mark.browser

READY = "document.body.dataset.ready === 'true'"


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """A 3-round match, saved (signed with the run's key) and read back; its player page; and
    every frame's primitives as the re-simulation lays them out."""
    _, replay, _ = play_match("chaser", "sniper", seed=7, rounds=3, record=True)
    folder = tmp_path_factory.mktemp("player")
    with pytest.MonkeyPatch.context() as patch:  # the run's key (conftest's replay_key)
        patch.setenv("SPACEWAR_REPLAY_KEY_FILE", str(tmp_path_factory.getbasetemp() / "replay-key"))
        replay_io.save(folder / "match.json", replay)
        replay = replay_io.load(folder / "match.json")
        player_page.write_player(replay, folder / "match.html")
    scenes = {}
    _, _, starts = player_page.frames(replay, on_snapshot=lambda k, s, p: scenes.__setitem__(k, p))
    return {"replay": replay, "page": folder / "match.html", "scenes": scenes, "starts": starts}


def wait_until(page, expression, seconds=10.0):
    """Poll ``expression`` in the page until it is true. (Playwright's ``wait_for_function``
    polls with ``eval``, which the page's policy forbids: a page that allowed it would be
    the weaker for it. ``evaluate`` goes through the debugging protocol, not the page.)"""
    deadline = time.monotonic() + seconds
    while not page.evaluate(expression):
        if time.monotonic() > deadline:
            raise AssertionError(f"never true within {seconds} s: {expression}")
        page.wait_for_timeout(20)


def opened(open_page, path):
    visit = open_page(path)
    wait_until(visit.page, READY)
    return visit


def frame_of(page):
    return page.evaluate("spacewarPlayer.frame")


def test_the_page_loads_with_no_console_error_and_no_request(open_page, recorded):
    visit = opened(open_page, recorded["page"])
    visit.assert_quiet()
    assert visit.page.evaluate("spacewarPlayer.count") == recorded["replay"]["frames"] + 1
    assert visit.page.evaluate("spacewarPlayer.signature") == "verified"
    assert "signed with this computer's key" in visit.page.text_content("#signature")


def picked_frames(recorded):
    """Frames across the rounds: the first, one inside each round, one just after each round
    starts, and the last."""
    starts, last = recorded["starts"], recorded["replay"]["frames"]
    picks = {0, last}
    for k, start in enumerate(starts):
        end = starts[k + 1] if k + 1 < len(starts) else last
        picks |= {start + 3, (start + end) // 2}
    return sorted(picks)


def test_each_frame_drawn_is_the_re_simulation_within_one_quantum(open_page, recorded):
    page = opened(open_page, recorded["page"]).page
    half = 0.5 / QUANTUM
    for k in picked_frames(recorded):
        page.evaluate(f"spacewarPlayer.seek({k})")
        drawn = page.evaluate("spacewarPlayer.drawn()")
        expected = recorded["scenes"][k]
        assert [d["kind"] for d in drawn] == [p[0] for p in expected], k
        for got, prim in zip(drawn, expected):
            for (gx, gy), (ex, ey) in zip(_points(got), _prim_points(prim)):
                assert abs(gx - ex) <= half + 1e-9 and abs(gy - ey) <= half + 1e-9, (k, got, prim)
            assert tuple(got["colour"]) == tuple(prim[_colour_index(prim)])
            if prim[0] == "text":
                assert got["text"] == prim[3]


def _points(drawn):
    if "points" in drawn:
        return [tuple(p) for p in drawn["points"]]
    return [(drawn["x"], drawn["y"])]


def _prim_points(prim):
    kind = prim[0]
    if kind in ("poly", "fill"):
        return list(prim[1])
    if kind == "line":
        return [(prim[1], prim[2]), (prim[3], prim[4])]
    return [(prim[1], prim[2])]


def _colour_index(prim):
    return {"dot": 4, "ring": 4, "poly": 2, "fill": 2, "line": 5, "text": 4}[prim[0]]


def canvas_pixels(page, x, y, reach):
    """The canvas's own RGB pixels in the square of side 2 reach + 1 around (x, y)."""
    return page.evaluate(
        """([x, y, r]) => {
            const c = document.getElementById('scope').getContext('2d');
            const d = c.getImageData(x - r, y - r, 2 * r + 1, 2 * r + 1).data;
            const out = [];
            for (let i = 0; i < d.length; i += 4) out.push([d[i], d[i + 1], d[i + 2]]);
            return out;
        }""", [int(round(x)), int(round(y)), reach])


def _near(pixels, rgb, tolerance=40):
    return any(max(abs(a - b) for a, b in zip(p, rgb)) <= tolerance for p in pixels)


def test_the_ships_are_on_the_canvas_where_the_replay_says(open_page, recorded):
    page = opened(open_page, recorded["page"]).page
    checked = 0
    for k in picked_frames(recorded):
        page.evaluate(f"spacewarPlayer.seek({k})")
        for prim in recorded["scenes"][k]:
            if prim[0] != "poly" or tuple(prim[2]) not in SHIP_COLOURS:
                continue
            nose = max(prim[1], key=lambda p: p[1])  # any vertex of the outline
            if not all(4 <= c <= SIZE - 5 for c in nose):
                continue
            colour = tuple(prim[2])
            assert _near(canvas_pixels(page, *nose, 2), colour), (k, nose, colour)
            # and 60 pixels away, where nothing is drawn in a ship's colour, it is not there
            away = (nose[0] + 60 if nose[0] < SIZE / 2 else nose[0] - 60, nose[1])
            if not any(_close(away, p, 10) for q in recorded["scenes"][k] for p in _prim_points(q)):
                assert not _near(canvas_pixels(page, *away, 2), colour), (k, away)
            checked += 1
    assert checked >= 4


def _close(a, b, reach):
    return math.hypot(a[0] - b[0], a[1] - b[1]) <= reach


def test_play_pause_step_speed_and_scrub_work_from_clicks_and_keys(open_page, recorded):
    page = opened(open_page, recorded["page"]).page
    assert frame_of(page) == 0 and page.text_content("#play") == "play"
    page.click("#play")
    wait_until(page, "spacewarPlayer.frame > 10")
    page.click("#play")  # pause
    stopped = frame_of(page)
    page.wait_for_timeout(150)
    assert frame_of(page) == stopped and not page.evaluate("spacewarPlayer.playing")
    page.click("#forward")
    assert frame_of(page) == stopped + 1
    page.click("#back")
    page.click("#back")
    assert frame_of(page) == stopped - 1
    page.keyboard.press(".")
    page.keyboard.press("ArrowRight")
    assert frame_of(page) == stopped + 1
    page.keyboard.press(",")
    assert frame_of(page) == stopped
    # speeds: 1/8x .. 8x, by the buttons and by [ ] and 1
    page.click("#faster")
    page.click("#faster")
    assert page.text_content("#speed") == "4x" and page.evaluate("spacewarPlayer.speed") == 4
    for _ in range(9):
        page.keyboard.press("]")
    assert page.text_content("#speed") == "8x"
    for _ in range(9):
        page.keyboard.press("[")
    assert page.text_content("#speed") == "1/8x" and page.evaluate("spacewarPlayer.speed") == 0.125
    page.keyboard.press("1")
    assert page.text_content("#speed") == "1x"
    # the scrub bar: to any frame
    target = recorded["starts"][1] + 5
    page.fill("#scrub", str(target))
    assert frame_of(page) == target
    page.keyboard.press("End")
    assert frame_of(page) == recorded["replay"]["frames"]
    page.keyboard.press("Home")
    assert frame_of(page) == 0
    page.keyboard.press(" ")
    wait_until(page, "spacewarPlayer.frame > 0")
    page.keyboard.press(" ")
    assert not page.evaluate("spacewarPlayer.playing")


def test_faster_plays_more_frames_in_the_same_time(open_page, recorded):
    page = opened(open_page, recorded["page"]).page
    # the page's clock counts frames from the time that passed: at 8x it runs 64 times as
    # many frames a second as at 1/8x; the counts are compared, not the time taken
    counts = {}
    for key, speed in (("[", 0.125), ("]", 8)):
        page.keyboard.press("Home")
        for _ in range(6):
            page.keyboard.press(key)
        assert page.evaluate("spacewarPlayer.speed") == speed
        page.evaluate("spacewarPlayer.play()")
        page.wait_for_timeout(400)
        page.evaluate("spacewarPlayer.pause()")
        counts[speed] = frame_of(page)
    assert counts[8] > 8 * max(counts[0.125], 1)


def test_the_round_starts_are_marked_on_the_bar(open_page, recorded):
    page = opened(open_page, recorded["page"]).page
    starts = recorded["starts"]
    lefts = page.evaluate("[...document.querySelectorAll('#marks span')].map(s => s.style.left)")
    total = recorded["replay"]["frames"]
    # CSS keeps a percentage to 6 significant digits
    assert [float(v.rstrip("%")) for v in lefts] == pytest.approx(
        [100 * s / total for s in starts[1:]], abs=1e-4)
    assert page.evaluate("spacewarPlayer.roundStarts") == starts


HOSTILE = ['"><img src=x onerror="window.__owned=1">', "</script><script>window.__owned=2"
           "</script>", "\u202emoc.evil\u202c <b>bold</b>", "y" * 3000]


@pytest.mark.parametrize("pair", [HOSTILE[:2], HOSTILE[2:]])
def test_hostile_names_are_shown_as_text(open_page, recorded, tmp_path, pair):
    replay = dict(recorded["replay"], bots=list(pair))
    replay["result"] = dict(replay["result"], bots=list(pair))
    replay.pop(replay_io.DIGEST_FIELD)
    replay.pop(replay_io.SIGNATURE_FIELD)
    player_page.write_player(replay, tmp_path / "hostile.html")
    visit = opened(open_page, tmp_path / "hostile.html")
    page = visit.page
    visit.assert_quiet()
    shown = [display_name(n) for n in pair]
    assert page.text_content("#title") == f"{shown[0]} vs {shown[1]}"
    full = [visible(n)[:player_page.FULL_NAME_CHARACTERS] for n in pair]
    assert page.get_attribute("#title", "title") == f"{full[0]} vs {full[1]}"
    assert page.evaluate("window.__owned") is None
    assert page.evaluate("document.querySelectorAll('img, b').length") == 0
    assert page.evaluate("document.scripts.length") == 2  # its data block and its code
    assert page.text_content("#signature").startswith("replay unsigned")
    texts = [d["text"] for d in page.evaluate("spacewarPlayer.drawn()") if d["kind"] == "text"]
    assert any(shown[0] in t for t in texts)  # on the canvas: drawn text, not markup
    assert "\u202e" not in page.text_content("body")  # an override is shown escaped


def test_the_policy_refuses_a_script_that_is_not_the_pages_own(open_page, recorded):
    visit = opened(open_page, recorded["page"])
    page = visit.page
    page.evaluate("""() => {
        const s = document.createElement('script');
        s.textContent = 'window.__injected = 1';
        document.body.appendChild(s);
    }""")
    page.wait_for_timeout(50)
    assert page.evaluate("window.__injected") is None
    assert any("Content Security Policy" in text for _, text in visit.console)


def test_the_notebook_frame_plays_the_same_page(open_page, recorded, tmp_path):
    notebook = ("<!DOCTYPE html><html><body><div class='output'>"
                + Player(recorded["replay"])._repr_html_() + "</div></body></html>")
    visit = open_page(notebook)
    frame = visit.page.frame_locator("iframe")
    frame.locator("body[data-ready='true']").wait_for()
    inner = visit.page.frames[1]
    assert inner.evaluate("spacewarPlayer.count") == recorded["replay"]["frames"] + 1
    inner.evaluate("spacewarPlayer.seek(40)")
    assert inner.evaluate("spacewarPlayer.drawn().length") == len(recorded["scenes"][40])
    visit.assert_quiet()
