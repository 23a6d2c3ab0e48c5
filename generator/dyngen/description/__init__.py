"""The robot description: a YAML file read into an immutable Robot value."""

from .robot import Joint, Limits, LinkValues, Robot
from .load import load_description, load_robot

__all__ = ["Joint", "Limits", "LinkValues", "Robot", "load_description", "load_robot"]
