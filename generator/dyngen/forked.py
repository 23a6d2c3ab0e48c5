"""Work forked onto this machine's cores, summed in a fixed order (identify's passes, the
diagnosis's every-row passes), and glibc's heap kept for block-sized arrays. Below every stage:
both identification and diagnosis use it."""

from __future__ import annotations

import multiprocessing

_HEAP = {"M_TRIM_THRESHOLD": (-1, 256 << 20), "M_MMAP_THRESHOLD": (-3, 32 << 20)}  # glibc's mallopt numbers


def roomy_heap() -> None:
    """Keep freed block-sized arrays in this process's heap (glibc), not unmapped and mapped
    afresh: by default every array over the dynamic mmap threshold is a new mapping whose pages
    fault in one by one, and a pass over an hour's blocks makes ~10^4 such arrays (the 1 kHz
    hour's diagnose: 8.4 -> 1.6 s of system time). Peak memory is the same (the arrays are
    reused, not added); the heap's top is returned beyond 256 MiB free. Elsewhere than glibc:
    nothing."""
    import ctypes

    try:
        mallopt = ctypes.CDLL("libc.so.6").mallopt
    except (OSError, AttributeError):
        return
    for number, value in _HEAP.values():
        mallopt(number, value)


_FORKED = None  # the work of the in_order pass whose worker processes are forked now


def _call(item):
    return _FORKED(item)


def in_order(work, items, workers: int = 2):
    """work(item) for every item, yielded in the items' order: in `workers` processes forked
    now (so that they see the caller's state as it is: the settings of this pass), a few items
    ahead, not all (the results wait in memory); where forking is not possible, or in a pool's
    worker (which may not start processes), in this process. What the caller sums in this order
    is summed as in one process, bitwise. work and the items' results must be picklable only
    as far as the items and results go: work itself is inherited by the fork."""
    from concurrent.futures import ProcessPoolExecutor
    from itertools import islice

    global _FORKED
    if workers < 2 or "fork" not in multiprocessing.get_all_start_methods() \
            or multiprocessing.current_process().daemon or _FORKED is not None:
        yield from map(work, items)
        return
    items = iter(items)
    roomy_heap()  # before the fork: the workers inherit it
    _FORKED = work
    try:
        with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork")) as pool:
            ahead = [pool.submit(_call, item) for item in islice(items, 2 * workers)]
            while ahead:
                done = ahead.pop(0).result()
                ahead += [pool.submit(_call, item) for item in islice(items, 1)]
                yield done
    finally:
        _FORKED = None
