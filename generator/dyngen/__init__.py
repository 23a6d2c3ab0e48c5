"""dyngen: robot dynamic models as exact, standalone C from a DH table.

The package follows the pipeline:
    description -> derivation -> reduction -> emission (-> extraction, data)
"""

__version__ = "0.1.0"


def load(folder, real: str = "double"):
    """The compiled C of a generated folder (e.g. "generated/lwr") with one numpy method per
    function of its manifest: model.rnea(q, qd, qdd, s), g, M, c = model.control(q, qd, s).
    real "float" loads the <ROBOT>_USE_FLOAT build. See dyngen.runtime and docs/controller-functions.md."""
    from .runtime import load as _load  # cffi and numpy only when asked for

    return _load(folder, real=real)
