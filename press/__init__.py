"""The machine: crank-slider geometry and kinematics."""

from press.kinematics import CrankSlider

__all__ = ["CrankSlider"]
