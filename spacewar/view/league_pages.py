"""The pages of a tournament or a league (``spacewar tournament ... --html DIR``, ``spacewar
league ... --html DIR``): static HTML files that a file browser or any static server opens,
each carrying its own data (a JSON data block), fetching nothing.

- ``DIR/index.html``: the standings (rank, bot, played, W-D-L, points, faults, forfeits, the
  Bradley-Terry Elo and its 95% interval; for a league also byes and openskill's mu, sigma and
  ordinal), the head-to-head matrix (up to ``MATRIX_MAX_BOTS`` bots) and every match, each
  linked to its player page and its replay when they were kept;
- ``DIR/bots/bot-001.html``, ...: a page a bot, numbered by its place in the run's list of bots
  (never named by it): its full name, its line of the standings, its head-to-head record
  against each opponent, its matches, and the first fault of each of its faulted matches (the
  message, from the kept replay);
- ``DIR/matches/<match>.html``: the player page of each match whose replay was kept
  (``spacewar.view.player_page.write_player``), when that module is there; without it no match
  page is written and none is linked;
- ``DIR/replays/<match>.json``: the replays, when no other directory was given for them.

``<match>`` is the replay's name (``spacewar.arena.kept_replays``: the match's place and seed).
A kept replay is linked only when it is this match's (its bots, seed, score, winner and frames
are the record's): a directory that holds another run's files links none of them.

**A page a bot, not a section a bot on the index**: a bot's section would list its matches
again, so the index would hold every match three times and grow with bots x matches; a page a
bot keeps the index to the table, the matrix and one line a match, and each bot's page to its
own matches (what a bot's author opens).

**Strangers' text stays text.** Bot names (a submission's path), fault messages and whatever
a replay holds are put on a page only escaped (``spacewar.faults.printable``, which shows
control and format characters such as U+202E as escapes, then ``html_page.text``), or inside
the JSON data block (``html_page.data_block``). A long name is cut on screen by CSS (its
``title`` holds the whole escaped name, as does the bot's own page). The pages' only script
(``assets/league.js``, a filter over the matches) reads and writes ``textContent``.

**The matrix.** The cell of row bot A and column bot B holds A's wins, draws and losses
against B (every seat and round together), coloured by A's score share, (wins + draws / 2) /
matches, to the nearest tenth (halves up): eleven classes ``h0`` (0%) to ``h10`` (100%),
orange for A's losses through grey to blue for A's wins (the two ships' colours). Colours come
from classes of ``assets/league.css``: the pages' policy allows no inline ``style``.
"""
import math
import os
import time
from urllib.parse import quote

from engine.atomic import check_output_dir

from spacewar.arena import kept_replays
from spacewar.arena.ratings import match_outcome
from spacewar.faults import printable
from spacewar.view.html_page import (check_page_path, package_text, page, text, visible,
                                     write_page)

#: above this many bots the index has no matrix (each bot's page has its row of it)
MATRIX_MAX_BOTS = 200

#: the element id of every page's JSON data block
DATA_ID = "league-data"

BOTS_DIR = "bots"
MATCHES_DIR = "matches"
REPLAYS_DIR = "replays"


def player_writer():
    """``spacewar.view.player_page.write_player``, or None when that module is not there."""
    try:
        from spacewar.view.player_page import write_player
    except ModuleNotFoundError as exc:
        if exc.name != f"{__package__}.player_page":
            raise  # the module is there, something it needs is not: say so
        return None
    return write_player


def check_pages_dir(directory):
    """``directory`` checked before any match is played: an existing writable directory or
    one that can be made, whose ``index.html`` (if any) is a page to replace and whose
    ``bots`` and ``matches`` (if any) are writable directories. Nothing is made here."""
    directory = check_output_dir(directory)
    if os.path.isdir(directory):
        check_page_path(os.path.join(directory, "index.html"))
        for sub in (BOTS_DIR, MATCHES_DIR):
            if os.path.lexists(os.path.join(directory, sub)):
                check_output_dir(os.path.join(directory, sub))
    return directory


