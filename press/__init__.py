"""The machine: press mechanisms (the slide's height over the crank turn) and the drive's dynamics.

A mechanism (``press.mechanism.Mechanism``) answers geometric questions only; the crank-slider, in line
or offset, is one (``press.crank_slider``). ``press.dynamics`` turns a mechanism's motion into crank
and motor torque. Nothing outside ``press/`` knows a link length.
"""

from press.crank_slider import CrankSlider
from press.mechanism import Mechanism

__all__ = ["CrankSlider", "Mechanism"]
