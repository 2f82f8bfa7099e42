"""The pages of a tournament and a league (``--html DIR``) and the replays they keep
(``--replays DIR``): the pages hold the results' numbers, every link leads to a file, a bot's
name is only ever text, each page's policy lists exactly its own code; kept replays (from
worker processes and from a cluster) are the matches played again, and the results are the
same with and without them; a bad output path fails before any match."""
import base64
import glob
import hashlib
import json
import os
import re
from html.parser import HTMLParser
from urllib.parse import unquote

import numpy as np
import pytest

from spacewar.arena import kept_replays, tournament
from spacewar.arena.league import run_league
from spacewar.arena.match import play_match
from spacewar.arena.ratings import bradley_terry_elo, bradley_terry_intervals
from spacewar.arena.tournament import bootstrap_rng, run_tournament, schedule
from spacewar.cli import main
from spacewar.faults import printable
from spacewar.replay import check, load, save
from spacewar.rules import Rules
from spacewar.view import league_pages

QUICK = dict(games=1, rounds=1, progress=False)
THREE = ["idle", "random", "chaser"]

#: names a stranger may give a bot (a submission's path): markup, a script's end, an
#: attribute break-out, direction overrides and control characters, and a huge one
HOSTILE = ["<script>alert(1)</script>",
           '"><img src=x onerror=alert(1)>',
           "</script><script>alert(2)</script><!--",
           "\u202eevil\u202c.py:Bot\x1b[2J\x07\n\t\u2028",
           "x" * 10_000 + "<b onclick=alert(3)>long</b>"]

#: a bot from a file that faults with a hostile message at every frame
FAULTING = b'''class Bot:
    def act(self, obs):
        raise RuntimeError("<script>alert('fault')</script>\\u202e\\x1b[2J")
'''

#: elements the pages are made of: anything else came from somewhere else
OWN_TAGS = {"html", "head", "meta", "title", "style", "body", "main", "nav", "a", "h1", "h2",
            "p", "span", "div", "table", "thead", "tbody", "tr", "th", "td", "input", "script"}


# -- reading a page back -------------------------------------------------------------------------
class Node:
    def __init__(self, tag, attrs, parent):
        self.tag, self.attrs, self.parent, self.children = tag, attrs, parent, []

    def get(self, name):
        return dict(self.attrs).get(name)

    def classes(self):
        return (self.get("class") or "").split()

    def text(self):
        return "".join(c if isinstance(c, str) else c.text() for c in self.children)

    def walk(self):
        for child in self.children:
            if isinstance(child, Node):
                yield child
                yield from child.walk()

    def find_all(self, tag, cls=None):
        return [n for n in self.walk() if n.tag == tag and (cls is None or cls in n.classes())]

    def find(self, tag, cls=None):
        found = self.find_all(tag, cls)
        assert found, (tag, cls)
        return found[0]


class Page(HTMLParser):
    """A page as a tree of ``Node`` (html.parser: a browser's tokenizer rules for script and
    style content)."""
    VOID = {"meta", "input", "br", "img", "link", "hr"}

    def __init__(self, path):
        super().__init__(convert_charrefs=True)
        with open(path, encoding="utf-8") as f:
            self.source = f.read()
        self.root = Node("#root", [], None)
        self.current = self.root
        self.feed(self.source)
        self.close()

    def handle_starttag(self, tag, attrs):
        node = Node(tag, attrs, self.current)
        self.current.children.append(node)
        if tag not in self.VOID:
            self.current = node

    def handle_startendtag(self, tag, attrs):
        self.current.children.append(Node(tag, attrs, self.current))

    def handle_endtag(self, tag):
        node = self.current
        while node is not self.root and node.tag != tag:
            node = node.parent
        assert node is not self.root, f"</{tag}> closes nothing"
        self.current = node.parent

    def handle_data(self, data):
        self.current.children.append(data)

    def data(self):
        """The page's JSON data block, read back."""
        return json.loads(next(n for n in self.root.find_all("script")
                               if n.get("id") == league_pages.DATA_ID).text())


def csp_hash(code):
    return "'sha256-" + base64.b64encode(hashlib.sha256(code.encode()).digest()).decode() + "'"


