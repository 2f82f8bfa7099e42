"""Replays: seed, rules and every action of a match, as versioned JSON (never pickle).

A replay holds what is needed to re-simulate the match exactly without the bots: the rules,
the seed, the number of rounds and the action codes of both ships for every frame played
(``actions``: base64 of two bytes a frame), the per-frame fault record (``faults``: base64 of
one byte per seat for every frame the bots were asked, the fault kind code, 0 = none), the
``max_faults`` of the match, the recorded result and a SHA-256 of the final state.

Version 2 (written now) adds ``faults``, ``max_faults``, ``startup`` (the kind code of a
seat's start-up failure, 0 = none), ``fatal`` (per seat, the frame whose fault ended the bot
regardless of its count: it died, hung or broke the protocol; ``null`` = never) and
``content_sha256``: a SHA-256 of the file's canonical JSON (sorted keys, compact separators,
that field left out), written by ``save`` and verified by ``load``, so any edit of a saved
file is detected. Version 1 files are still read and checked, without the checks that need
the new fields (faults, forfeits).

``check`` re-simulates and re-derives the whole recorded result from the replay alone:
winner, winner_seat, score, rounds, steps, forfeit, forfeits, error, the fault counts of each
kind per seat and the frame and kind of each fault example, bots, seed, rounds_asked and
rules, plus the final state bit for bit; frames recorded after the match was over are
refused. The fault *messages* (and the bots' captured ``output``) cannot be re-derived without
the bots and are not compared.

The code: ``spacewar.replay.format`` (fields, ``make_replay``, canonical JSON), ``.signing``
(the per-user key), ``.files`` (``save``, ``load``), ``.schema`` (``validate``), ``.simulate``
and ``.check``; this package's names are theirs.
"""
from spacewar.faults import FAULT_KINDS
from spacewar.replay.check import check
from spacewar.replay.files import MAX_JSON_VALUES, load, save
from spacewar.replay.format import (DIGEST_FIELD, FORMAT, MAX_COUNT, MAX_FAULTS, MAX_FILE_BYTES, MAX_ROUNDS,
                     MAX_SEED, READABLE_VERSIONS, UNCHECKED_RESULT_FIELDS, VERSION, ReplayError,
                     canonical_json, digest, make_replay)
from spacewar.replay.schema import validate
from spacewar.replay.signing import SIGNATURE_FIELD, key_path, sign, signature_status
from spacewar.replay.simulate import actions, fault_record, new_game, simulate

__all__ = ["FORMAT", "VERSION", "FAULT_KINDS", "ReplayError", "make_replay", "save", "load",
           "validate", "check", "simulate", "actions", "fault_record", "digest",
           "canonical_json", "signature_status", "key_path", "SIGNATURE_FIELD", "sign",
           "DIGEST_FIELD", "READABLE_VERSIONS", "UNCHECKED_RESULT_FIELDS", "MAX_FILE_BYTES",
           "MAX_JSON_VALUES", "MAX_SEED", "MAX_ROUNDS", "MAX_FAULTS", "MAX_COUNT", "new_game"]
