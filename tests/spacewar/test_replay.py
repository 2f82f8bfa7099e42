"""Replays: every edit is detected, the whole result is re-derived, bad files are clear errors."""
import base64
import json
import os

import pytest

from spacewar import replay
from spacewar.arena.match import play_match

TEST_BOTS = "tests.spacewar.bots_for_tests"


@pytest.fixture(scope="module")
def clean():
    """A match without faults (built-in bots, in this process)."""
    result, rep, _ = play_match("chaser", "random", seed=9, rounds=1, record=True)
    return result, rep


@pytest.fixture(scope="module")
def faulty():
    """A match with faults but no forfeit, and one forfeited on the fault count."""
    some, rep_some, _ = play_match(f"{TEST_BOTS}:SometimesRaising", "idle", seed=3, rounds=1,
                                   record=True)
    lost, rep_lost, _ = play_match(f"{TEST_BOTS}:Raising", "chaser", seed=1, rounds=1,
                                   max_faults=3, record=True)
    assert some["faults"][0]["raised"] == 3 and some["forfeit"] is None
    assert lost["forfeit"] and lost["faults"][0]["raised"] == 3
    return rep_some, rep_lost


def fresh(rep):
    return json.loads(json.dumps(rep))


def saved(tmp_path, rep, name="game.json"):
    path = tmp_path / name
    replay.save(path, rep)
    return path


def forge(path, edit):
    """Edit a saved replay and recompute its digest (a forger who knows the format)."""
    data = json.loads(path.read_text())
    edit(data)
    data[replay.DIGEST_FIELD] = replay.digest(data)
    path.write_text(json.dumps(data))
    return path


def append_frames(data, n=30):
    codes = base64.b64decode(data["actions"]) + bytes(2 * n)
    data["actions"] = base64.b64encode(codes).decode()
    data["frames"] += n
    if "faults" in data:
        data["faults"] = base64.b64encode(base64.b64decode(data["faults"]) + bytes(2 * n)).decode()


def set_fault_count(data):
    log = data["result"]["faults"][0]
    log["raised"] += 1
    log["total"] += 1


def change_rule(data):
    data["result"]["rules"]["fuel"] = 2000.0


def change_rule_everywhere(data):
    data["rules"]["fuel"] = 2000.0
    data["result"]["rules"]["fuel"] = 2000.0


EDITS = {
    "winner": lambda d: d["result"].update(winner=d["result"]["bots"][1], winner_seat=1),
    "winner_seat": lambda d: d["result"].update(winner_seat=1 - (d["result"]["winner_seat"] or 0)),
    "score": lambda d: d["result"]["score"].__setitem__(0, d["result"]["score"][0] + 1),
    "rounds": lambda d: d["result"].update(rounds=d["result"]["rounds"] + 1),
    "steps": lambda d: d["result"].update(steps=d["result"]["steps"] - 1),
    "forfeit": lambda d: d["result"].update(forfeit=d["result"]["bots"][0]),
    "forfeits": lambda d: d["result"]["forfeits"].__setitem__(1, True),
    "error": lambda d: d["result"].update(error=True),
    "faults": set_fault_count,
    "bots": lambda d: d["result"]["bots"].__setitem__(0, "sniper"),
    "seed": lambda d: d["result"].update(seed=d["result"]["seed"] + 1),
    "rounds_asked": lambda d: d["result"].update(rounds_asked=7),
    "rules": change_rule,
}


def test_saved_file_has_a_digest_the_usual_mode_and_checks(tmp_path, clean):
    result, rep = clean
    old = os.umask(0o027)
    try:
        path = saved(tmp_path, rep)
    finally:
        os.umask(old)
    assert path.stat().st_mode & 0o777 == 0o640  # 0o666 & ~umask, not mkstemp's 0600
    assert os.listdir(tmp_path) == ["game.json"]
    data = replay.load(path)
    assert data["version"] == replay.VERSION == 2
    assert data[replay.DIGEST_FIELD] == replay.digest(data)
    assert data["result"] == json.loads(json.dumps(result))
    ok, details = replay.check(data)
    assert ok, details["mismatches"]
    assert details["unchecked"] == ["output"]


@pytest.mark.parametrize("field", sorted(EDITS) + ["actions past the end", "rules everywhere"])
def test_any_edit_of_a_saved_file_is_refused_by_its_digest(tmp_path, clean, field):
    path = saved(tmp_path, clean[1])
    data = json.loads(path.read_text())
    edit = {"actions past the end": append_frames,
            "rules everywhere": change_rule_everywhere}.get(field) or EDITS[field]
    edit(data)
    path.write_text(json.dumps(data))
    with pytest.raises(replay.ReplayError, match="does not match its content_sha256"):
        replay.load(path)