def default_replays(directory):
    """Where the replays of a run with pages and no replay directory of its own are kept."""
    return os.path.join(directory, REPLAYS_DIR)


def bot_page(index):
    """The file of the page of the bot at ``index`` (from 0) of the run's list of bots."""
    return f"bot-{index + 1:03d}.html"


def share_class(wins, draws, losses):
    """The matrix class of a record: ``h0`` .. ``h10`` by score share, to the nearest tenth."""
    share = (wins + 0.5 * draws) / (wins + draws + losses)
    return f"h{int(math.floor(share * 10 + 0.5))}"


# -- the run as the pages show it ------------------------------------------------------------
def run_model(results):
    """A tournament's report or a league's results as the pages show them: ``kind``, ``title``,
    ``facts`` (lines of settings), ``notes`` (a league resumed from unverified files),
    ``bots`` (the run's list), ``table`` (the standings, as given), ``matches`` (each record
    with its ``name``, ``number`` and ``round``: None in a tournament) and ``bootstrap``."""
    from spacewar.arena.league import resumed_note

    if results.get("format") == "spacewar-league":
        config = results["config"]
        matches = [dict(m, name=kept_replays.league_match_name(r["round"], n, m["seed"]),
                        number=n, round=r["round"])
                   for r in results["rounds"] for n, m in enumerate(r["matches"], 1)]
        facts = [f"League: {len(config['bots'])} bots, {results['rounds_played']} "
                 f"{config['pairing']} rounds, {len(matches)} matches of "
                 f"{config['match_rounds']} rounds, {config['games']} seeds per pairing in both "
                 f"seat orders, seed {config['seed']}, mode {config['rules']['mode']}",
                 "Ranked by openskill's ordinal (mu - 3 sigma); Elo: the Bradley-Terry fit "
                 "of all matches, its 95% interval from a bootstrap over matches"]
        return {"kind": "league", "title": "League", "facts": facts,
                "notes": [resumed_note(e) for e in results.get("resumed_from", [])],
                "bots": list(config["bots"]), "table": results["table"], "matches": matches}
    matches = [dict(m, name=kept_replays.tournament_match_name(n, m["seed"]), number=n,
                    round=None) for n, m in enumerate(results["matches"], 1)]
    bootstrap = results.get("bootstrap")
    facts = [f"Round robin: {len(results['bots'])} bots, {results['games_per_pairing']} seeds "
             f"per pair in both seat orders, {len(matches)} matches of {results['rounds']} "
             f"rounds, seed {results['seed']}, mode {results['rules']['mode']}",
             "Elo: the Bradley-Terry fit of all matches" + (
                 f"; its 95% interval from {bootstrap} bootstrap resamples of the matches "
                 "(seeded by the tournament's seed)" if bootstrap else "")]
    return {"kind": "tournament", "title": "Tournament", "facts": facts, "notes": [],
            "bots": list(results["bots"]), "table": results["table"], "matches": matches}


def head_to_head(matches):
    """``{(a, b): [wins, draws, losses, points_for, points_against]}`` of bot ``a`` against
    bot ``b`` over ``matches`` (both seats; a draw is a match without a winner)."""
    record = {}
    for m in matches:
        outcome = match_outcome(m)
        for seat, (me, other) in enumerate(((m["p1"], m["p2"]), (m["p2"], m["p1"]))):
            mine = outcome if seat == 0 else 1.0 - outcome
            cell = record.setdefault((me, other), [0, 0, 0, 0, 0])
            cell[0 if mine == 1.0 else 2 if mine == 0.0 else 1] += 1
            cell[3] += m["score"][seat]
            cell[4] += m["score"][1 - seat]
    return record


# -- pieces of HTML (every stranger's string through _shown) ---------------------------------
def _shown(value):
    """A stranger's string as page text: control and format characters made visible, then
    HTML-escaped."""
    return text(visible(value))


def _name(name, href=None):
    """A bot's name, cut on screen to a width by CSS, whole (escaped) in its title."""
    shown = _shown(name)
    inner = f'<span class="name" title="{shown}">{shown}</span>'
    return f'<a href="{text(href)}">{inner}</a>' if href else inner