def check_policy(page):
    """The page's policy loads nothing and allows exactly the page's own inline code."""
    policy = next(n.get("content") for n in page.root.find_all("meta")
                  if n.get("http-equiv") == "Content-Security-Policy")
    assert "unsafe-inline" not in policy and "unsafe-eval" not in policy
    parts = dict(part.strip().split(" ", 1) for part in policy.split(";") if part.strip())
    assert parts["default-src"] == "'none'"
    scripts = [n.text() for n in page.root.find_all("script") if n.get("type") is None]
    styles = [n.text() for n in page.root.find_all("style")]
    assert scripts and styles
    assert set(parts["script-src"].split()) == {csp_hash(s) for s in scripts}
    assert set(parts["style-src"].split()) == {csp_hash(s) for s in styles}
    # the page's own: one data block and one script, whatever the names held
    assert page.source.lower().count("<script") == 2
    assert not [n for n in page.root.walk() if n.get("style") is not None]


def check_only_own_markup(page):
    """No element or attribute but the page's own: no handler, no image, no stray script."""
    assert {n.tag for n in page.root.walk()} <= OWN_TAGS
    for node in page.root.walk():
        for name, value in node.attrs:
            assert not name.startswith("on"), (node.tag, name)
            assert name in {"lang", "charset", "http-equiv", "content", "name", "class",
                            "title", "href", "id", "type", "hidden", "aria-label",
                            "placeholder"}, (node.tag, name)
            if name == "href":
                assert re.fullmatch(r"[A-Za-z0-9._/%-]+", value), value  # relative, ours


def links_resolve(path):
    """Every link of the page at ``path`` leads to an existing file; returns them."""
    page = Page(path)
    targets = []
    for a in page.root.find_all("a"):
        href = a.get("href")
        assert "://" not in href and not href.startswith("/")
        target = os.path.normpath(os.path.join(os.path.dirname(path), unquote(href)))
        assert os.path.isfile(target), (path, href)
        targets.append(target)
    return targets


def all_pages(directory):
    return [os.path.join(directory, "index.html")] + sorted(
        glob.glob(os.path.join(directory, "bots", "*.html")))


def player_there():
    return league_pages.player_writer() is not None


def _json(data):
    return json.dumps(data, sort_keys=True)


def record_of(report_matches, a, b):
    """The test's own head-to-head count: a's wins, draws, losses, points against b."""
    wins = draws = losses = points_for = points_against = 0
    for m in report_matches:
        if {m["p1"], m["p2"]} != {a, b}:
            continue
        seat = 0 if m["p1"] == a else 1
        points_for += m["score"][seat]
        points_against += m["score"][1 - seat]
        if m["winner"] is None:
            draws += 1
        elif m["winner"] == a:
            wins += 1
        else:
            losses += 1
    return wins, draws, losses, points_for, points_against


def check_index_numbers(directory, results, matches):
    """The index's standings, matrix and matches are the results'."""
    page = Page(os.path.join(directory, "index.html"))
    data = page.data()
    assert data["table"] == results["table"]
    rows = page.root.find("table", "standings").find("tbody").find_all("tr")
    assert len(rows) == len(results["table"])
    for rank, (tr, row) in enumerate(zip(rows, results["table"]), 1):
        cell = {c.classes()[0]: c for c in tr.find_all("td")}
        assert cell["rank"].text() == str(rank)
        assert cell["bot"].find("span", "name").text() == printable(row["bot"])
        assert cell["bot"].find("span", "name").get("title") == printable(row["bot"])
        assert cell["played"].text() == str(row["played"])
        assert cell["record"].text() == f"{row['wins']}-{row['draws']}-{row['losses']}"
        assert cell["points"].text() == f"{row['points_for']}-{row['points_against']}"
        assert cell["faults"].text() == str(row["faults"])
        assert cell["forfeits"].text() == str(row["forfeits"])
        assert float(cell["elo"].text()) == row["elo"]
        low, high = cell["interval"].text().split(" to ")
        assert (float(low), float(high)) == (row["elo_low"], row["elo_high"])
        assert row["elo_low"] <= row["elo"] + 0.1 and row["elo"] - 0.1 <= row["elo_high"]
    # the matrix: rows and columns in table order, each cell the row bot's record
    order = [row["bot"] for row in results["table"]]
    grid = page.root.find("table", "matrix").find("tbody").find_all("tr")
    for a, tr in zip(order, grid, strict=True):
        cells = tr.find_all("td")
        assert len(cells) == len(order)
        for b, td in zip(order, cells):
            wins, draws, losses, pf, pa = record_of(matches, a, b)
            if a == b:
                assert td.classes() == ["self"] and td.text() == ""
            elif wins + draws + losses == 0:
                assert td.classes() == ["none"] and td.text() == ""
            else:
                assert td.text() == f"{wins}-{draws}-{losses}"
                share = (wins + draws / 2) / (wins + draws + losses)
                assert td.classes() == [f"h{int(share * 10 + 0.5)}"]
                assert f"points {pf}-{pa}" in td.get("title")
    legend = page.root.find("div", "legend")
    assert [s.classes() for s in legend.find_all("span")][1:] == \
        [[f"h{k}"] for k in range(11)] + [["none"]]
    # every match, in order, with its numbers
    shown = [{k: v for k, v in m.items() if k not in ("name", "number", "round", "page",
                                                        "replay")} for m in data["matches"]]
    assert shown == matches
    listed = next(t for t in page.root.find_all("tbody") if t.get("id") == "match-rows")
    trs = listed.find_all("tr")
    assert len(trs) == len(matches)
    for tr, m in zip(trs, matches):
        cell = {c.classes()[0]: c for c in tr.find_all("td")}
        assert cell["score"].text() == f"{m['score'][0]}-{m['score'][1]}"
        assert cell["frames"].text() == str(m["steps"]) and cell["seed"].text() == str(m["seed"])
        assert cell["faults"].text() == f"{m['faults'][0]}-{m['faults'][1]}"
    return page, data


