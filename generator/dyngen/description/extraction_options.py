"""The extraction step's options (dyngen.options): the command line's extraction flags, the
YAML `extraction:` block and the problem file the driver reads all come from this class. Part of
the description: a robot YAML may set them, and its loader checks them (load.py)."""

from __future__ import annotations

from dataclasses import dataclass

from ..options import option

MAX_RUNS = 100_000
MAX_EVALUATIONS = 10**8
MAX_SEED = 2**31 - 1
MAX_THREADS = 1024


@dataclass
class Options:
    procedure: str = option("joint", "one stage over all coefficients, or the paper's two stages: gravity "
                            "(eq. 16), then inertia with the gravity parameters fixed (eq. 19)",
                            choices=("joint", "two-stage"))
    restarts: int = option(16, "random starts, eq. 17", metavar="K", bounds=(1, MAX_RUNS))
    seed: int = option(1, "seed of the random starts (reproducible)", bounds=(0, MAX_SEED))
    threads: int = option(0, "threads for the restarts; 0: all cores", bounds=(0, MAX_THREADS))
    global_algorithm: str = option("isres", "global NLopt stage before the local refinement", flag="--global",
                                   choices=("isres", "none"))
    global_maxeval: int = option(1500, "budget of the global stage", metavar="N", bounds=(0, MAX_EVALUATIONS))
    local_maxeval: int = option(1000, "budget of the local stage", metavar="N", bounds=(0, MAX_EVALUATIONS))
    hops: int = option(0, "basin-hopping kicks of each restart's local minimum", metavar="N", bounds=(0, 10_000))
    hop_size: float = option(0.1, "kick standard deviation, as a fraction of each parameter's range",
                             bounds=(0.0, 1.0))
    margin: float = option(1e-7, "consistency margin: smallest eigenvalue of tr(I)/2 E - I accepted [kg m^2]",
                           bounds=(0.0, 1e5))
    mass_margin: float = option(1e-3, "smallest link mass accepted [kg]", bounds=(0.0, 1e6))
    tolerance: float = option(1e-10, "constraint violation still counted as satisfied", bounds=(0.0, 1.0))
    identities: tuple = option((), 'an identity imposed on the parameters, e.g. "I7xz = c7x*c7z*m7" (eq. 15); '
                               "repeatable", flag="--identity", metavar="EQ", repeat=True)
