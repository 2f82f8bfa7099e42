"""Section 6: headless Spacewar, frames per second of one match with built-in bots (inline and
with each bot confined in its own process), of the game alone, and of many matches advanced
together."""
import math
import statistics
import time

import numpy as np

NAME = "spacewar"
KEYS = ("spacewar",)
NEEDS = ()


def run(quick):
    return {"spacewar": bench_spacewar(64 if quick else 256, 500 if quick else 2000,
                                       3 if quick else 5)}


def bench_spacewar(matches=256, frames=2000, repeats=5):
    from spacewar import Game, Rules
    from spacewar.arena.match import play_match

    play_match("chaser", "sniper", seed=1, rounds=1)  # compiled code loaded, bots' too
    # The same match inline and with both bots each in its own confined process (as untrusted
    # bots play), alternating, ``repeats`` times: frames per second once both seats are
    # ready, the start-up of the seats apart.
    inline_fps, confined_fps, ratios, startups = [], [], [], []
    for _ in range(repeats):
        result, _, timing = play_match("chaser", "sniper", seed=1, rounds=3)
        confined, _, confined_timing = play_match("chaser", "sniper", seed=1, rounds=3,
                                                  isolation="process")
        inline_fps.append(timing["play_frames_per_second"])
        confined_fps.append(confined_timing["play_frames_per_second"])
        ratios.append(confined_fps[-1] / inline_fps[-1])
        startups.append(confined_timing["startup_seconds"])
    # A confined bot can fault (a timeout on a loaded machine) and change the match: reported,
    # not asserted, so the rest of the bench still runs.
    agrees = confined["steps"] == result["steps"] and confined["score"] == result["score"]
    rng = np.random.default_rng(0)
    game = Game(Rules(), seeds=range(matches), rounds=1000)
    game.step(rng.integers(0, 48, size=(matches, 2)))
    codes = rng.integers(0, 48, size=(frames, matches, 2))
    start = time.perf_counter()
    for f in range(frames):
        game.step(codes[f])
    batch = time.perf_counter() - start
    single = Game(Rules(), seeds=[0], rounds=1000)
    start = time.perf_counter()
    for f in range(frames):
        single.step(codes[f, :1])
    alone = time.perf_counter() - start
    played = [f for f in confined_fps if f > 0]
    return {
        "one_match_with_bots": {"bots": result["bots"], "frames": result["steps"],
                                "frames_per_second": statistics.median(inline_fps)},
        "one_match_confined_bots": {
            "frames": confined["steps"],
            "repeats": repeats,
            "frames_per_second": statistics.median(confined_fps),
            # confined over inline, each pair measured one after the other
            "over_inline": statistics.median(ratios),
            "startup_seconds": statistics.median(startups),
            "wall_seconds": confined_timing["wall_seconds"],
            # None when the confined match played no frame (a bot that could not start)
            "slowdown": (statistics.median(inline_fps) / statistics.median(played)
                         if played else None),
            "agrees_with_inline": agrees,
            "faults": [seat["total"] for seat in confined["faults"]],
            "fault_kinds": [{k: n for k, n in seat.items() if isinstance(n, int) and n and
                             k != "total"} for seat in confined["faults"]],
            "forfeits": confined["forfeits"]},
        "one_match_no_bots_frames_per_second": frames / alone,
        "batch": {"matches": matches, "frames": frames,
                  "match_frames_per_second": matches * frames / batch},
        "confined_bot_ready_seconds": {spec: _confined_ready_seconds(spec, repeats)
                                       for spec in ("idle", "chaser", "sniper")},
    }


def _confined_ready_seconds(spec, repeats):
    """Median seconds from opening a confined seat for ``spec`` to its bot's being ready (its
    process started and confined, its module imported, the bot made and reset)."""
    from spacewar import Rules
    from spacewar.sandbox.limits import Limits
    from spacewar.sandbox.process import ProcessSeat

    seconds = []
    for _ in range(repeats):
        start = time.perf_counter()
        seat = ProcessSeat(spec, 1, Limits(), Rules())
        fault = seat.wait_ready()
        seconds.append(time.perf_counter() - start if fault is None else math.inf)
        seat.close()
    return statistics.median(seconds)