# -- a tournament's pages ------------------------------------------------------------------------
def run_cli(capsys, args):
    assert main(args) == 0
    out = capsys.readouterr()
    return out.out, out.err


def test_tournament_pages_hold_the_report_and_link_only_existing_files(tmp_path, capsys):
    args = ["tournament", "--bots", ",".join(THREE), "--games", "1", "--rounds", "1",
            "--workers", "1", "--no-progress", "--json"]
    plain, _ = run_cli(capsys, args)
    pages = tmp_path / "new" / "pages"  # made, parents too
    out, err = run_cli(capsys, args + ["--html", str(pages)])
    assert out == plain  # the same report, byte for byte, and nothing else on stdout
    assert f"wrote {pages / 'index.html'}" in err
    report = json.loads(out)
    assert report["bootstrap"] == 200
    page, data = check_index_numbers(pages, report, report["matches"])
    assert data["kind"] == "tournament" and data["bots"] == THREE
    # with --html alone the replays are kept in DIR/replays, one a match, named by its place
    names = kept_replays.tournament_names(schedule(THREE, 1, 1))
    assert sorted(os.listdir(pages / "replays")) == sorted(n + ".json" for n in names)
    for entry, name in zip(data["matches"], names):
        assert entry["name"] == name and entry["replay"] == f"replays/{name}.json"
        assert (entry["page"] == f"matches/{name}.html") == player_there()
    for path in all_pages(pages):
        check_policy(Page(path))
        check_only_own_markup(Page(path))
        targets = links_resolve(path)
        assert len([t for t in targets if t.endswith(".json")]) >= 2
    assert sorted(os.listdir(pages / "bots")) == ["bot-001.html", "bot-002.html", "bot-003.html"]
    # a bot's page: its line of the table, its head-to-head row, its matches
    for number, bot in enumerate(THREE, 1):
        bot_page = Page(pages / "bots" / f"bot-{number:03d}.html")
        mine = bot_page.data()
        assert mine["bot"] == bot and mine["row"] == next(r for r in report["table"]
                                                          if r["bot"] == bot)
        assert [m["seed"] for m in mine["matches"]] == [
            m["seed"] for m in report["matches"] if bot in (m["p1"], m["p2"])]
        for opponent, *cell in mine["head_to_head"]:
            assert tuple(cell) == record_of(report["matches"], bot, opponent)
    if player_there():
        assert len(os.listdir(pages / "matches")) == len(names)
    else:
        assert not (pages / "matches").exists()