@pytest.mark.parametrize("field", sorted(EDITS))
def test_a_forged_result_is_rejected_by_check(tmp_path, faulty, field):
    rep = faulty[0] if field != "forfeits" else faulty[1]
    path = forge(saved(tmp_path, rep), EDITS[field])
    data = replay.load(path)  # the digest was recomputed: only re-deriving can tell
    ok, details = replay.check(data)
    assert not ok
    assert field in details["mismatches"], details["mismatches"]


def test_an_edited_fault_count_is_rejected(tmp_path, faulty):
    path = forge(saved(tmp_path, faulty[0]), set_fault_count)
    ok, details = replay.check(replay.load(path))
    mismatch = details["mismatches"]["faults"]
    assert not ok and mismatch["recorded"][0]["raised"] == 4
    assert mismatch["replayed"][0]["raised"] == 3


def test_an_edited_fault_kind_is_rejected(tmp_path, faulty):
    def edit(data):
        log = data["result"]["faults"][0]
        log["raised"] -= 1
        log["invalid"] += 1  # same total, different kind
    ok, details = replay.check(replay.load(forge(saved(tmp_path, faulty[0]), edit)))
    assert not ok and "faults" in details["mismatches"]


def test_an_edited_example_frame_is_rejected(faulty):
    rep = fresh(faulty[0])
    rep["result"]["faults"][0]["examples"][0]["frame"] += 1
    ok, details = replay.check(rep)
    assert not ok and "faults" in details["mismatches"]
    rep = fresh(faulty[0])
    rep["result"]["faults"][0]["examples"][0]["message"] = "any text"  # not re-derivable
    assert replay.check(rep)[0]


def test_an_edited_rules_field_is_rejected(tmp_path, clean):
    ok, details = replay.check(replay.load(forge(saved(tmp_path, clean[1]), change_rule)))
    assert not ok and "rules" in details["mismatches"]
    # changing the simulated rules and the result's alike changes the match itself
    ok, details = replay.check(replay.load(forge(saved(tmp_path, clean[1]),
                                                 change_rule_everywhere)))
    assert not ok and "final_state_sha256" in details["mismatches"]


@pytest.mark.parametrize("which", [0, 1])
def test_actions_appended_past_the_end_are_rejected(tmp_path, clean, faulty, which):
    rep = (clean[1], faulty[1])[which]  # ended by the game, ended by a forfeit
    path = forge(saved(tmp_path, rep), append_frames)
    ok, details = replay.check(replay.load(path))
    assert not ok
    assert any("past the end" in p for p in details["mismatches"]["record"]["problems"])
    if which == 0:  # (a forfeit is not in the game: only check can see frames after it)
        with pytest.raises(replay.ReplayError, match="past the end"):
            replay.simulate(replay.load(path))


def test_a_truncated_record_is_rejected(clean):
    rep = fresh(clean[1])
    codes = base64.b64decode(rep["actions"])[:-20]
    rep["actions"] = base64.b64encode(codes).decode()
    rep["faults"] = base64.b64encode(base64.b64decode(rep["faults"])[:-20]).decode()
    rep["frames"] -= 10
    ok, details = replay.check(rep)
    assert not ok and any("before the match is over" in p
                          for p in details["mismatches"]["record"]["problems"])


def test_max_faults_edited_so_the_forfeit_no_longer_follows(faulty):
    rep = fresh(faulty[1])
    rep["max_faults"] = 50
    ok, details = replay.check(rep)
    assert not ok and "forfeit" in details["mismatches"]


def test_forfeits_by_count_and_plain_faults_check(faulty):
    for rep in faulty:
        ok, details = replay.check(rep)
        assert ok, details["mismatches"]


def test_crash_and_startup_forfeits_are_re_derived(tmp_path):
    bad = tmp_path / "badbot.py"
    bad.write_text("class Bad:\n    def __init__(self):\n        raise RuntimeError('no')\n"
                   "    def act(self, obs):\n        return None\n")
    result, rep, _ = play_match(f"{bad}:Bad", "idle", seed=1, rounds=1, record=True)
    assert result["forfeits"] == [True, False] and rep["frames"] == 0
    assert rep["startup"][0] == 1 + replay.FAULT_KINDS.index(
        result["faults"][0]["examples"][0]["kind"])
    assert replay.check(rep)[0]
    forged = fresh(rep)
    forged["startup"] = [0, 0]
    ok, details = replay.check(forged)
    assert not ok and "forfeit" in details["mismatches"]

    result, rep, _ = play_match(f"{TEST_BOTS}:Dies", "idle", seed=1, rounds=1, budget=0.5,
                                max_faults=5, record=True)
    assert result["forfeits"] == [True, False] and result["faults"][0]["total"] < 5
    assert rep["fatal"][0] == rep["frames"]  # the frame asked but not played
    assert replay.check(rep)[0]
    forged = fresh(rep)
    forged["fatal"] = [None, None]
    assert not replay.check(forged)[0]


