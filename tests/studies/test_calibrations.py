"""Every method's calibration on one head, beside the simulator's truth."""

from __future__ import annotations

import json

import numpy as np

from headsim.files import to_jsonable


def test_calibrations_are_close_to_the_truth(calibrations) -> None:
    report = calibrations.report()
    assert report["stereo"]["rms_px"] < 0.2
    assert max(abs(e) for e in report["stereo"]["focal_error_pct"]) < 0.5
    assert np.abs(report["active"]["alpha_e_error_mrad"]).max() < 0.5
    assert np.abs(report["principal_point"]["error_px"]).max() < 0.2
    assert np.abs(report["fixed_point"]["alpha_e_error_mrad"]).max() < 0.5
    json.dumps(to_jsonable(report), allow_nan=False)  # plain JSON
