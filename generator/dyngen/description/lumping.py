"""Rigid bodies merged exactly: links joined by fixed joints (or locked beyond the tip) become
one body with the summed mass, the mass-weighted centre of mass and the inertia moved to it
(parallel-axis theorem), all in the frame of the link they are merged into."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Body:
    mass: float
    com: np.ndarray  # (3,) in the body's frame
    inertia: np.ndarray  # (3, 3) about the centre of mass, body-frame axes

    @staticmethod
    def empty() -> "Body":
        return Body(0.0, np.zeros(3), np.zeros((3, 3)))

    def moved(self, R: np.ndarray, p: np.ndarray) -> "Body":
        """The same body seen from a frame in which this one's frame has rotation R, origin p."""
        return Body(self.mass, R @ self.com + p, R @ self.inertia @ R.T)

    def __add__(self, other: "Body") -> "Body":
        mass = self.mass + other.mass
        if mass == 0:
            return Body.empty()
        com = (self.mass * self.com + other.mass * other.com) / mass
        inertia = np.zeros((3, 3))
        for body in (self, other):
            d = body.com - com
            inertia += body.inertia + body.mass * (d @ d * np.eye(3) - np.outer(d, d))
        return Body(mass, com, inertia)
