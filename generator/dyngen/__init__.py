"""dyngen: robot dynamic models as exact, standalone C from a DH table.

The package follows the pipeline:
    description -> derivation -> reduction -> emission (-> extraction, data)
"""

__version__ = "0.1.0"