def test_tournament_intervals_are_the_seeded_bootstrap_and_leave_elo_and_order():
    bots = ["a", "b", "c", "d"]
    report = fabricated_report(bots, seed=3, bootstrap=200)
    assert _json(fabricated_report(bots, seed=3, bootstrap=200)) == _json(report)
    results = [(m["p1"], m["p2"], 0.5 if m["winner"] is None else
                1.0 if m["winner"] == m["p1"] else 0.0) for m in report["matches"]]
    elo = bradley_terry_elo(bots, results)
    intervals = bradley_terry_intervals(bots, report["matches"], 200, bootstrap_rng(3))
    for row in report["table"]:
        assert row["elo"] == round(elo[row["bot"]], 1)  # the full-matrix fit, as before
        _, low, high = intervals[row["bot"]]
        assert (row["elo_low"], row["elo_high"]) == (round(low, 1), round(high, 1))
        assert row["elo_low"] < row["elo"] < row["elo_high"]
    assert [r["bot"] for r in report["table"]] == sorted(
        bots, key=lambda b: (-round(elo[b], 1), b))
    other = fabricated_report(bots, seed=3, bootstrap=200, bootstrap_seed=4)
    assert [r["elo"] for r in other["table"]] == [r["elo"] for r in report["table"]]
    assert [r["elo_low"] for r in other["table"]] != [r["elo_low"] for r in report["table"]]
    none = fabricated_report(bots, seed=3, bootstrap=0)
    for row, bare in zip(report["table"], none["table"]):
        assert {k: v for k, v in row.items() if not k.startswith("elo_")} == \
            {k: v for k, v in bare.items() if not k.startswith("elo_")}
        assert abs(bare["elo_low"] - bare["elo"]) <= 0.1 and bare["elo_low"] == bare["elo_high"]
    with pytest.raises(ValueError, match="bootstrap must be an int >= 0"):
        run_tournament(THREE, bootstrap=-1, **QUICK)


def test_the_bootstrap_s_fits_together_are_each_fit_alone_bit_for_bit():
    """``bradley_terry_rows`` (the resamples fitted together, for speed) gives every row
    exactly what ``bradley_terry_sparse`` gives it alone: the league's intervals are
    unchanged by it, converged or stopped at the iteration limit."""
    from spacewar.arena.ratings import bradley_terry_rows, bradley_terry_sparse

    rng = np.random.default_rng(7)
    for k, pairs, iterations in ((3, 3, 2000), (9, 20, 2000), (40, 200, 2000), (6, 10, 7)):
        a = rng.integers(0, k - 1, pairs)
        b = np.minimum(a + 1 + rng.integers(0, k, pairs), k - 1)
        a_won = rng.integers(0, 4, (30, pairs)).astype(float)
        b_won = rng.integers(0, 4, (30, pairs)).astype(float) * (rng.random((30, pairs)) < 0.8)
        together = bradley_terry_rows(k, a, b, a_won, b_won, iterations)
        for row in range(30):
            alone = bradley_terry_sparse(k, a, b, a_won[row], b_won[row], iterations)
            assert np.array_equal(together[row], alone), (k, row)


# -- a league's pages ----------------------------------------------------------------------------
def test_league_pages_hold_the_results_and_the_results_are_the_same_without(tmp_path, capsys):
    base = ["league", "--bots", ",".join(THREE), "--rounds", "2", "--games", "1",
            "--match-rounds", "1", "--workers", "1", "--bootstrap", "20", "--json"]
    plain, _ = run_cli(capsys, base + ["--out", str(tmp_path / "plain.json")])
    pages = tmp_path / "pages"
    out, _ = run_cli(capsys, base + ["--out", str(tmp_path / "paged.json"), "--html",
                                     str(pages), "--replays", str(tmp_path / "kept")])
    assert out == plain
    assert (tmp_path / "paged.json").read_bytes() == (tmp_path / "plain.json").read_bytes()
    results = json.loads(out)
    matches = [m for r in results["rounds"] for m in r["matches"]]
    page, data = check_index_numbers(pages, results, matches)
    assert data["kind"] == "league"
    rows = page.root.find("table", "standings").find("tbody").find_all("tr")
    for tr, row in zip(rows, results["table"]):
        cell = {c.classes()[0]: c for c in tr.find_all("td")}
        for field in ("mu", "sigma", "ordinal"):
            assert cell[field].text() == f"{row[field]:.2f}"
        assert cell["byes"].text() == str(row["byes"])
    assert sum(row["byes"] for row in results["table"]) == 2  # three bots: a bye a round
    listed = next(t for t in page.root.find_all("tbody") if t.get("id") == "match-rows")
    assert [tr.find("td", "round").text() for tr in listed.find_all("tr")] == [
        str(r["round"]) for r in results["rounds"] for _ in r["matches"]]
    names = [kept_replays.league_match_name(r["round"], n, m["seed"])
             for r in results["rounds"] for n, m in enumerate(r["matches"], 1)]
    assert sorted(os.listdir(tmp_path / "kept")) == sorted(n + ".json" for n in names)
    assert not (pages / "replays").exists()  # --replays said where
    for entry, name in zip(data["matches"], names):
        assert entry["replay"] == f"../kept/{name}.json"
    for path in all_pages(pages):
        check_policy(Page(path))
        check_only_own_markup(Page(path))
        links_resolve(path)


