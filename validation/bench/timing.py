"""Timing tools of the bench: every claim is a ratio measured in one run, each repetition
timing ours and the reference back to back."""
import statistics
import time


def repeats(quick):
    """Repetitions of a side-by-side measurement: fewer at the quick level."""
    return 3 if quick else 7


def timed(fn):
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def side_by_side(ours, reference, repeats):
    """Median of per-repetition ratios reference/ours, and the median times."""
    t_ours, t_ref, ratios = [], [], []
    for _ in range(repeats):
        a = timed(ours)
        b = timed(reference)
        t_ours.append(a)
        t_ref.append(b)
        ratios.append(b / a)
    return statistics.median(t_ours), statistics.median(t_ref), statistics.median(ratios)


def per_step_side_by_side(ours, reference, repeats):
    """Like ``side_by_side`` for calls that return how many steps they took: the median times
    per step and the median of the per-repetition ratios of time per step, ours / reference."""
    t_ours, t_ref, ratios = [], [], []
    for _ in range(repeats):
        start = time.perf_counter()
        n_ours = ours()
        a = (time.perf_counter() - start) / n_ours
        start = time.perf_counter()
        n_ref = reference()
        b = (time.perf_counter() - start) / n_ref
        t_ours.append(a)
        t_ref.append(b)
        ratios.append(a / b)
    return statistics.median(t_ours), statistics.median(t_ref), statistics.median(ratios)


def time_per_step(sim, budget=0.25):
    """Seconds per step of ``sim``: steps in one call, four times more each time, until a
    call takes longer than ``budget``."""
    steps = 1
    while True:
        t = timed(lambda: sim.step(steps))
        if t > budget or steps > 1 << 20:
            return t / steps
        steps *= 4


def each_thread_count():
    """1, then every thread numba has: numba's thread count set to each in turn while the
    caller measures, and put back afterwards."""
    import numba

    threads = numba.get_num_threads()
    try:
        for count in sorted({1, numba.config.NUMBA_NUM_THREADS}):
            numba.set_num_threads(count)
            yield count
    finally:
        numba.set_num_threads(threads)
