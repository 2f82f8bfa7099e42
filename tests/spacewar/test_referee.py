"""One referee (``spacewar.game.referee``) judges every frame of every match: a single match, the
rows of a batch, the window's live match and the replay check. Its rules on their own, and a
check that no other module keeps its own copy of them."""
import ast
import os

import numpy as np
import pytest

from spacewar.faults import FAULT_KINDS
from spacewar.game.referee import Referee

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


class Seat:
    """A seat that answers from a script: each call its next (code, fault); ``dead`` set
    from the frame given on."""

    def __init__(self, answers, dies_at=None):
        self.answers = list(answers)
        self.dies_at = dies_at
        self.calls = 0
        self.dead = None

    def act(self, raw):
        self.calls += 1
        if self.dies_at is not None and self.calls >= self.dies_at:
            self.dead = ("crashed", "gone")
        return self.answers.pop(0)


def test_a_fault_costs_the_turn_is_logged_coded_and_forfeits_at_the_limit():
    ref = Referee(max_faults=2, record=True)
    actions = np.zeros((1, 2), dtype=np.int64)
    seats = [Seat([(5, None), (0, ("timeout", "late")), (0, ("raised", "boom\x1b[2J"))]),
             Seat([(7, None), (9, None), (3, None)])]
    raws = [None, None]
    assert ref.ask(seats, raws, actions, frame=0) is False
    ref.played(*actions[0])
    assert ref.ask(seats, raws, actions, frame=1) is False
    ref.played(*actions[0])
    assert ref.ask(seats, raws, actions, frame=2) is True  # the second fault: the limit
    assert ref.forfeits == [True, False]
    assert bytes(ref.history) == bytes([5, 7, 0, 9])
    assert bytes(ref.fault_codes) == bytes([0, 0, 1 + FAULT_KINDS.index("timeout"), 0,
                                            1 + FAULT_KINDS.index("raised"), 0])
    log = ref.faults[0].to_dict()
    assert (log["total"], log["timeout"], log["raised"]) == (2, 1, 1)
    assert log["last"] == {"frame": 2, "kind": "raised", "message": "boom\\x1b[2J"}


def test_a_dead_seat_forfeits_at_once_and_both_seats_are_asked_that_frame():
    ref = Referee(max_faults=100)
    actions = np.zeros((1, 2), dtype=np.int64)
    seats = [Seat([(1, None)], dies_at=1), Seat([(2, None)])]
    assert ref.ask(seats, [None, None], actions, frame=0) is True
    assert seats[1].calls == 1 and ref.forfeits == [True, False]


def test_a_seat_that_cannot_start_forfeits_before_any_frame():
    ref = Referee(max_faults=3, record=True)
    ref.could_not_start(1, ("startup", "no such file"))
    assert ref.forfeited and ref.forfeits == [False, True]
    assert ref.faults[1].to_dict()["examples"] == [
        {"frame": 0, "kind": "startup", "message": "no such file"}]


@pytest.mark.parametrize("name", ["FaultLog", "fault_code", "step_one_codes"])
def test_no_module_keeps_its_own_copy_of_the_referee(name):
    # the referee's rules live in spacewar/game/referee.py: no other module builds a fault log,
    # codes a fault for a replay or steps one match a frame (a copy of the loop would)
    users = []
    for folder, _, files in os.walk(os.path.join(ROOT, "spacewar")):
        for file in files:
            if not file.endswith(".py"):
                continue
            path = os.path.join(folder, file)
            with open(path, encoding="utf-8") as f:
                tree = ast.parse(f.read())
            for node in ast.walk(tree):
                if isinstance(node, ast.Call):
                    func = node.func
                    called = (func.attr if isinstance(func, ast.Attribute)
                              else getattr(func, "id", None))
                    if called == name:
                        users.append(os.path.relpath(path, ROOT))
    assert set(users) == {"spacewar/game/referee.py"}, users
