"""The league and tournament pages in a real headless Chromium (tests/browser.py): they load
with no console error and no request, the table and the matrix show the results' numbers in
the legend's colours, the filter of the matches works, and hostile names render as text."""
import pytest

from spacewar.arena.tournament import run_tournament
from spacewar.faults import printable
from spacewar.view import league_pages

from .test_league_pages import HOSTILE, fabricated_report, record_of

pytestmark = pytest.mark.browser

#: the legend's end colours (assets/league.css): a row bot that lost every match, won every one
H0, H10 = "rgb(150, 62, 22)", "rgb(28, 104, 156)"

ROWS = """[...document.querySelectorAll(SELECTOR)].map(
    tr => [...tr.children].map(td => td.textContent))"""


@pytest.fixture(scope="module")
def played(tmp_path_factory):
    """A small tournament's report and pages (its replays kept, signed with the run's key)."""
    folder = tmp_path_factory.mktemp("pages")
    with pytest.MonkeyPatch.context() as patch:  # the run's key (conftest's replay_key)
        patch.setenv("SPACEWAR_REPLAY_KEY_FILE",
                     str(tmp_path_factory.getbasetemp() / "replay-key"))
        report, _ = run_tournament(["idle", "random", "chaser"], games=1, rounds=1, workers=1,
                                   progress=False, replays=folder / "replays")
        league_pages.write_pages(folder, report, folder / "replays")
    return report, folder


def rows(page, selector):
    return page.evaluate(ROWS.replace("SELECTOR", repr(selector)))


def test_the_pages_load_with_no_console_error_and_no_request(open_page, played):
    report, folder = played
    for path in [folder / "index.html"] + sorted((folder / "bots").glob("*.html")):
        visit = open_page(path)
        visit.assert_quiet()
        assert visit.page.evaluate("document.scripts.length") == 2
        assert visit.page.is_visible("#match-filter")  # the page's own script ran


def test_the_table_and_the_matrix_show_the_results_in_the_legend_s_colours(open_page, played):
    report, folder = played
    page = open_page(folder / "index.html").page
    shown = rows(page, "table.standings tbody tr")
    assert [r[1] for r in shown] == [row["bot"] for row in report["table"]]
    assert [r[2:5] for r in shown] == [
        [str(row["played"]), f"{row['wins']}-{row['draws']}-{row['losses']}",
         f"{row['points_for']}-{row['points_against']}"] for row in report["table"]]
    assert [r[7:9] for r in shown] == [
        [f"{row['elo']:.1f}", f"{row['elo_low']:.1f} to {row['elo_high']:.1f}"]
        for row in report["table"]]
    order = [row["bot"] for row in report["table"]]
    grid = rows(page, "table.matrix tbody tr")
    colours = page.evaluate("""[...document.querySelectorAll('table.matrix tbody tr')].map(
        tr => [...tr.querySelectorAll('td')].map(td => getComputedStyle(td).backgroundColor))""")
    legend = page.evaluate("""[...document.querySelectorAll('.legend span')].slice(1).map(
        s => getComputedStyle(s).backgroundColor)""")
    assert legend[0] == H0 and legend[10] == H10 and len(set(legend[:11])) == 11
    coloured = 0
    for a, cells, paint in zip(order, grid, colours, strict=True):
        for b, text, colour in zip(order, cells[1:], paint):
            wins, draws, losses, _, _ = record_of(report["matches"], a, b)
            if a != b and wins + draws + losses:
                assert text == f"{wins}-{draws}-{losses}"
                # the legend's colour of the row bot's score share, to the nearest tenth
                share = (wins + 0.5 * draws) / (wins + draws + losses)
                assert colour == legend[int(share * 10 + 0.5)], (a, b, text)
                coloured += 1
    assert coloured == len(order) * (len(order) - 1)  # a round robin: every pair met
    # the filter: a name's words keep its matches only, and the count says so
    page.fill("#match-filter", "chaser")
    visible = page.evaluate("""[...document.querySelectorAll('#match-rows tr')]
        .filter(tr => !tr.hidden).length""")
    mine = sum(1 for m in report["matches"] if "chaser" in (m["p1"], m["p2"]))
    assert visible == mine
    assert page.text_content("#match-count") == f"{mine} of {len(report['matches'])} matches"


def test_hostile_names_render_as_text(open_page, tmp_path):
    report = fabricated_report(HOSTILE)
    league_pages.write_pages(tmp_path / "pages", report)
    for path in [tmp_path / "pages" / "index.html"] + sorted(
            (tmp_path / "pages" / "bots").glob("*.html")):
        visit = open_page(path)
        visit.assert_quiet()  # a script let in would be refused by the policy: an error
        page = visit.page
        assert page.evaluate("document.scripts.length") == 2
        assert page.evaluate("document.images.length") == 0
        assert page.evaluate("""[...document.querySelectorAll('*')].flatMap(
            e => [...e.attributes].map(a => a.name)).filter(n => n.startsWith('on'))""") == []
        names = page.evaluate("""[...document.querySelectorAll('span.name')].map(
            s => [s.textContent, s.title, s.getBoundingClientRect().width])""")
        assert names and all(text in {printable(n) for n in HOSTILE} and title == text
                             for text, title, _ in names)
        # a 10,000-character name is cut on screen (text-overflow), whole in its title
        assert max(width for _, _, width in names) < 400