def test_make_replay_positional_arguments_still_work(clean):
    result, rep = clean
    history = base64.b64decode(rep["actions"])
    again = replay.make_replay(result, history, rep["final_state_sha256"])
    assert again["faults"] == base64.b64encode(bytes(len(history))).decode()
    assert again["max_faults"] is None
    assert replay.check(again)[0]


def test_fault_codes_follow_the_seats_kinds():
    from spacewar.faults import FAULT_KINDS

    assert replay.FAULT_KINDS == FAULT_KINDS == (
        "raised", "invalid", "timeout", "crashed", "startup", "memory")


def _version_1(rep):
    v1 = fresh(rep)
    v1["version"] = 1
    for key in ("faults", "max_faults", "startup", "fatal", "bots"):
        v1.pop(key)
    v1["result"].pop("forfeits")
    v1["result"].pop("output", None)
    for log in v1["result"]["faults"]:
        for kind in ("startup", "memory"):
            log.pop(kind)
    return v1


def test_version_1_files_still_load_and_check(tmp_path, clean):
    path = tmp_path / "old.json"
    path.write_text(json.dumps(_version_1(clean[1])))
    data = replay.load(path)
    ok, details = replay.check(data)
    assert ok, details["mismatches"]
    assert "faults" in details["unchecked"]
    edited = fresh(data)
    edited["result"]["winner_seat"] = 1 - (edited["result"]["winner_seat"] or 0)
    assert not replay.check(edited)[0]
    append_frames(edited)
    assert "record" in replay.check(edited)[1]["mismatches"]


def test_save_refuses_to_overwrite_a_gif(tmp_path, clean):
    gif = tmp_path / "game.gif"
    gif.write_bytes(b"GIF89a keep")
    with pytest.raises(ValueError, match="GIF"):
        replay.save(gif, clean[1])
    assert gif.read_bytes() == b"GIF89a keep"


def test_render_refuses_to_overwrite_the_replay(tmp_path, clean, optional):
    optional("PIL")
    from spacewar.render import render_gif

    path = saved(tmp_path, clean[1])
    before = path.read_bytes()
    with pytest.raises(ValueError, match="spacewar replay"):
        render_gif(str(path), str(path))
    assert path.read_bytes() == before
    assert os.listdir(tmp_path) == ["game.json"]


# -- malformed files -------------------------------------------------------------------------
def _v1_text(clean, edit):
    data = _version_1(clean[1])
    edit(data)
    return json.dumps(data)


def _v2_text(clean, edit):
    data = json.loads(json.dumps(replay.validate(fresh(clean[1]))))
    data[replay.DIGEST_FIELD] = "0" * 64
    edit(data)
    data[replay.DIGEST_FIELD] = replay.digest(data)
    return json.dumps(data)