def test_a_resumed_league_keeps_the_replays_of_the_rounds_it_plays(tmp_path):
    quick = dict(games=1, match_rounds=1, progress=False, workers=1, bootstrap=5)
    bots = ["idle", "random"]
    run_league(bots, 1, tmp_path / "l.json", replays=tmp_path / "kept", **quick)
    results = run_league(bots, 2, tmp_path / "l.json", replays=tmp_path / "kept", **quick)
    run_league(bots, 2, tmp_path / "straight.json", **quick)
    assert (tmp_path / "l.json").read_bytes() == (tmp_path / "straight.json").read_bytes()
    assert len(os.listdir(tmp_path / "kept")) == 4
    summary = league_pages.write_pages(tmp_path / "pages", results, tmp_path / "kept")
    assert summary["replays_missing"] == summary["replays_refused"] == 0
    data = Page(tmp_path / "pages" / "index.html").data()
    assert all(m["replay"] for m in data["matches"])


# -- strangers' names ----------------------------------------------------------------------------
def fabricated_report(bots, seed=5, bootstrap=20, bootstrap_seed=None, games=1):
    """A tournament's report of ``bots`` (through the tournament's own table) with made-up
    results: the pages do not look at how a result came about. ``bootstrap_seed``: the
    report's resamples drawn as if its seed were that one."""
    outcomes = []
    for k, (p1, p2, match_seed) in enumerate(schedule(bots, games, seed)):
        seat = k % 3 if k % 3 < 2 else None
        score = [1, 0] if seat == 0 else [0, 1] if seat == 1 else [1, 1]
        result = {"bots": [p1, p2], "winner": None if seat is None else (p1, p2)[seat],
                  "winner_seat": seat, "score": score, "steps": 100 + k, "seed": match_seed,
                  "forfeit": None, "forfeits": [False, False],
                  "faults": [{"total": k % 2}, {"total": 0}]}
        outcomes.append((result, {"wall_seconds": 0.0}))
    report, _ = tournament._report(bots, games, seed if bootstrap_seed is None else
                                   bootstrap_seed, 1, Rules(), outcomes, bootstrap)
    return dict(report, seed=seed)


def test_hostile_names_are_only_ever_text(tmp_path):
    report = fabricated_report(HOSTILE)
    # another run's replays under this run's names: never linked to these matches
    other = tmp_path / "other"
    other.mkdir()
    result, replay, _ = play_match("idle", "idle", seed=1, rounds=1, record=True)
    for name in kept_replays.tournament_names(schedule(HOSTILE, 1, 5)):
        save(kept_replays.replay_path(other, name), replay)
    summary = league_pages.write_pages(tmp_path / "pages", report, other)
    assert summary["replays_refused"] == len(report["matches"])
    assert summary["match_pages"] == 0 and not (tmp_path / "pages" / "matches").exists()
    for path in all_pages(tmp_path / "pages"):
        page = Page(path)
        check_policy(page)
        check_only_own_markup(page)
        links_resolve(path)
        # no raw direction override outside the data block (where no text is shown)
        assert "\u202e" not in page.source[:page.source.index('<script type="application')]
        data = page.data()  # the data block reads back with every name whole
        if "table" in data:
            assert data["table"] == report["table"] and data["bots"] == HOSTILE
            assert [{k: m[k] for k in ("p1", "p2", "winner")} for m in data["matches"]] == \
                [{k: m[k] for k in ("p1", "p2", "winner")} for m in report["matches"]]
            assert all(m["page"] is None and m["replay"] is None for m in data["matches"])
        else:
            assert data["bot"] in HOSTILE
        # each name is shown, escaped, in a span whose title holds it whole
        spans = page.root.find_all("span", "name")
        shown = {s.text() for s in spans}
        assert shown <= {printable(n) for n in HOSTILE}
        assert all(s.get("title") == s.text() for s in spans)
    index, _ = check_index_numbers(tmp_path / "pages", report, report["matches"])
    assert {s.text() for s in index.root.find_all("span", "name")} == {
        printable(n) for n in HOSTILE}
    shares = {td.classes()[0] for td in index.root.find("table", "matrix").find_all("td")}
    assert {"h3", "h8"} <= shares  # a quarter and three quarters, rounded half up


def test_a_name_that_is_not_utf_8_is_shown_and_kept_escaped(tmp_path):
    """A file name's undecodable bytes come as lone surrogates, which no page can hold: the
    name is shown, and kept in the data block, with them escaped."""
    odd = "bots/caf\udce9.py:Bot"
    report = fabricated_report(["idle", odd])
    league_pages.write_pages(tmp_path / "pages", report)
    index = Page(tmp_path / "pages" / "index.html")
    assert printable(odd) == "bots/caf\\udce9.py:Bot"
    assert printable(odd) in {s.text() for s in index.root.find_all("span", "name")}
    assert index.data()["bots"] == ["idle", printable(odd)]


