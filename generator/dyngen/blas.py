"""One BLAS thread for dyngen's commands and benchmarks.

dyngen's numerical work is on small matrices (tens of columns), where a multi-threaded BLAS
only adds synchronisation: on a loaded 2-core machine the diagnosis ran 4x slower with
OpenBLAS threads. Called by the `dyngen` command (not on importing the package, so a library
user's process keeps its own settings); it takes effect only before numpy is first imported,
and never overrides a value the user set.
"""

import os

VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def use_one_thread() -> None:
    for variable in VARIABLES:
        os.environ.setdefault(variable, "1")
