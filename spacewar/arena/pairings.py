"""A league's pairings: each round's pairs from the standings so far (``"swiss"``) or at random
(``"sampled"``), its bye, and its matches' seeds, all from the league's seed (the rules in
``spacewar.arena.league``'s text)."""

import numpy as np

from spacewar.arena.ratings import openskill_ratings


PAIRINGS = ("swiss", "sampled")


SEED_TAG = 0x1EA6  # keeps a league's seeds apart from a tournament's of the same seed


# -- pairings ----------------------------------------------------------------------------------
def league_rng(seed, *words):
    return np.random.default_rng(np.random.SeedSequence([int(seed), SEED_TAG, *words]))


def pair_round(config, round_index, standings, met, byes):
    """``(pairs, bye)`` of round ``round_index`` (from 0): ``standings`` the bots best first,
    ``met[(a, b)]`` (a < b) how often two bots have met, ``byes[bot]`` its byes so far."""
    bots = config["bots"]
    if config["pairing"] == "sampled" or (config["pairing"] == "swiss" and round_index == 0):
        order = [bots[i] for i in league_rng(config["seed"], 0, round_index).permutation(len(bots))]
    else:
        order = list(standings)
    bye = None
    if len(order) % 2:
        fewest = min(byes.get(b, 0) for b in order)
        bye = next(b for b in reversed(order) if byes.get(b, 0) == fewest)
        order.remove(bye)
    if config["pairing"] == "sampled":
        return [(order[i], order[i + 1]) for i in range(0, len(order), 2)], bye
    pairs, left = [], list(order)
    while left:
        first = left.pop(0)
        times = [met.get(tuple(sorted((first, other))), 0) for other in left]
        second = left.pop(times.index(min(times)))
        pairs.append((first, second))
    return pairs, bye


def round_schedule(config, round_index, pairs):
    """The matches (p1, p2, seed) of a round: each pairing ``games`` seeds, both seat orders
    with the same seed."""
    out = []
    for pair, (a, b) in enumerate(pairs):
        for g in range(config["games"]):
            seed = int(np.random.SeedSequence(
                [config["seed"], SEED_TAG, 1, round_index, pair, g]).generate_state(1)[0])
            out += [(a, b, seed), (b, a, seed)]
    return out


def state_after(config, rounds):
    """``(standings, met, byes)`` after ``rounds``: the pairing's inputs for the next round."""
    met, byes = {}, {}
    for r in rounds:
        for a, b in r["pairs"]:
            key = tuple(sorted((a, b)))
            met[key] = met.get(key, 0) + 1
        if r["bye"] is not None:
            byes[r["bye"]] = byes.get(r["bye"], 0) + 1
    matches = [m for r in rounds for m in r["matches"]]
    skill = openskill_ratings(config["bots"], matches)
    order = sorted(config["bots"], key=lambda b: (-(skill[b][0] - 3 * skill[b][1]), b))
    return order, met, byes
