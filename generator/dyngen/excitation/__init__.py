"""Optimised excitation trajectories for identification (`dyngen excite`).

    design = optimise(robot, model, Settings(seed=1))      # design.trajectory: a FourierTrajectory
    design.condition, design.random_condition               # cond of the identification matrix

A finite Fourier series per joint (Swevers et al. 1997, Gaz et al. 2019) at rest at t = 0 and
at every period's end, scaled into the joint limits, with coefficients chosen to minimise the
condition number of the matrix `dyngen identify --consistent` fits: the base regressor with
the per-joint friction and offset columns.
"""

from .design import Design, Settings, identification_matrix, limits_of, optimise, random_design

__all__ = ["Design", "Settings", "identification_matrix", "limits_of", "optimise", "random_design"]
