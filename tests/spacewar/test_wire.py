"""The wire between a match and a bot's process: exact layouts, and every malformed answer
refused by name."""
import struct

import numpy as np
import pytest

from spacewar import Action, Game, Rules, wire
from spacewar.protocol import action_code, observation_from_raw, raw_layout, raw_length


def test_answer_round_trip_in_any_pieces():
    data = wire.pack_answer(7, wire.OK, 13) + wire.pack_answer(8, wire.RAISED, 0, "boom")
    reader = wire.AnswerReader()
    got = []
    for byte in data[:-1]:  # one byte at a time: never a partial answer
        reader.feed(bytes([byte]))
        answer = reader.next()
        if answer:
            got.append(answer)
    assert got == [(7, wire.OK, 13, "")]
    reader.feed(data[-1:])
    assert reader.next() == (8, wire.RAISED, 0, "boom")


@pytest.mark.parametrize("data, message", [
    (b"\x80\x03garbage", "magic"),
    (struct.pack("<4sqBBH", b"SWA1", 1, 99, 0, 0), "unknown answer status 99"),
    (struct.pack("<4sqBBH", b"SWA1", 1, wire.RAISED, 0, 60000), "exceeds 1024"),
])
def test_malformed_answers_are_wire_errors(data, message):
    reader = wire.AnswerReader()
    reader.feed(data)
    with pytest.raises(wire.WireError, match=message):
        reader.next()


def test_a_flood_is_refused_before_it_is_parsed():
    with pytest.raises(wire.WireError, match="without being asked"):
        wire.AnswerReader().feed(wire.pack_answer(1, wire.OK, 1) * 200)


def test_texts_are_capped_when_packed():
    reader = wire.AnswerReader()
    reader.feed(wire.pack_answer(3, wire.RAISED, 0, "é" * 5000))
    frame, status, code, text = reader.next()
    assert len(text.encode("utf-8", "replace")) <= wire.MAX_TEXT


def test_observe_and_start_messages_round_trip():
    raw = np.arange(10.0)
    message = wire.pack_observe(5, raw)
    view = memoryview(message)
    pos = [0]

    def read_exact(n):
        chunk = bytes(view[pos[0]:pos[0] + n])
        pos[0] += n
        return chunk

    frame, got = wire.read_observe(read_exact)
    assert frame == 5 and np.array_equal(got, raw)
    start = wire.pack_start({"spec": "x.py:Bot", "seed": 3})
    pos[0], view = 0, memoryview(start)
    assert wire.read_start(read_exact) == {"spec": "x.py:Bot", "seed": 3}


def test_raw_observation_decodes_to_the_same_observation_on_both_sides():
    rules = Rules(mode="electric")
    game = Game(rules, seeds=[4])
    rng = np.random.default_rng(1)
    for _ in range(120):
        game.step(rng.integers(0, 48, size=(1, 2)))
    for seat in (0, 1):
        raw = game.raw_observation(0, seat)
        assert raw.shape == (raw_length(rules),) == (len(raw_layout(rules)),)
        sent = np.frombuffer(wire.pack_observe(0, raw)[wire.OBSERVE_HEADER.size:], dtype="<f8")
        a, b = game.observe(0, seat), observation_from_raw(sent, Rules.from_dict(rules.to_dict()))
        for ship_a, ship_b in ((a.me, b.me), (a.enemy, b.enemy)):
            assert np.array_equal(ship_a.pos, ship_b.pos) and np.array_equal(ship_a.vel, ship_b.vel)
            assert (ship_a.heading, ship_a.fuel, ship_a.charge, ship_a.torpedoes) == \
                (ship_b.heading, ship_b.fuel, ship_b.charge, ship_b.torpedoes)
        assert np.array_equal(a.vector(), b.vector()) and len(a.torpedoes) == len(b.torpedoes)
        assert a.score == b.score and a.frame == b.frame and a.seat == seat
        with pytest.raises(ValueError):
            a.me.pos[0] = 0.0  # read-only


def test_action_code_trusts_the_fields_not_the_class():
    assert action_code(Action(turn=1, fire=True)) == 2 + 6
    forged = Action()
    object.__setattr__(forged, "turn", 100)
    with pytest.raises(ValueError, match="turn must be -1, 0 or 1, got 100"):
        action_code(forged)
    object.__setattr__(forged, "turn", 0)
    object.__setattr__(forged, "fire", "yes")
    with pytest.raises(ValueError, match="fire must be True or False"):
        action_code(forged)

    class Sly(Action):
        def code(self):
            return 10 ** 30

    assert action_code(Sly(thrust=True)) == 1 + 3
    for code in range(48):
        assert action_code(Action.from_code(code)) == code


