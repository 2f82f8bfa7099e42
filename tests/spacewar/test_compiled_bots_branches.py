"""Every branch of the compiled bots is reached by the compiled-versus-Python scenes.

The scenes of ``compiled_bot_scenes.SCENES`` are played by test_compiled_bots.py, every frame
compared. Here the branch coverage they give is held: the bots' source
(``spacewar/game/compiled_bots/``, one module per bot) run as plain Python (``NUMBA_DISABLE_JIT=1``, a subprocess)
under a line tracer, on states of those scenes, must take each ``if`` / ``while`` both ways and
enter and leave each ``for`` (``branch_table``), but for the ``UNREACHABLE`` list (each with its
reason). Each traced decision must also be the compiled code's, on the same state.

Why probes and not every frame: a plain-Python sniper or dodger decision costs about 5 ms, 12 ms
traced; the scenes' 60,000 decisions would take about ten minutes. ``PROBES`` lists, per branch,
the first (scene, match, frame, seat) of the scenes that takes it (found by the full run,
``python -m tests.spacewar.compiled_bot_scenes --probes``); the test replays those matches of
those scenes (compiled game and Python bots, cheap) to those frames and traces the decisions
there, so each listed branch is shown to be taken by a frame the comparison checks. If the bots
or the game change and a probe stops taking its branch, the test fails naming the branch: run
the full measurement again and update ``PROBES``.

Measured with the full run on this machine (12 matches of each scene): the original three
scenes reached 195 of the 280 branches; with the added scenes 258: the other 22 are out of
scope (the one-match entry, the random bot, reset), special floats no game state holds, or
proved unreachable, each with its reason in UNREACHABLE; none is left open.
"""
import pytest

from tests.spacewar.compiled_bot_scenes import (PROBES, UNREACHABLE, branch_id, branch_table,
                                                coverage_report, reached)


@pytest.fixture(scope="module")
def probed():
    return coverage_report(PROBES)


def missing_branches(branches, per_state):
    """The ids of the branches no state reaches, beyond the listed unreachable ones."""
    seen = set()
    for arcs in per_state:
        seen |= reached(branches, arcs)
    return {branch_id(b) for b in branches} - seen - set(UNREACHABLE), seen


def test_every_branch_of_the_compiled_bots_is_reached(probed):
    branches, per_state, meta, mismatches = probed
    assert not mismatches, mismatches  # the plain-Python decisions are the compiled ones
    missing, seen = missing_branches(branches, per_state)
    every = {branch_id(b) for b in branches}
    print(f"{len(seen)} of {len(every)} branches reached, {len(UNREACHABLE)} unreachable")
    assert not missing, f"branches of the compiled bots no scene reaches: {sorted(missing)}"
    # the list of unreachable branches is exact: each names a branch, none is reached
    assert set(UNREACHABLE) <= every, set(UNREACHABLE) - every
    assert not set(UNREACHABLE) & seen, set(UNREACHABLE) & seen
    # and none is left open: each has its reason
    assert not [b for b, why in UNREACHABLE.items() if why.startswith("OPEN")]


def test_coverage_check_fails_on_the_original_scenes_alone(probed):
    """Positive control: the same check on the probes of the three original scenes alone
    (chaser, sniper, dodger) reports the chaser's ram dodge and the dodger's hyperspace jump
    among the branches not reached (the added scenes take them: ram, torpedo, electric,
    torpedo-no-star, side-by-side)."""
    branches, per_state, meta, _ = probed
    kept = [arcs for arcs, item in zip(per_state, meta)
            if item["scene"] in ("chaser", "sniper", "dodger")]
    missing, _ = missing_branches(branches, kept)
    print(f"the original scenes alone leave {len(missing)} branches not reached:",
          sorted(missing))
    assert RAM_DODGE in missing and HYPERSPACE in missing


def test_branch_table_finds_the_chaser_branches():
    """The table itself: the chaser's ram dodge and the dodger's jump are listed branches."""
    ids = {branch_id(b) for b in branch_table()}
    assert RAM_DODGE in ids and HYPERSPACE in ids
    assert len(ids) == len(branch_table())


RAM_DODGE = "chaser+46:if:T"
HYPERSPACE = "dodge+48:if:T"
