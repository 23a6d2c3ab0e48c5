"""The models of the controller functions (catalogue: coriolis_matrix, ...), by catalogue model name."""

from __future__ import annotations

from . import coriolis, derivatives, forward_dynamics
from .models import Derivation


def controller_models(derivation: Derivation, operations, bases=None) -> dict:
    """operations: model -> its operation count, by which forward_dynamics picks its method.
    bases: kind -> BaseSet; the functions of the dynamics then read their grouped parameters
    (Derivation._grouped), as rnea does: the same values, fewer products. None: s itself."""
    full, inertia = ((bases or {}).get(kind) for kind in ("full", "inertia"))
    return {"coriolis_matrix": coriolis.coriolis_matrix(derivation, inertia),
            "mass_matrix_derivative": derivatives.mass_matrix_derivative(derivation, inertia),
            "regressor_slotine_li": coriolis.slotine_li_regressor(derivation),
            "forward_dynamics": forward_dynamics.forward_dynamics(derivation, operations, full),
            "rnea_derivatives": derivatives.rnea_derivatives(derivation, full),
            "forward_dynamics_derivatives": derivatives.forward_dynamics_derivatives(derivation, full)}
