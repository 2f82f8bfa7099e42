"""``spacewar.seats``, a documented path kept: ``open_seat``, ``bot_name`` and ``InlineSeat``
(now ``spacewar.arena.seats``), ``Limits`` and ``TimeBank`` (``spacewar.sandbox.limits``), the
confined seats ``ProcessSeat`` and ``BatchProcessSeat`` (``spacewar.sandbox.process``),
``sweep_stale_directories`` (``spacewar.sandbox.provision``), ``FAULT_KINDS`` and ``printable``
(``spacewar.faults``). This module only re-exports them (``docs/game.md``, "Layout"), and
nothing inside ``spacewar`` imports it."""
from spacewar.arena.seats import InlineSeat, bot_name, open_seat  # noqa: F401
from spacewar.faults import FAULT_KINDS, KIND_BY_STATUS, printable  # noqa: F401
from spacewar.sandbox.limits import DEFAULT_ROUNDS, MAX_SECONDS, Limits, TimeBank  # noqa: F401
from spacewar.sandbox.process import SHOWN_OUTPUT, BatchProcessSeat, ProcessSeat  # noqa: F401
from spacewar.sandbox.provision import sweep_stale_directories  # noqa: F401
