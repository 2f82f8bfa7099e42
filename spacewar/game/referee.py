"""The referee: how one frame of a match is judged, written once for every place a match is
played (``spacewar.arena.match.play_match``, ``spacewar.arena.batch_match.play_matches``, the window's
``spacewar.view.live.LiveMatch``) and for the replay check that re-judges a recorded match
(``spacewar.replay.check``).

Each frame both seats are asked (seat index 0 first). A fault costs the seat its turn (the
seat answers a no-op) and is entered in its fault log (``spacewar.faults.FaultLog``) and in
the frame's fault record (code 1 + the kind's index in ``FAULT_KINDS``, 0 for none). A seat
whose bot can no longer play (it died, hung, broke the protocol, could not start), or whose
faults reach ``max_faults``, forfeits; once a seat has forfeited after a frame's questions,
that frame is not played and the match ends there. Otherwise the frame is stepped and its two
action codes recorded.
"""
import math

from spacewar.game import core
from spacewar.faults import FaultLog, fault_code


class Referee:
    """One match's judge: the two seats' fault logs, who forfeited, and, when ``record`` is
    true, the two records a replay is made of (``history``: two action codes per frame
    played; ``fault_codes``: two fault codes per frame asked, the frame a match forfeits on
    included)."""

    def __init__(self, max_faults=math.inf, record=False):
        self.max_faults = max_faults
        self.faults = [FaultLog(), FaultLog()]
        self.forfeits = [False, False]
        self.history = bytearray() if record else None
        self.fault_codes = bytearray() if record else None
        self._codes = [0, 0]

    @property
    def forfeited(self):
        return self.forfeits[0] or self.forfeits[1]

    def could_not_start(self, s, fault):
        """Seat s's bot failed to start (``fault``: its ``(kind, message)``): logged at frame 0,
        and the seat forfeits before any frame is asked."""
        self.faults[s].add(0, *fault)
        self.forfeits[s] = True

    def judge(self, s, frame, fault, dead=False):
        """Seat s's answer at ``frame``: ``fault`` None or ``(kind, message)``; ``dead``: its
        bot can play no more. Forfeits it when dead or at ``max_faults`` faults."""
        if fault is not None:
            self.faults[s].add(frame, *fault)
            self._codes[s] = fault_code(fault[0])
        if dead or self.faults[s].total >= self.max_faults:
            self.forfeits[s] = True

    def forfeit(self, s):
        """Seat s forfeits now (its bot can play no more)."""
        self.forfeits[s] = True

    def questions_done(self):
        """The frame's questions are over: its fault codes are recorded; True when a seat has
        forfeited (the frame is then not played)."""
        if self.fault_codes is not None:
            self.fault_codes += bytes(self._codes)
        self._codes = [0, 0]
        return self.forfeited

    def played(self, code0, code1):
        """The frame was stepped with these two action codes."""
        if self.history is not None:
            self.history += bytes((int(code0), int(code1)))

    def ask(self, seats, raws, actions, frame, m=0):
        """Ask both seats for ``frame`` (each ``seat.act(raw) -> (code, fault)``), their codes
        into ``actions[m]``; True when a seat has forfeited."""
        for s, seat in enumerate(seats):
            code, fault = seat.act(raws[s])
            actions[m, s] = code
            if fault is not None or seat.dead is not None:  # else nothing changes
                self.judge(s, frame, fault, seat.dead is not None)
        return self.questions_done()

    def play_frame(self, game, seats, raws, actions, m=0):
        """One frame of match ``m`` of ``game``: ask, judge, and unless a seat forfeited step
        it (``Game.step_one_codes``, which writes what each seat sees next into ``raws``).
        Returns True when the frame was played."""
        if self.ask(seats, raws, actions, int(game.match_state[m, core.FRAME]), m):
            return False
        game.step_one_codes(m, actions, raws)
        self.played(actions[m, 0], actions[m, 1])
        return True
