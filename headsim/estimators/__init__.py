"""Estimators of the paper, as pure vectorised numpy functions (no simulator inside)."""

from headsim.estimators.model1 import model1
from headsim.estimators.model2 import model2
from headsim.estimators.result import Flag, PositionEstimate, Uncertainty

__all__ = ["Flag", "PositionEstimate", "Uncertainty", "model1", "model2"]