def _head(label, is_bot):
    return f'<th class="bot">{label}</th>' if is_bot else f"<th>{label}</th>"


def _cells(pairs):
    return "".join(f'<td class="{cls}">{value}</td>' for cls, value in pairs)


def _standings(model, pages, prefix, only=None):
    """The standings table (``only``: the row of that bot alone)."""
    league = model["kind"] == "league"
    head = ["rank", "bot", "played", "W-D-L", "points", "faults", "forfeits"]
    head += ["byes", "mu", "sigma", "ordinal"] if league else []
    head += ["Elo", "95% interval"]
    rows = []
    for rank, row in enumerate(model["table"], 1):
        if only is not None and row["bot"] != only:
            continue
        bot = _name(row["bot"], prefix + pages[row["bot"]])
        cells = [("rank", rank), ("bot", bot), ("played", row["played"]),
                 ("record", f"{row['wins']}-{row['draws']}-{row['losses']}"),
                 ("points", f"{row['points_for']}-{row['points_against']}"),
                 ("faults", row["faults"]), ("forfeits", row["forfeits"])]
        if league:
            cells += [("byes", row["byes"]), ("mu", f"{row['mu']:.2f}"),
                      ("sigma", f"{row['sigma']:.2f}"), ("ordinal", f"{row['ordinal']:.2f}")]
        cells += [("elo", f"{row['elo']:.1f}"),
                  ("interval", f"{row['elo_low']:.1f} to {row['elo_high']:.1f}")]
        rows.append(f"<tr>{_cells(cells)}</tr>")
    heads = "".join(_head(h, h == "bot") for h in head)
    return (f'<div class="scroll"><table class="standings"><thead><tr>{heads}</tr></thead>'
            f'<tbody>{"".join(rows)}</tbody></table></div>')


def _legend():
    swatches = "".join(f'<span class="h{k}">{10 * k}%</span>' for k in range(11))
    return ('<div class="legend"><span class="label">row bot\'s score share against the '
            'column bot (a win 1, a draw 1/2):</span>'
            f'{swatches}<span class="none">never met</span></div>')


def _record_cell(cell, tag="td"):
    wins, draws, losses, points_for, points_against = cell
    share = (wins + 0.5 * draws) / (wins + draws + losses)
    title = (f"won {wins}, drawn {draws}, lost {losses}: score share {100 * share:.0f}%; "
             f"points {points_for}-{points_against}")
    return (f'<{tag} class="{share_class(wins, draws, losses)}" title="{title}">'
            f"{wins}-{draws}-{losses}</{tag}>")


def _matrix(model, record, pages):
    order = [row["bot"] for row in model["table"]]
    if len(order) > MATRIX_MAX_BOTS:
        return (f'<p class="note">{len(order)} bots: the matrix would have {len(order) ** 2} '
                f"cells, more than a page should hold (at most {MATRIX_MAX_BOTS} bots); each "
                "bot's page has its row.</p>")
    cols = "".join(f'<th class="col" title="{_shown(b)}">{rank}</th>'
                   for rank, b in enumerate(order, 1))
    rows = []
    for rank, a in enumerate(order, 1):
        cells = []
        for b in order:
            if a == b:
                cells.append('<td class="self"></td>')
            elif (a, b) in record:
                cells.append(_record_cell(record[(a, b)]))
            else:
                cells.append('<td class="none"></td>')
        rows.append(f'<tr><th class="row">{rank} {_name(a, pages[a])}</th>{"".join(cells)}</tr>')
    return (_legend() + f'<div class="scroll"><table class="matrix"><thead><tr><th></th>{cols}'
            f'</tr></thead><tbody>{"".join(rows)}</tbody></table></div>')


def _result_text(m):
    if all(m["forfeits"]):
        return '<span class="forfeit">no winner: both forfeited</span>'
    if any(m["forfeits"]):
        seat = m["forfeits"].index(True) + 1
        return (f'seat {3 - seat} wins: <span class="forfeit">seat {seat} forfeited</span>')
    if m["winner"] is None:
        return "draw"
    return f"seat {1 if m['winner'] == m['p1'] else 2} wins"