def _over_inline(conf):
    """The confined match's frame rate as a fraction of the inline one's."""
    ratio = conf.get("over_inline")
    return "ratio not measured" if ratio is None else f"{ratio:.2f} of the inline rate"


def _ready_text(spacewar):
    """``idle 0.21 s, chaser 0.24 s, ...``: each built-in bot's confined start-up."""
    ready = spacewar.get("confined_bot_ready_seconds", {})
    return ", ".join(f"{spec} {seconds:.2f} s" for spec, seconds in ready.items()) or "not measured"


def _confined_outcome(conf):
    """Whether the confined match replayed the inline one, and the confined bots' faults."""
    same = conf.get("agrees_with_inline")
    text = ("same frames and score as inline" if same else
            "DIFFERS from the inline match" if same is not None else "agreement not measured")
    faults = conf.get("faults")
    if faults is not None:
        kinds = conf.get("fault_kinds") or [{}, {}]
        text += "; confined bots' faults " + ", ".join(
            f"{n}" + (f" ({', '.join(f'{k} {c}' for k, c in kind.items())})" if kind else "")
            for n, kind in zip(faults, kinds))
    return text


def text(r):
    lines = []
    s = r["spacewar"]
    one = s["one_match_with_bots"]
    conf = s["one_match_confined_bots"]
    lines.append(f"\n6. Spacewar: one match {one['bots'][0]} vs {one['bots'][1]} with bots "
                 f"{one['frames_per_second']:.0f} frames/s; both bots confined in their "
                 f"own processes {conf['frames_per_second']:.0f} frames/s once ready, "
                 f"{_over_inline(conf)} "
                 f"({_confined_outcome(conf)}); start-up of both confined seats "
                 f"{conf.get('startup_seconds', math.nan):.2f} s; a confined bot ready in "
                 f"{_ready_text(s)}; without bots "
                 f"{s['one_match_no_bots_frames_per_second']:.0f} frames/s; "
                 f"{s['batch']['matches']} matches together "
                 f"{s['batch']['match_frames_per_second']:.3e} match-frames/s")
    return lines


def markdown(r):
    out = []
    s = r["spacewar"]
    one = s["one_match_with_bots"]
    conf = s["one_match_confined_bots"]
    slowdown = ("no frame played" if conf.get("slowdown") is None
                else f"{conf['slowdown']:.2f}x the time")
    out += ["## 6. Headless Spacewar", "",
            f"- one match, {one['bots'][0]} vs {one['bots'][1]}, bots included: "
            f"{one['frames_per_second']:.0f} frames per second",
            f"- the same match with each bot confined in its own process (as every bot that "
            f"is not built in plays), once both are ready: {conf['frames_per_second']:.0f} "
            f"frames per second, {_over_inline(conf)} ({slowdown}; the median of "
            f"{conf.get('repeats', 1)} pairs played one after the other); "
            f"{_confined_outcome(conf)}",
            f"- start-up of the two confined seats (process, confinement, the bot's "
            f"module): {conf.get('startup_seconds', math.nan):.2f} s; one confined bot "
            f"ready in {_ready_text(s)}",
            f"- one match, no bots (action codes only): {s['one_match_no_bots_frames_per_second']:.0f} "
            "frames per second",
            f"- {s['batch']['matches']} matches advanced together by one compiled call: "
            f"{s['batch']['match_frames_per_second']:.3e} match-frames per second", ""]
    return out


def targets(r):
    rows = []
    conf = r["spacewar"]["one_match_confined_bots"]
    if conf.get("over_inline") is not None:
        rows.append(("one match, both bots confined: at least 0.5 of the inline frame rate "
                     "once the seats are ready", f"{conf['over_inline']:.2f}",
                     conf["over_inline"] >= 0.5))
    ready = r["spacewar"].get("confined_bot_ready_seconds", {})
    for spec in ("idle", "chaser"):  # they import spacewar and numpy alone
        if spec in ready:
            rows.append((f"a confined {spec} (spacewar and numpy alone) ready within 0.3 s",
                         f"{ready[spec]:.2f} s", ready[spec] <= 0.3))
    return rows