MALFORMED = {
    "result not a dict": (lambda d: d.update(result=[1, 2]), "result must be a dict"),
    "result missing key": (lambda d: d["result"].pop("winner_seat"), "result lacks the field 'winner_seat'"),
    "result score strings": (lambda d: d["result"].update(score=["1", "0"]), r"score\[0\] must be an int"),
    "result score bool": (lambda d: d["result"].update(score=[True, 0]), r"score\[0\] must be an int"),
    "result winner_seat 5": (lambda d: d["result"].update(winner_seat=5), "winner_seat must be in"),
    "result faults not list": (lambda d: d["result"].update(faults={"total": 0}), "faults must be a list"),
    "result fault total str": (lambda d: d["result"]["faults"][0].update(total="0"), "total must be an int"),
    "result example kind": (lambda d: d["result"]["faults"][0]["examples"].append(
        {"frame": 0, "kind": "boom", "message": ""}), "kind must be one of"),
    "result error": (lambda d: d["result"].update(error="no"), "error must be true or false"),
    "result rules": (lambda d: d["result"].update(rules="classic"), "rules must be a dict"),
    "seed str": (lambda d: d.update(seed="7"), "seed must be an int"),
    "seed float": (lambda d: d.update(seed=7.0), "seed must be an int"),
    "seed negative": (lambda d: d.update(seed=-1), r"seed must be in \[0"),
    "seed 400 digits": (lambda d: d.update(seed=10 ** 400), "seed must be in.*401 digits"),
    "rounds bool": (lambda d: d.update(rounds=True), "rounds must be an int"),
    "rounds huge": (lambda d: d.update(rounds=10 ** 30), r"rounds must be in \[1"),
    "rounds zero": (lambda d: d.update(rounds=0), r"rounds must be in \[1"),
    "frames huge": (lambda d: d.update(frames=10 ** 40), r"frames must be in \[0"),
    "frames str": (lambda d: d.update(frames="12"), "frames must be an int"),
    "rules list": (lambda d: d.update(rules=[1, 2]), "rules must be a dict"),
    "rules unknown": (lambda d: d["rules"].update(warp=1), "rules are invalid: unknown rules field"),
    "rules bad value": (lambda d: d["rules"].update(torpedoes=10 ** 400), "rules are invalid"),
    "rules wrong type": (lambda d: d["rules"].update(fuel=[1]), "rules are invalid"),
    "actions not str": (lambda d: d.update(actions=12), "actions must be a base64 string"),
    "actions not base64": (lambda d: d.update(actions="@@@"), "not valid base64"),
    "hash": (lambda d: d.update(final_state_sha256="xyz"), "64 lowercase hex"),
}
MALFORMED_V2 = {
    "faults not str": (lambda d: d.update(faults=None), "faults must be a base64 string"),
    "fault code": (lambda d: d.update(faults=base64.b64encode(b"\x09" * (2 * d["frames"])).decode()),
                   "fault code 9 out of range"),
    "fault rows": (lambda d: d.update(faults=""), "frames of fault record"),
    "max_faults": (lambda d: d.update(max_faults=0), "max_faults must be in"),
    "startup": (lambda d: d.update(startup=[9, 0]), r"startup\[0\] must be in"),
    "fatal": (lambda d: d.update(fatal="none"), "fatal must be a list"),
    "bots": (lambda d: d.update(bots=["a"]), "bots must be a list of two"),
    "forfeits": (lambda d: d["result"].update(forfeits=[0, 0]), r"forfeits\[0\] must be true"),
    "missing kind": (lambda d: d["result"]["faults"][1].pop("memory"), "lacks the field 'memory'"),
}


@pytest.mark.parametrize("case", sorted(MALFORMED))
@pytest.mark.parametrize("version", [1, 2])
def test_malformed_fields_are_clear_replay_errors(tmp_path, clean, case, version):
    edit, message = MALFORMED[case]
    path = tmp_path / "bad.json"
    path.write_text((_v1_text if version == 1 else _v2_text)(clean, edit))
    with pytest.raises(replay.ReplayError, match=message):
        replay.load(path)


@pytest.mark.parametrize("case", sorted(MALFORMED_V2))
def test_malformed_version_2_fields_are_clear_replay_errors(tmp_path, clean, case):
    edit, message = MALFORMED_V2[case]
    path = tmp_path / "bad.json"
    path.write_text(_v2_text(clean, edit))
    with pytest.raises(replay.ReplayError, match=message):
        replay.load(path)


@pytest.mark.parametrize("content, message", [
    ("[" * 50_000 + "]" * 50_000, "nested too deeply"),  # fewer than MAX_JSON_VALUES
    ('{"format": "spacewar-replay", "version": 1, "seed": ' + "9" * 5000 + "}", "not a JSON"),
    ('{"format": "spacewar-replay", "version": NaN}', "not a JSON"),
    ('{"format": "spacewar-replay", "version": true}', "version True"),
    ('{"format": "spacewar-replay", "version": 2, "seed": 1}', "lacks the field"),
    (b"\xff\xfe garbage", "not a JSON"),
    ("", "not a JSON"),
    ("[]", "not a spacewar replay"),
])
def test_unreadable_files_are_clear_replay_errors(tmp_path, content, message):
    path = tmp_path / "bad.json"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    with pytest.raises(replay.ReplayError, match=message):
        replay.load(path)


def test_non_finite_rules_number_is_a_clear_replay_error(tmp_path, clean):
    for version, message in ((1, "rules are invalid"), (2, "not plain JSON")):
        text = (_v1_text if version == 1 else _v2_text)(
            clean, lambda d: d["rules"].update(fuel="INF"))
        path = tmp_path / "inf.json"
        path.write_text(text.replace('"fuel":"INF"', '"fuel":1e400')
                        .replace('"fuel": "INF"', '"fuel": 1e400'))
        assert "1e400" in path.read_text()
        with pytest.raises(replay.ReplayError, match=message):
            replay.load(path)