def test_a_replay_the_player_refuses_is_linked_without_a_page(tmp_path, monkeypatch):
    from spacewar.replay import ReplayError

    report, _ = run_tournament(["idle", "random"], workers=1, replays=tmp_path / "kept",
                               **QUICK)

    def refusing(replay, out_path):
        raise ReplayError("too long for a page")

    monkeypatch.setattr(league_pages, "player_writer", lambda: refusing)
    summary = league_pages.write_pages(tmp_path / "pages", report, tmp_path / "kept")
    assert summary["player_refused"] == 2 and summary["match_pages"] == 0
    data = Page(tmp_path / "pages" / "index.html").data()
    assert all(m["page"] is None and m["replay"] for m in data["matches"])
    for path in all_pages(tmp_path / "pages"):
        links_resolve(path)


def test_a_hostile_bot_played_for_real_stays_text_on_every_page(tmp_path):
    folder = tmp_path / '"><img src=x onerror=alert(1)>' / "a</script><script>alert(1)<"
    folder.mkdir(parents=True)
    path = folder / "script>\u202e\x07.py"
    path.write_bytes(FAULTING)
    spec = f"{path}:Bot"
    report, _ = run_tournament([spec, "idle"], workers=1, max_faults=3,
                               replays=tmp_path / "pages" / "replays", **QUICK)
    assert {r["bot"]: r["forfeits"] for r in report["table"]} == {spec: 2, "idle": 0}
    summary = league_pages.write_pages(tmp_path / "pages", report, tmp_path / "pages" / "replays")
    assert summary["replays_missing"] == summary["replays_refused"] == 0
    for page_path in all_pages(tmp_path / "pages"):
        page = Page(page_path)
        check_policy(page)
        check_only_own_markup(page)
        links_resolve(page_path)
    bot_page = Page(tmp_path / "pages" / "bots" / "bot-001.html")
    assert bot_page.root.find("p", "fullname").text() == printable(spec)
    messages = [td.text() for td in bot_page.root.find_all("td", "message")]
    assert len(messages) == 2 and all(m.startswith("RuntimeError: <script>alert('fault')")
                                      and "\\u202e" in m for m in messages)
    assert bot_page.data()["faults"][0]["message"] == messages[0]
    if player_there():  # the player pages of the hostile bot's matches are there and linked
        assert len(os.listdir(tmp_path / "pages" / "matches")) == 2


# -- kept replays --------------------------------------------------------------------------------
def check_replays_are_the_matches(directory, report):
    """Each kept replay is its match played again, byte for byte, and checks."""
    names = kept_replays.tournament_names(
        [(m["p1"], m["p2"], m["seed"]) for m in report["matches"]])
    again = directory.parent / (directory.name + "-again")
    again.mkdir()
    for name, m in zip(names, report["matches"]):
        _, replay, _ = play_match(m["p1"], m["p2"], seed=m["seed"], rounds=report["rounds"],
                                  record=True)
        save(kept_replays.replay_path(again, name), replay)
        kept = kept_replays.replay_path(directory, name)
        with open(kept, "rb") as a, open(kept_replays.replay_path(again, name), "rb") as b:
            assert a.read() == b.read(), name
        assert load(kept)["bots"] == [m["p1"], m["p2"]]
    ok, details = check(load(kept_replays.replay_path(directory, names[0])))
    assert ok, details


def test_replays_from_worker_processes_are_the_matches_and_change_no_result(tmp_path):
    bots = ["idle", "random"]
    plain, _ = run_tournament(bots, workers=1, **QUICK)
    kept, _ = run_tournament(bots, workers=2, replays=tmp_path / "kept", **QUICK)
    assert _json(kept) == _json(plain)
    check_replays_are_the_matches(tmp_path / "kept", kept)


def test_replays_of_matches_played_together_are_each_match_alone(tmp_path):
    """A batch bot's pairing is one job, its matches played in one game
    (``jobs.group_jobs``): each match's replay is the one it records alone."""
    from spacewar.arena.jobs import group_jobs

    (tmp_path / "spinner.py").write_text(
        "import numpy as np\n\n\nclass Spinner:\n    def act_batch(self, obs):\n"
        "        return np.full(len(obs), 8, dtype=np.int64)  # turn left and fire\n")
    bots = [f"{tmp_path / 'spinner.py'}:Spinner", "idle"]
    assert [together for _, together in group_jobs(
        schedule(bots, 1, 1), "auto", frozenset(bots[:1]))] == [True]
    plain, _ = run_tournament(bots, workers=1, **QUICK)
    kept, _ = run_tournament(bots, workers=1, replays=tmp_path / "kept", **QUICK)
    assert _json(kept) == _json(plain)
    check_replays_are_the_matches(tmp_path / "kept", kept)


