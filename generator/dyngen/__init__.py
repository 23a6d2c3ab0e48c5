"""dyngen: robot dynamic models as exact, standalone C from a DH table.

The package follows the pipeline:
    description -> derivation -> reduction -> emission (-> extraction, data)
"""

__version__ = "0.1.0"

# dyngen's numerical work is on small matrices (tens of columns), where a multi-threaded
# BLAS only adds synchronisation: on a loaded 2-core machine the diagnosis ran 4x slower with
# OpenBLAS threads. Unless the user chose otherwise, one BLAS thread (effective only when
# numpy is first imported after dyngen).
import os as _os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_var, "1")
