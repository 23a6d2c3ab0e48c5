"""Optimised excitation trajectories for identification (`dyngen excite`; design.py).

    design = optimise(robot, model, Settings(seed=1))      # design.trajectory: a FourierTrajectory
    design.condition, design.random_condition               # cond of the identification matrix
"""

from .design import Design, Settings, identification_matrix, limits_of, optimise, random_design

__all__ = ["Design", "Settings", "identification_matrix", "limits_of", "optimise", "random_design"]