@pytest.fixture(scope="module")
def dask_cluster(optional):
    from engine import cluster

    distributed = optional("distributed")
    cluster.warm_up(["spacewar.arena.jobs:warm_up_game"])
    with distributed.LocalCluster(n_workers=1, processes=True, threads_per_worker=1,
                                  dashboard_address=":0") as local:
        yield local


def test_replays_come_back_from_the_cluster_with_the_client_s_names(tmp_path, dask_cluster):
    (tmp_path / "bots").mkdir()
    (tmp_path / "bots" / "mover.py").write_bytes(
        b"from spacewar import Action\n\n\nclass Bot:\n    def act(self, obs):\n"
        b"        return Action(turn=1, thrust=True, fire=True)\n")
    bots = [f"{tmp_path / 'bots' / 'mover.py'}:Bot", "idle"]
    plain, _ = run_tournament(bots, workers=1, **QUICK)
    remote, _ = run_tournament(bots, scheduler=dask_cluster.scheduler_address,
                               replays=tmp_path / "kept", **QUICK)
    assert _json(remote) == _json(plain)
    check_replays_are_the_matches(tmp_path / "kept", remote)
    quick = dict(games=1, match_rounds=1, progress=False, bootstrap=5)
    run_league(bots, 1, tmp_path / "local.json", workers=1, replays=tmp_path / "lk", **quick)
    run_league(bots, 1, tmp_path / "remote.json", scheduler=dask_cluster.scheduler_address,
               replays=tmp_path / "rk", **quick)
    assert (tmp_path / "remote.json").read_bytes() == (tmp_path / "local.json").read_bytes()
    assert sorted(os.listdir(tmp_path / "rk")) == sorted(os.listdir(tmp_path / "lk"))
    for name in os.listdir(tmp_path / "lk"):
        assert (tmp_path / "rk" / name).read_bytes() == (tmp_path / "lk" / name).read_bytes()


# -- bad paths fail first ------------------------------------------------------------------------
@pytest.fixture
def no_match(monkeypatch):
    """Records any attempt to play a match (there must be none)."""
    from spacewar.arena.runner import MatchRunner

    played = []
    monkeypatch.setattr(MatchRunner, "play", lambda self, *a, **k: played.append(a))
    return played


def test_bad_output_paths_fail_before_any_match(tmp_path, capsys, no_match):
    a_file = tmp_path / "a-file"
    a_file.write_text("not a directory\n")
    png = tmp_path / "has-png"
    png.mkdir()
    (png / "index.html").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(32))
    taken = tmp_path / "taken"
    taken.mkdir()
    first = kept_replays.tournament_names(schedule(["idle", "random"], 1, 1))[0]
    (taken / (first + ".json")).write_bytes(b"GIF89a" + bytes(16))
    league_taken = tmp_path / "league-taken"
    league_taken.mkdir()
    # the league's first round pairs idle and random (two bots), its first match's name:
    from spacewar.arena.league import league_config
    from spacewar.arena.pairings import pair_round, round_schedule, state_after
    from spacewar.sandbox.limits import Limits

    config = league_config(["idle", "random"], 1, "swiss", 1, 1, Rules(), Limits(), 25, "auto")
    planned = round_schedule(config, 0, pair_round(config, 0, *state_after(config, []))[0])
    (league_taken / (kept_replays.league_round_names(1, planned)[0] + ".json")).write_bytes(
        b"GIF89a" + bytes(16))
    tournament_args = ["tournament", "--bots", "idle,random", "--games", "1", "--rounds", "1",
                       "--workers", "1", "--no-progress"]
    league_args = ["league", "--bots", "idle,random", "--rounds", "1", "--games", "1",
                   "--match-rounds", "1", "--workers", "1", "--no-progress", "--out",
                   str(tmp_path / "league.json")]
    for args, where in [
            (tournament_args + ["--html", str(a_file)], a_file),
            (tournament_args + ["--html", str(png)], png / "index.html"),
            (tournament_args + ["--replays", str(a_file)], a_file),
            (tournament_args + ["--replays", str(taken)], taken / (first + ".json")),
            (tournament_args + ["--html", str(tmp_path / "p"), "--replays", str(taken)],
             taken / (first + ".json")),
            (league_args + ["--html", str(a_file)], a_file),
            (league_args + ["--replays", str(a_file)], a_file),
            (league_args + ["--replays", str(league_taken)], league_taken)]:
        assert main(args) == 2, args
        err = capsys.readouterr().err
        assert "error" in err and str(where) in err, (args, err)
    assert no_match == []
    assert not (tmp_path / "league.json").exists()
    assert (png / "index.html").read_bytes().startswith(b"\x89PNG")
    assert (taken / (first + ".json")).read_bytes().startswith(b"GIF89a")


