"""Ratings from match results, for tournaments and leagues.

- Bradley-Terry strengths on the Elo scale, fitted to all results at once (a draw counts half
  a win each way), which unlike sequential Elo updates does not depend on game order:
  P(i beats j) = 1 / (1 + 10^((R_j - R_i) / 400)). Each bot also plays one virtual draw
  against a 1500-rated anchor, so a perfect record gives a finite rating (Hunter 2004, "MM
  algorithms for generalized Bradley-Terry models", Ann. Statist. 32:384; the virtual draw is
  a standard prior). ``bradley_terry_fit`` on a k x k matrix (a tournament: every pair met),
  ``bradley_terry_sparse`` on the pairs that met (a league), the same iteration; with a 95%
  interval from a bootstrap over matches (Efron 1979, "Bootstrap methods: another look at the
  jackknife", Ann. Statist. 7:1: the fit repeated on resamples of the matches drawn with
  replacement; the 2.5th and 97.5th percentiles).
- openskill's Plackett-Luce model (Weng & Lin 2011, "A Bayesian Approximation Method for
  Online Ranking", JMLR 12:267), ``mu`` and ``sigma`` per bot, updated match after match in
  the order the matches were scheduled (so the same results give the same ratings).
"""
import numpy as np

def bradley_terry_elo(names, results, iterations=2000):
    """Elo-scale ratings from (p1, p2, outcome) with outcome 1, 0.5 or 0 for p1."""
    k = len(names)
    index = {n: i for i, n in enumerate(names)}
    wins = np.zeros((k, k))
    for p1, p2, outcome in results:
        i, j = index[p1], index[p2]
        wins[i, j] += outcome
        wins[j, i] += 1.0 - outcome
    elo = bradley_terry_fit(wins, iterations)
    return {n: float(elo[index[n]]) for n in names}


def bradley_terry_fit(wins, iterations=2000):
    """Elo-scale Bradley-Terry ratings (an array) from ``wins[i, j]``, the games i won against
    j (a draw half each way): Hunter's (2004) MM iteration, each bot also drawing once with
    an anchor of strength 1 (1500)."""
    games = wins + wins.T
    strength = np.ones(wins.shape[0])
    won = wins.sum(axis=1) + 0.5
    for _ in range(iterations):
        denom = (games / (strength[:, None] + strength[None, :])).sum(axis=1) + 1.0 / (strength + 1.0)
        new = won / denom
        if np.allclose(new, strength, rtol=1e-12, atol=0):
            strength = new
            break
        strength = new
    return 1500.0 + 400.0 * np.log10(strength)


# -- ratings -----------------------------------------------------------------------------------
def match_outcome(match):
    """1, 0.5 or 0: the result for the match's p1."""
    if match["winner"] is None:
        return 0.5
    return 1.0 if match["winner"] == match["p1"] else 0.0


def bradley_terry_sparse(k, a, b, a_won, b_won, iterations=2000):
    """Elo-scale Bradley-Terry ratings of ``k`` bots from the pairs that met: ``a[e] < b[e]``
    with ``a_won[e]``, ``b_won[e]`` their wins over each other (a draw half each way). The
    tournament's MM iteration with its 1500 anchor (``bradley_terry_fit``), summed
    over the pairs that played instead of a k x k matrix: a league's few opponents a bot."""
    games = a_won + b_won
    won = np.bincount(a, a_won, k) + np.bincount(b, b_won, k) + 0.5
    strength = np.ones(k)
    for _ in range(iterations):
        share = games / (strength[a] + strength[b])
        new = won / (np.bincount(a, share, k) + np.bincount(b, share, k) + 1.0 / (strength + 1.0))
        if np.allclose(new, strength, rtol=1e-12, atol=0):
            strength = new
            break
        strength = new
    return 1500.0 + 400.0 * np.log10(strength)


#: the most numbers (resamples x matches or pairs) an array of ``bradley_terry_rows`` holds
ROWS_BLOCK = 1 << 21


