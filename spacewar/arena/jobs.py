"""The work of a tournament or a league cut into jobs, and what a worker does with one: the
same in this process, in a local worker process and on a Dask worker (``spacewar.arena.runner``
sends them; ``spacewar.arena.cluster`` ships them to the cluster).

A job is plain data, ``(matches, together, rounds, rules_dict, limits, max_faults,
isolation, batch_files)``: one match, or every match of a pairing with a batch bot, played
together in one game (``spacewar.arena.batch_match``). Whether the matches' replays come back
too is asked of the run (``play_job(job, record=True)``), not written into the job: a job is
what to play, the same whichever way it is played.
"""
from spacewar.arena.match import play_match
from spacewar.rules import Rules


def play_job(job, record=False):
    """A job's outcomes ``[(result, timing), ...]``: one match, or every match of a pairing
    with a batch bot, played together (``spacewar.arena.batch_match``). With ``record``,
    ``[(result, timing, replay), ...]``: each match's replay dict (``spacewar.replay``) comes
    back too, the results the same as without (recording only keeps what was played)."""
    matches, together, rounds, rules_dict, limits, max_faults, isolation, batch_files = job
    rules = Rules.from_dict(rules_dict)
    if together:
        from spacewar.arena.batch_match import play_matches

        outcomes = play_matches(matches, rounds=rounds, rules=rules, limits=limits,
                                max_faults=max_faults, batch_files=batch_files, record=record)
        return [(result, timing, replay) for result, replay, timing in outcomes] if record \
            else outcomes
    (p1, p2, match_seed), = matches
    result, replay, timing = play_match(p1, p2, seed=match_seed, rounds=rounds, rules=rules,
                                        limits=limits, max_faults=max_faults,
                                        isolation=isolation, record=record)
    return [(result, timing, replay)] if record else [(result, timing)]


def batch_files_of(bots):
    """The bots from files among ``bots`` that play as batch bots (their class defines
    ``act_batch``: ``spacewar.bots.declares_act_batch``), read once for the whole run."""
    from spacewar.bots import declares_act_batch

    return frozenset(spec for spec in bots if declares_act_batch(spec))


def group_jobs(schedule_, isolation, batch_files=frozenset()):
    """The schedule cut into jobs ``(matches, together)``: each match alone, except that a
    pairing with a batch bot (a policy file, or a bot from a file in ``batch_files``) and a
    bot that can share its game (``batch_match.can_play_together``) is one job, all its
    matches in one game, the batch bot answering for all of them at once (at most
    ``wire.MAX_ROWS`` matches a job). Under ``isolation="process"`` every match plays alone."""
    from spacewar.arena.batch_match import can_play_together, is_batch_spec
    from spacewar.wire import MAX_ROWS

    jobs = []
    for p1, p2, seed in schedule_:
        together = (isolation != "process"
                    and (is_batch_spec(p1, batch_files) or is_batch_spec(p2, batch_files))
                    and can_play_together(p1, batch_files)
                    and can_play_together(p2, batch_files))
        if together and jobs and jobs[-1][0] and {p1, p2} == jobs[-1][2] \
                and len(jobs[-1][1]) < MAX_ROWS // 2:
            jobs[-1][1].append((p1, p2, seed))
        else:
            jobs.append((together, [(p1, p2, seed)], {p1, p2}))
    return [(matches, together) for together, matches, _ in jobs]


def make_jobs(schedule_, rounds, rules, limits, max_faults, isolation, batch_files):
    """The work of a schedule: ``group_jobs``' matches with everything a worker needs to
    play them."""
    return [(matches, together, rounds, rules.to_dict(), limits, max_faults, isolation,
             batch_files)
            for matches, together in group_jobs(schedule_, isolation, batch_files)]


def match_record(result):
    """A match's line in a tournament's or a league's results: a match result cut to plain
    data (fault totals, no wall-clock figure)."""
    return {"p1": result["bots"][0], "p2": result["bots"][1], "seed": result["seed"],
            "winner": result["winner"], "score": result["score"], "steps": result["steps"],
            "forfeit": result["forfeit"], "forfeits": result["forfeits"],
            "faults": [result["faults"][0]["total"], result["faults"][1]["total"]]}


def worker_start():
    """A worker dies with the tournament's process (and its bots with it), instead of waiting
    forever on a queue nobody feeds."""
    from spacewar.sandbox.confinement import die_with_parent

    die_with_parent()


def warm_up_game():
    """A cluster worker's warm-up (``engine.cluster.WarmWorker``): the game's kernels."""
    warm_up(Rules())


def warm_up(rules):
    """Compile (or load) the game's code here, once, before the workers start: workers then
    only read numba's cache instead of all compiling and writing it at the same time."""
    from spacewar.game.game import Game

    Game(rules, seeds=[0], rounds=1).step()
