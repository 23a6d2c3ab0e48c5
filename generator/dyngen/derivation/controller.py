"""The models of the controller functions (catalogue: coriolis_matrix, ...), by catalogue model name."""

from __future__ import annotations

from . import coriolis, derivatives, forward_dynamics
from .models import Derivation


def controller_models(derivation: Derivation, operations) -> dict:
    """operations: model -> its operation count, by which forward_dynamics picks its method."""
    return {"coriolis_matrix": coriolis.coriolis_matrix(derivation),
            "mass_matrix_derivative": derivatives.mass_matrix_derivative(derivation),
            "regressor_slotine_li": coriolis.slotine_li_regressor(derivation),
            "forward_dynamics": forward_dynamics.forward_dynamics(derivation, operations),
            "rnea_derivatives": derivatives.rnea_derivatives(derivation),
            "forward_dynamics_derivatives": derivatives.forward_dynamics_derivatives(derivation)}