def _matches(model, matches, links, pages, prefix):
    """The list of ``matches``, each linked to its player page and replay (``links``)."""
    league = model["kind"] == "league"
    head = ["match"] + (["round"] if league else []) + [
        "seat 1 (needle)", "score", "seat 2 (wedge)", "result", "faults", "frames", "seed",
        "player", "replay"]
    rows = []
    for m in matches:
        outcome = match_outcome(m)
        classes = (("won", "lost") if outcome == 1.0 else ("lost", "won") if outcome == 0.0
                   else ("", ""))
        page_link, replay_link = links.get(m["name"], (None, None))
        cells = [("number", m["number"])] + ([("round", m["round"])] if league else []) + [
            (f"bot p1 {classes[0]}".strip(), _name(m["p1"], prefix + pages[m["p1"]])),
            ("score", f"{m['score'][0]}-{m['score'][1]}"),
            (f"bot p2 {classes[1]}".strip(), _name(m["p2"], prefix + pages[m["p2"]])),
            ("result", _result_text(m)),
            ("faults", f"{m['faults'][0]}-{m['faults'][1]}"),
            ("frames", m["steps"]), ("seed", m["seed"]),
            ("player", f'<a href="{text(prefix + page_link)}">play</a>' if page_link else ""),
            ("replay", f'<a href="{text(prefix + replay_link)}">json</a>' if replay_link
             else "")]
        rows.append(f"<tr>{_cells(cells)}</tr>")
    heads = "".join(_head(h, h.startswith("seat")) for h in head)
    return ('<p><input type="search" id="match-filter" hidden aria-label="filter the matches" '
            'placeholder="filter: words of a name, a round, a seed"><span id="match-count" '
            f'class="count">{len(matches)} matches</span></p>'
            f'<div class="scroll"><table class="matches"><thead><tr>{heads}</tr></thead>'
            f'<tbody id="match-rows">{"".join(rows)}</tbody></table></div>')


def _faults(entries):
    """A bot's faulted matches: the first fault of each (from its kept replay)."""
    if not entries:
        return "<p class=\"facts\">No fault, or no kept replay of a faulted match.</p>"
    rows = "".join(
        "<tr>" + _cells([("number", e["number"]), ("round", "" if e["round"] is None else
                                                     e["round"]),
                         ("faults", e["total"]), ("frame", e["frame"]),
                         ("kind", _shown(e["kind"])), ("message", _shown(e["message"]))])
        + "</tr>" for e in entries)
    return ('<div class="scroll"><table class="faults"><thead><tr><th>match</th><th>round</th>'
            '<th>faults</th><th>first at frame</th><th>kind</th><th class="bot">message</th>'
            f"</tr></thead><tbody>{rows}</tbody></table></div>")


def _document(title, body, data, code):
    """A whole page: ``code`` is ``(script, style)``, the assets' texts."""
    script, style = code
    return page(title, f"<main>{body}</main>", scripts=[script], styles=[style],
                data={DATA_ID: data})


def _data_match(m, links):
    page_link, replay_link = links.get(m["name"], (None, None))
    return dict(m, page=page_link, replay=replay_link)


# -- the replays: found, checked to be the match's, made into player pages --------------------
def _is_this_match(replay, m):
    result = replay.get("result", {})
    return (replay.get("bots") == [m["p1"], m["p2"]] and replay.get("seed") == m["seed"]
            and result.get("score") == m["score"] and result.get("winner") == m["winner"]
            and result.get("steps") == m["steps"])


def _link(path, directory):
    """A relative link from a page of ``directory`` to the file ``path``."""
    relative = os.path.relpath(os.path.abspath(path), os.path.abspath(directory))
    return quote(relative.replace(os.sep, "/"))