def test_missing_file_and_directory_are_replay_errors(tmp_path):
    with pytest.raises(replay.ReplayError, match="cannot read"):
        replay.load(tmp_path / "none.json")
    with pytest.raises(replay.ReplayError, match="cannot read"):
        replay.load(tmp_path)


def test_a_v2_file_without_its_digest_is_refused(tmp_path, clean):
    path = saved(tmp_path, clean[1])
    data = json.loads(path.read_text())
    del data[replay.DIGEST_FIELD]
    path.write_text(json.dumps(data))
    with pytest.raises(replay.ReplayError, match="lacks the field 'content_sha256'"):
        replay.load(path)


def _as_version_1(rep):
    old = {k: v for k, v in rep.items() if k in ("format", "seed", "rounds", "rules", "frames",
                                                 "actions", "result", "final_state_sha256")}
    old["version"] = 1
    old["result"] = {k: v for k, v in rep["result"].items() if k not in ("forfeits", "output")}
    old["result"]["faults"] = [{"total": f["total"], "examples": f["examples"]}
                               for f in rep["result"]["faults"]]
    return old


def test_a_result_forged_under_version_1_is_rejected():
    """A version 1 file carries no fault record and no digest: relabelling an edited replay as
    version 1 must not make its forged forfeit pass."""
    from spacewar.arena.match import play_match

    result, rep, _ = play_match("chaser", "random", seed=9, rounds=1, record=True)
    honest = _as_version_1(rep)
    assert replay.check(honest)[0]
    forged = _as_version_1(rep)
    loser = 1 - result["winner_seat"]
    forged["result"].update(winner=result["bots"][loser], winner_seat=loser,
                            forfeit=result["bots"][1 - loser])
    forged["result"]["faults"][1 - loser]["total"] = 999
    ok, details = replay.check(forged)
    assert not ok and {"winner", "winner_seat", "forfeit"} <= set(details["mismatches"])
    cut = _as_version_1(rep)  # a record stopped early, as a forfeit would have it
    codes = replay.actions(rep)[:10]
    import base64
    cut["actions"], cut["frames"] = base64.b64encode(codes.astype("uint8").tobytes()).decode(), 10
    assert not replay.check(cut)[0]


def test_a_faulted_frame_must_have_played_the_no_op():
    import base64

    from spacewar.arena.match import play_match

    _, rep, _ = play_match("tests.spacewar.bots_for_tests:Raising", "chaser", seed=1, rounds=1,
                           max_faults=3, record=True)
    assert replay.check(rep)[0]
    codes = replay.actions(rep)
    codes[0, 0] = 7  # the faulting seat "fired" on a frame it faulted
    rep["actions"] = base64.b64encode(codes.astype("uint8").tobytes()).decode()
    ok, details = replay.check(rep)
    assert not ok and "not the no-op" in " ".join(details["mismatches"]["record"]["problems"])


def test_signed_replays_detect_a_forger_who_recomputes_the_digest(tmp_path, replay_key):
    """The content digest is public: anyone can recompute it. The signature is an HMAC with the
    user's key: swapping the bots' names, or forging a fault record, is caught."""
    import json as _json

    from spacewar.arena.match import play_match

    result, rep, _ = play_match("idle", "sniper", seed=3, rounds=1, record=True)
    path = tmp_path / "r.json"
    replay.save(path, rep)
    assert replay_key.exists() and (replay_key.stat().st_mode & 0o777) == 0o600
    ok, details = replay.check(replay.load(path))
    assert ok and details["signature"] == "verified"
    data = _json.loads(path.read_text())
    data["bots"] = data["result"]["bots"] = ["sniper", "idle"]  # idle "beats" sniper
    data["result"]["winner"] = "idle"
    data[replay.DIGEST_FIELD] = replay.digest(data)
    path.write_text(_json.dumps(data))
    ok, details = replay.check(replay.load(path))  # the digest is fine; the signature is not
    assert not ok and details["signature"] == "forged" and "signature" in details["mismatches"]
    del data[replay.SIGNATURE_FIELD]
    data[replay.DIGEST_FIELD] = replay.digest(data)
    assert replay.check(data)[1]["signature"] == "unsigned"


def test_a_replay_signed_elsewhere_is_reported_as_unverifiable(tmp_path, monkeypatch, capsys):
    from spacewar.cli import main
    from spacewar.arena.match import play_match

    _, rep, _ = play_match("chaser", "random", seed=2, rounds=1, record=True)
    path = tmp_path / "r.json"
    replay.save(path, rep)
    monkeypatch.setenv("SPACEWAR_REPLAY_KEY_FILE", str(tmp_path / "another-key"))
    assert main(["replay", str(path), "--check"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("OK") and "WARNING: other key" in out
