"""The paper's equations as pure, vectorised numpy functions (no simulator inside).

Frames, signs and units as in ``docs/equations.md``: positions in the
head frame H, m; angles in rad; pixels in the OpenCV convention.
"""

from headsim.estimators.areas import (
    AreaComparison,
    Q1Side,
    areas_from_geometry,
    areas_from_pixels,
    compare_areas,
    q1_columns,
    q1_side,
)
from headsim.estimators.calibration import (
    Calibration,
    calibrate_initial_directions,
    calibration_coefficients,
)
from headsim.estimators.errors import (
    MODEL2_PARAMETERS,
    model1_covariance,
    model2_covariance,
    model2_jacobian,
    rel_dx_model2,
    rel_dy_model2,
    rel_dy_model2_simplified,
    rel_dz_correspondence,
    rel_dz_model1,
    rel_dz_model1_small_angle,
    rel_dz_model2,
    rel_dz_model2_small_angle,
)
from headsim.estimators.model1 import model1
from headsim.estimators.model2 import model2
from headsim.estimators.result import Flag, PositionEstimate, Uncertainty

__all__ = [
    "MODEL2_PARAMETERS",
    "AreaComparison",
    "Calibration",
    "Flag",
    "PositionEstimate",
    "Q1Side",
    "Uncertainty",
    "areas_from_geometry",
    "areas_from_pixels",
    "calibrate_initial_directions",
    "calibration_coefficients",
    "compare_areas",
    "model1",
    "model1_covariance",
    "model2",
    "model2_covariance",
    "model2_jacobian",
    "q1_columns",
    "q1_side",
    "rel_dx_model2",
    "rel_dy_model2",
    "rel_dy_model2_simplified",
    "rel_dz_correspondence",
    "rel_dz_model1",
    "rel_dz_model1_small_angle",
    "rel_dz_model2",
    "rel_dz_model2_small_angle",
]