def test_match_pages_are_written_and_linked_only_when_the_player_is_there(tmp_path,
                                                                          monkeypatch):
    report, _ = run_tournament(["idle", "random"], workers=1, replays=tmp_path / "kept",
                               **QUICK)
    monkeypatch.setattr(league_pages, "player_writer", lambda: None)
    summary = league_pages.write_pages(tmp_path / "without", report, tmp_path / "kept")
    assert summary["match_pages"] == 0 and not (tmp_path / "without" / "matches").exists()
    index = Page(tmp_path / "without" / "index.html")
    assert not [a for a in index.root.find_all("a") if "matches/" in a.get("href")]
    assert all(m["page"] is None and m["replay"] for m in index.data()["matches"])
    written = []

    def player(replay, out_path):  # stands for spacewar.view.player_page.write_player
        written.append(load(replay)["seed"])  # given the kept replay's path
        with open(out_path, "w") as f:
            f.write("<!DOCTYPE html><title>player</title>\n")

    monkeypatch.setattr(league_pages, "player_writer", lambda: player)
    summary = league_pages.write_pages(tmp_path / "with", report, tmp_path / "kept")
    assert summary["match_pages"] == 2 and written == [m["seed"] for m in report["matches"]]
    for path in all_pages(tmp_path / "with"):
        links_resolve(path)
    index = Page(tmp_path / "with" / "index.html")
    assert [a.get("href") for a in index.root.find_all("a") if "matches/" in a.get("href")] == \
        [f"matches/{n}.html" for n in kept_replays.tournament_names(
            [(m["p1"], m["p2"], m["seed"]) for m in report["matches"]])]


def test_a_large_run_has_no_matrix_but_every_bot_its_row(tmp_path, monkeypatch):
    monkeypatch.setattr(league_pages, "MATRIX_MAX_BOTS", 3)
    bots = ["b0", "b1", "b2", "b3"]
    report = fabricated_report(bots)
    league_pages.write_pages(tmp_path / "pages", report)
    index = Page(tmp_path / "pages" / "index.html")
    assert not index.root.find_all("table", "matrix")
    assert "4 bots" in index.root.find("p", "note").text()
    bot_page = Page(tmp_path / "pages" / "bots" / "bot-001.html")
    assert len(bot_page.root.find("table", "h2h").find("tbody").find_all("tr")) == 3


def test_player_pages_written_by_several_processes_are_the_same_bytes(tmp_path):
    report, _ = run_tournament(["idle", "random", "chaser"], workers=1,
                               replays=tmp_path / "kept", **QUICK)
    one = league_pages.write_pages(tmp_path / "one", report, tmp_path / "kept", workers=1)
    two = league_pages.write_pages(tmp_path / "two", report, tmp_path / "kept", workers=2)
    assert one["match_pages"] == two["match_pages"] == len(report["matches"]) > 1
    files = sorted(p.relative_to(tmp_path / "one") for p in (tmp_path / "one").rglob("*.html"))
    assert files == sorted(p.relative_to(tmp_path / "two")
                           for p in (tmp_path / "two").rglob("*.html"))
    for name in files:
        assert (tmp_path / "one" / name).read_bytes() == (tmp_path / "two" / name).read_bytes()


def test_the_pages_are_written_without_the_player_module(tmp_path, monkeypatch):
    """With spacewar.view.player_page not importable at all (not only unused), the pages are
    written, each match linked to its replay and to no player page."""
    import sys

    report, _ = run_tournament(["idle", "random"], workers=1, replays=tmp_path / "kept",
                               **QUICK)
    monkeypatch.setitem(sys.modules, "spacewar.view.player_page", None)
    summary = league_pages.write_pages(tmp_path / "pages", report, tmp_path / "kept")
    assert summary["match_pages"] == 0 and summary["replays_missing"] == 0
    assert not (tmp_path / "pages" / "matches").exists()