def _replays(directory, model, replays, writer, summary, workers=1):
    """``({match name: (player page link, replay link)}, {bot: [first faults]})``: each kept
    replay that is its match's, made into a player page when ``writer`` (on ``workers``
    processes: a page re-simulates its match, the pages are independent)."""
    from spacewar.replay import ReplayError, load

    links, faults, pages = {}, {}, []
    if replays is None:
        return links, faults
    for m in model["matches"]:
        path = kept_replays.replay_path(replays, m["name"])
        if not os.path.isfile(path):
            summary["replays_missing"] += 1
            continue
        try:
            replay = load(path)
        except ReplayError:
            summary["replays_refused"] += 1
            continue
        if not _is_this_match(replay, m):
            summary["replays_refused"] += 1
            continue
        if writer is not None:
            os.makedirs(os.path.join(directory, MATCHES_DIR), exist_ok=True)
            pages.append((m["name"], path, os.path.join(directory, MATCHES_DIR,
                                                        m["name"] + ".html")))
        links[m["name"]] = (None, _link(path, directory))
        for seat, bot in enumerate((m["p1"], m["p2"])):
            examples = replay["result"]["faults"][seat].get("examples") or []
            if m["faults"][seat] and examples:
                faults.setdefault(bot, []).append(
                    {"number": m["number"], "round": m["round"], "total": m["faults"][seat],
                     "frame": examples[0]["frame"], "kind": examples[0]["kind"],
                     "message": examples[0]["message"]})
    for (name, _, out), written in zip(pages, _player_pages(pages, writer, workers)):
        if written is None:  # one the player refuses (too long to hold): no page
            summary["player_refused"] += 1
            continue
        summary["match_pages"] += 1
        summary["bytes"] += written
        links[name] = (f"{MATCHES_DIR}/{name}.html", links[name][1])
    return links, faults


