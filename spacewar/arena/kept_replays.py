"""The replays a tournament or a league keeps (``--replays DIR``): one JSON replay file a match
(``spacewar.replay.save``: checked, signed with this user's key, written atomically), named by
the match's place in the run and its seed, never by a bot's name (names are strangers' text:
``/``, ``..``, control characters, 10,000 characters).

- a tournament's match ``n`` (from 1, in schedule order: ``report["matches"][n - 1]``):
  ``match-00001-seed-3070458474.json``;
- a league's match ``n`` (from 1) of round ``r`` (from 1): ``round-001-match-0001-seed-....json``.

The name is a function of the match's place and seed alone, so the results (which hold no
path) are the same with and without replays kept, and the pages of a run
(``spacewar.view.league_pages``) find each match's replay from the results alone. The
directory and every file name of a round are checked before any of its matches is played
(``engine.atomic``: an existing file of another kind is never replaced).
"""
import os

from engine.atomic import check_output_dir, check_output_path

#: the extension of a kept replay file
EXTENSION = ".json"


def tournament_match_name(number, seed):
    """The file stem of a tournament's match ``number`` (from 1) played with ``seed``."""
    return f"match-{int(number):05d}-seed-{int(seed)}"


def league_match_name(round_number, number, seed):
    """The file stem of match ``number`` (from 1) of a league's round ``round_number``
    (from 1), played with ``seed``."""
    return f"round-{int(round_number):03d}-match-{int(number):04d}-seed-{int(seed)}"


def tournament_names(schedule_):
    """The file stems of a tournament's matches, ``(p1, p2, seed)`` in schedule order."""
    return [tournament_match_name(n, seed) for n, (_, _, seed) in enumerate(schedule_, 1)]


def league_round_names(round_number, schedule_):
    """The file stems of a league round's matches, ``(p1, p2, seed)`` in schedule order."""
    return [league_match_name(round_number, n, seed)
            for n, (_, _, seed) in enumerate(schedule_, 1)]


def replay_path(directory, name):
    return os.path.join(directory, name + EXTENSION)


def prepare(directory):
    """``directory`` checked (an existing writable directory, or one that can be made) and
    made; returned as given."""
    directory = check_output_dir(directory)
    os.makedirs(directory, exist_ok=True)
    return directory


def check_paths(directory, names):
    """Every replay file about to be written can be: refused now (before the matches are
    played), not after them."""
    for name in names:
        check_output_path(replay_path(directory, name), "replay")


def save_all(directory, names, replays):
    """Save each replay as ``directory/name.json`` (``spacewar.replay.save``)."""
    from spacewar.replay import save

    for name, replay in zip(names, replays, strict=True):
        save(replay_path(directory, name), replay)
