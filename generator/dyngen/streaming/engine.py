"""Where per-recording steps run: in this process, on a pool of local worker processes
(concurrent.futures), or on a Dask distributed cluster (`--scheduler ADDRESS`, the optional
extra `distributed`). No scheduling of our own: the executor's map, results in task order.

Local workers run with one BLAS thread (dyngen.blas: small matrices, and the cores are the
workers'). When this process already runs with one (the dyngen command sets it before NumPy
loads, so no BLAS thread pool exists to be copied), workers are forked: they start at once with
NumPy and the compiled model loaded, where spawning costs each worker about a second of imports.
Otherwise they are spawned fresh with one BLAS thread set before their NumPy loads. A Dask cluster's workers are the user's: they must see the recordings
and the generated model at the same paths (a shared file system) and should run with
OPENBLAS_NUM_THREADS=1 (docs/many-recordings.md).
"""

from __future__ import annotations

import multiprocessing
import os

from ..errors import InputError


def workers_default(tasks: int) -> int:
    return max(1, min(tasks, os.cpu_count() or 1))


def run_all(function, tasks: list, workers: int | None = None, scheduler: str | None = None) -> list:
    """[function(task) for task in tasks], run where asked; the first error is raised here."""
    if scheduler:
        return _on_dask(function, tasks, scheduler)
    workers = workers or workers_default(len(tasks))
    if workers <= 1 or len(tasks) <= 1:
        return [function(t) for t in tasks]
    from concurrent.futures import ProcessPoolExecutor

    from .. import blas

    single = all(os.environ.get(v) == "1" for v in blas.VARIABLES)
    method = "fork" if single and "fork" in multiprocessing.get_all_start_methods() else "spawn"
    with ProcessPoolExecutor(max_workers=min(workers, len(tasks)), mp_context=multiprocessing.get_context(method),
                             initializer=blas.use_one_thread) as pool:
        return list(pool.map(function, tasks))


def _on_dask(function, tasks, scheduler: str) -> list:
    try:
        from distributed import Client
    except ImportError:
        raise InputError("--scheduler", "", "needs Dask distributed (pip install 'dyngen[distributed]')") from None
    try:
        client = Client(scheduler, timeout="10s") if isinstance(scheduler, str) else scheduler
    except (OSError, TimeoutError, ValueError) as err:
        raise InputError("--scheduler", "", f"cannot reach the Dask scheduler at {scheduler} ({err})") from None
    try:
        futures = client.map(function, tasks, pure=False)
        return client.gather(futures)
    finally:
        if isinstance(scheduler, str):
            client.close()