def _player_pages(pages, writer, workers):
    """The bytes of each player page written (None: refused), in the order of ``pages``
    (``(name, replay path, page path)``); in a pool of ``workers`` processes when more than
    one and more than one page."""
    jobs = [(path, out) for _, path, out in pages]
    if not jobs:
        return []
    try:  # another process writes with the real player only: any other writer (a test's) here
        from spacewar.view.player_page import write_player
    except ImportError:
        write_player = None
    if workers <= 1 or len(jobs) <= 1 or write_player is None or writer is not write_player:
        return [_one_player_page(job, writer) for job in jobs]
    import concurrent.futures
    import multiprocessing

    with concurrent.futures.ProcessPoolExecutor(
            max_workers=min(workers, len(jobs)),
            mp_context=multiprocessing.get_context("spawn")) as pool:
        chunk = max(1, len(jobs) // (8 * workers))
        return list(pool.map(_one_player_page, jobs, chunksize=chunk))


def _one_player_page(job, writer=None):
    """Write one player page (``job``: replay path, page path); its bytes, or None if the
    player refuses the replay."""
    from spacewar.replay import ReplayError

    writer = player_writer() if writer is None else writer
    replay_path, out = job
    try:
        writer(replay_path, out)
    except ReplayError:
        return None
    return os.path.getsize(out)


def _data_text(value):
    """A string for a data block: as it is, unless it cannot be written as UTF-8 (a lone
    surrogate, from a file name's undecodable bytes): then with its characters escaped."""
    try:
        value.encode("utf-8")
        return value
    except UnicodeEncodeError:
        return printable(value)


def _clean(value):
    """``value`` with every string fit for a data block (``_data_text``)."""
    if isinstance(value, str):
        return _data_text(value)
    if isinstance(value, dict):
        return {_clean(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    return value


# -- the pages --------------------------------------------------------------------------------
def write_pages(directory, results, replays=None, player=True, workers=None):
    """Write the pages of ``results`` (a tournament's report or a league's results) into
    ``directory`` (made if missing), linking each match to its replay in ``replays`` (a
    directory, or None) and to its player page, written when ``player`` and the player
    module is there. Returns a summary: ``index`` (its path), ``bot_pages``,
    ``match_pages``, ``replays_missing``, ``replays_refused`` (unreadable, or another
    match's), ``player_refused`` (replays the player cannot hold: linked, with no page),
    ``bytes`` (of every page written) and ``seconds``. ``workers``: processes writing the
    player pages (default: one per core)."""
    start = time.perf_counter()
    directory = check_pages_dir(directory)
    model = run_model(results)
    writer = player_writer() if player else None
    summary = {"index": os.path.join(directory, "index.html"), "bot_pages": 0,
               "match_pages": 0, "replays_missing": 0, "replays_refused": 0,
               "player_refused": 0, "bytes": 0}
    os.makedirs(os.path.join(directory, BOTS_DIR), exist_ok=True)
    workers = (os.cpu_count() or 1) if workers is None else int(workers)
    links, faults = _replays(directory, model, replays, writer, summary, workers)
    bots = model["bots"]
    pages = {b: f"{BOTS_DIR}/{bot_page(i)}" for i, b in enumerate(bots)}
    record = head_to_head(model["matches"])
    rank = {row["bot"]: r for r, row in enumerate(model["table"], 1)}
    order = [row["bot"] for row in model["table"]]
    played = {b: [] for b in bots}
    for m in model["matches"]:
        played[m["p1"]].append(m)
        played[m["p2"]].append(m)

    code = (package_text("league.js"), package_text("league.css"))

    def written(path, document):
        write_page(path, document)
        summary["bytes"] += len(document.encode("utf-8"))

    for i, bot in enumerate(bots):
        mine = played[bot]
        opponents = [b for b in order if (bot, b) in record]
        h2h_rows = "".join(
            f'<tr><td class="rank">{rank[b]}</td><td class="bot">{_name(b, "../" + pages[b])}'
            f"</td>{_record_cell(record[(bot, b)])}<td class=\"points\">"
            f"{record[(bot, b)][3]}-{record[(bot, b)][4]}</td></tr>" for b in opponents)
        body = (f'<nav><a href="../index.html">standings</a></nav>'
                f"<h1>{_shown(model['title'])}: bot {i + 1}, rank {rank[bot]}</h1>"
                f'<p class="fullname">{_shown(bot)}</p>'
                + _standings(model, pages, "../", only=bot)
                + "<h2>Against each opponent</h2>" + _legend()
                + ('<div class="scroll"><table class="h2h"><thead><tr><th>rank</th>'
                   '<th class="bot">opponent</th><th>W-D-L</th><th>points</th></tr></thead>'
                   f"<tbody>{h2h_rows}</tbody></table></div>")
                + "<h2>Matches</h2>" + _matches(model, mine, links, pages, "../")
                + "<h2>Faults</h2>" + _faults(faults.get(bot, [])))
        data = _clean({"kind": model["kind"], "bot": bot, "number": i + 1, "rank": rank[bot],
                       "row": model["table"][rank[bot] - 1],
                       "head_to_head": [[b] + record[(bot, b)] for b in opponents],
                       "matches": [_data_match(m, links) for m in mine],
                       "faults": faults.get(bot, [])})
        title = f"{model['title']}: {printable(bot)[:60]}"
        written(os.path.join(directory, pages[bot]), _document(title, body, data, code))
        summary["bot_pages"] += 1

    facts = "".join(f'<p class="facts">{_shown(f)}</p>' for f in model["facts"])
    notes = "".join(f'<p class="note">{_shown(n)}</p>' for n in model["notes"])
    body = (f"<h1>{_shown(model['title'])}</h1>{facts}{notes}<h2>Standings</h2>"
            + _standings(model, pages, "") + "<h2>Head to head</h2>"
            + _matrix(model, record, pages) + "<h2>Matches</h2>"
            + _matches(model, model["matches"], links, pages, ""))
    order_index = {b: k for k, b in enumerate(order)}
    data = _clean({"kind": model["kind"], "facts": model["facts"], "notes": model["notes"],
                   "bots": bots, "table": model["table"],
                   "matrix": {"order": order, "cells": [
                       [order_index[a], order_index[b]] + cell
                       for (a, b), cell in sorted(record.items(), key=lambda item: (
                           order_index[item[0][0]], order_index[item[0][1]]))]},
                   "matches": [_data_match(m, links) for m in model["matches"]],
                   "bot_pages": [pages[b] for b in bots]})
    written(summary["index"], _document(model["title"], body, data, code))
    summary["seconds"] = time.perf_counter() - start
    return summary