def bradley_terry_rows(k, a, b, a_won, b_won, iterations=2000):
    """``bradley_terry_sparse`` for many weightings of the same pairs at once: ``a_won`` and
    ``b_won`` of shape (rows, pairs); returns the (rows, k) Elo ratings. Each row is exactly
    (bit for bit) what ``bradley_terry_sparse`` gives for it: the same operations in the same
    order (``np.bincount`` over the flattened rows sums each row's pairs in pair order, as it
    does for one row), and a row stops when it converges, as the single fit does; the rows
    still going are iterated together, which for a bootstrap's 200 small fits is about a
    hundred times faster than one fit after another."""
    rows = a_won.shape[0]
    games = a_won + b_won

    def by_bot(index, weights, m):  # per row, the sum of each bot's entries, in pair order
        flat = (np.arange(m)[:, None] * k + index[None, :]).ravel()
        return np.bincount(flat, weights.ravel(), m * k).reshape(m, k)

    won = by_bot(a, a_won, rows) + by_bot(b, b_won, rows) + 0.5
    strength = np.ones((rows, k))
    going = np.arange(rows)
    for _ in range(iterations):
        if not going.size:
            break
        now = strength[going]
        share = games[going] / (now[:, a] + now[:, b])
        new = won[going] / (by_bot(a, share, going.size) + by_bot(b, share, going.size)
                            + 1.0 / (now + 1.0))
        converged = np.isclose(new, now, rtol=1e-12, atol=0).all(axis=1)
        strength[going] = new
        going = going[~converged]
    return 1500.0 + 400.0 * np.log10(strength)


def bradley_terry_intervals(bots, matches, samples, rng, level=0.95):
    """``{bot: (elo, low, high)}``: the Bradley-Terry fit of all matches, and the
    ``level`` percentile interval of the fits of ``samples`` bootstrap resamples drawn with
    ``rng`` (a numpy ``Generator``; one resample after another, each of n matches drawn
    with replacement). The resamples are fitted a block at a time (``bradley_terry_rows``:
    each fit the one ``bradley_terry_sparse`` gives alone)."""
    index = {b: i for i, b in enumerate(bots)}
    k, n = len(bots), len(matches)
    i = np.array([index[m["p1"]] for m in matches], dtype=np.int64)
    j = np.array([index[m["p2"]] for m in matches], dtype=np.int64)
    p1_won = np.array([match_outcome(m) for m in matches])
    low_first = i < j
    pair_key = np.where(low_first, i * k + j, j * k + i)
    keys, pair = np.unique(pair_key, return_inverse=True)
    a, b = keys // k, keys % k
    a_share = np.where(low_first, p1_won, 1.0 - p1_won)  # each match's result for the pair's a

    def fit(weight):
        a_won = np.bincount(pair, weight * a_share, len(keys))
        b_won = np.bincount(pair, weight * (1.0 - a_share), len(keys))
        return bradley_terry_sparse(k, a, b, a_won, b_won)

    elo = fit(np.ones(n))
    if samples and n:
        block = max(1, ROWS_BLOCK // max(n, len(keys)))
        draws = []
        for start in range(0, samples, block):
            weight = np.array([np.bincount(rng.integers(0, n, n), minlength=n).astype(float)
                               for _ in range(min(block, samples - start))])
            flat = (np.arange(weight.shape[0])[:, None] * len(keys) + pair[None, :]).ravel()
            a_won = np.bincount(flat, (weight * a_share).ravel(), weight.shape[0] * len(keys))
            b_won = np.bincount(flat, (weight * (1.0 - a_share)).ravel(),
                                weight.shape[0] * len(keys))
            draws.append(bradley_terry_rows(k, a, b, a_won.reshape(-1, len(keys)),
                                            b_won.reshape(-1, len(keys))))
        draws = np.concatenate(draws)
        tail = 100.0 * (1.0 - level) / 2.0
        low, high = np.percentile(draws, [tail, 100.0 - tail], axis=0)
    else:
        low = high = elo
    return {bot: (float(elo[index[bot]]), float(low[index[bot]]), float(high[index[bot]]))
            for bot in bots}


def openskill_ratings(bots, matches):
    """``{bot: (mu, sigma)}`` after openskill's Plackett-Luce updates, match by match."""
    from openskill.models import PlackettLuce

    model = PlackettLuce()
    ratings = {b: model.rating(name=b) for b in bots}
    for m in matches:
        outcome = match_outcome(m)
        ranks = [0, 0] if outcome == 0.5 else ([0, 1] if outcome == 1.0 else [1, 0])
        [[r1], [r2]] = model.rate([[ratings[m["p1"]]], [ratings[m["p2"]]]], ranks=ranks)
        ratings[m["p1"]], ratings[m["p2"]] = r1, r2
    return {b: (float(r.mu), float(r.sigma)) for b, r in ratings.items()}