def test_an_observation_is_decoded_when_first_read_with_the_raw_numbers():
    from spacewar import Game

    game = Game(Rules(), seeds=[3], rounds=2)
    for _ in range(300):
        game.step([[7, 10]])
    raw = game.raw_observation(0, 1)
    obs = observation_from_raw(raw, game.rules)
    assert "me" not in vars(obs)  # nothing decoded yet: the match paid only for the copy
    names = raw_layout(game.rules)
    value = dict(zip(names, raw.tolist()))
    assert obs.seat == 1 and obs.frame == value["frame"] == 300
    assert obs.me.pos.tolist() == [value["me.x"], value["me.y"]]
    assert obs.enemy.fuel == value["enemy.fuel"]
    live = [k for k in range(2 * game.rules.torpedoes) if value[f"torpedo{k}.present"]]
    assert len(obs.torpedoes) == len(live) > 0
    assert [t.ttl for t in obs.torpedoes] == [value[f"torpedo{k}.ttl"] for k in live]
    raw[:] = 0.0  # the observation decoded its own copy
    assert obs.torpedoes[0].pos.tolist() != [0.0, 0.0] and not obs.me.pos.flags.writeable
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        obs.nothing


def test_batch_and_codes_messages_round_trip():
    obs = np.arange(12, dtype=np.float32).reshape(3, 4) / 7
    view = memoryview(wire.pack_batch(9, obs) + wire.pack_stop())
    pos = [0]

    def read_exact(n):
        chunk = bytes(view[pos[0]:pos[0] + n])
        pos[0] += n
        return chunk

    call, got = wire.read_batch(read_exact)
    assert call == 9 and got.dtype == np.float32 and np.array_equal(got, obs)
    assert wire.read_batch(read_exact) is None  # STOP
    reader = wire.AnswerReader(rows=3)
    data = wire.pack_codes(9, wire.OK, [1, 47, 0]) + wire.pack_codes(10, wire.RAISED, b"", "x")
    for byte in data:
        reader.feed(bytes([byte]))
        answer = reader.next()
        if answer:
            assert answer == (9, wire.OK, bytes([1, 47, 0]), "")
            break
    reader.feed(data[len(wire.pack_codes(9, wire.OK, [1, 47, 0])):])
    assert reader.next() == (10, wire.RAISED, b"", "x")
    with pytest.raises(wire.WireError, match="caps"):
        wire.pack_batch(0, np.zeros((wire.MAX_ROWS + 1, 1), np.float32))


@pytest.mark.parametrize("data, message", [
    (wire.pack_answer(1, wire.OK, 3), "magic"),  # one match's answer where codes are due
    (struct.pack("<4sqBBHI", b"SWC1", 1, wire.OK, 0, 0, 4) + bytes(4), "4 codes for a batch of 3"),
    (struct.pack("<4sqBBHI", b"SWC1", 1, 77, 0, 0, 3) + bytes(3), "unknown answer status 77"),
    (struct.pack("<4sqBBHI", b"SWC1", 1, wire.RAISED, 0, 5000, 0), "exceeds 1024"),
    # a count of codes other than K with OK, none included, and codes with any other status
    (wire.pack_codes(1, wire.OK, b""), "0 codes for a batch of 3 with status 'ok'"),
    (wire.pack_codes(1, wire.OK, [0, 0]), "2 codes for a batch of 3"),
    (wire.pack_codes(1, wire.RAISED, [0, 0, 0], "boom"), "3 codes for a batch of 3 with status "
                                                         "'raised'"),
])
def test_malformed_codes_are_wire_errors(data, message):
    reader = wire.AnswerReader(rows=3)
    with pytest.raises(wire.WireError, match=message):
        reader.feed(data)
        reader.next()


def test_a_batch_answer_is_k_codes_with_ok_or_none_with_another_status():
    reader = wire.AnswerReader(rows=3)
    reader.feed(wire.pack_codes(4, wire.OK, [1, 2, 3]) + wire.pack_codes(5, wire.RAISED, b"", "x"))
    assert reader.next() == (4, wire.OK, bytes([1, 2, 3]), "")
    assert reader.next() == (5, wire.RAISED, b"", "x")


def test_a_flood_of_codes_is_refused_before_it_is_parsed():
    with pytest.raises(wire.WireError, match="without being asked"):
        wire.AnswerReader(rows=100).feed(wire.pack_codes(1, wire.OK, [0] * 100) * 20)
