"""The insensitivity study's methods, their labels, its targets' bodies, its configuration
and its progress callback (the study's lowest module: plots and every study module use it)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from headsim.active.measurement import body_target
from headsim.sim import names
from headsim.vision.markers import MarkerDetector

METHODS = (
    "stereo",
    "active_v_known",
    "active_centre",
    "active_extended",
    "active_fixed_point",
    "active_refound",
)
#: The methods of the sweeps: re-finding the fixed point matters only where
#: the principal point moves (the comparison and the principal-point sweep).
SWEEP_METHODS = METHODS[:5]
#: How each method is named in tables and plots.
METHOD_LABELS = {
    "stereo": "calibrated stereo",
    "active_v_known": "active, v known (Table V)",
    "active_centre": "active, image centre (Table VI)",
    "active_extended": "active, extended calibration",
    "active_fixed_point": "active, zoom fixed point",
    "active_refound": "active, zoom fixed point found again",
}
TARGET = body_target(names.MARKERS[0], MarkerDetector("red"))
BALL = body_target(names.CALIBRATION_BALL, MarkerDetector("yellow"))


@dataclass(frozen=True)
class StudyConfig:
    """How much work each calibration and sweep point does.

    ``board_poses``: chessboard poses for the stereo calibration;
    ``calibration_targets``: Sec. V targets per active calibration;
    ``principal_poses``: chessboard poses per zoom fixed point;
    ``targets_per_depth``: targets at each depth of the depth sweep;
    ``table_targets``: how many of :data:`TABLE_TARGETS_HEAD` the other
    sweeps measure; ``fast``: the sweeps' short value lists.
    """

    preset: str = "paper"
    seed: int = 0
    board_poses: int = 20
    calibration_targets: int = 60
    principal_poses: int = 4
    targets_per_depth: int = 4
    table_targets: int = 6
    fast: bool = False

    @classmethod
    def quick(cls, **overrides: Any) -> StudyConfig:
        """The smallest study that still calibrates every method (tests, smoke runs)."""
        values: dict[str, Any] = {
            "board_poses": 8,
            "calibration_targets": 16,
            "principal_poses": 1,
            "targets_per_depth": 2,
            "table_targets": 3,
            "fast": True,
        }
        values.update(overrides)
        return cls(**values)
