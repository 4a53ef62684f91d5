"""The realistic preset's tolerance budget: each imperfection of a real head, with its source.

Each entry: (value, unit, where it comes from).  Lengths in metres, angles in
radians; the realistic preset (:func:`headsim.sim.settings.realistic_head`)
builds the paper's head to these tolerances.
"""

from __future__ import annotations

#: The realistic preset's tolerance budget: value, unit and where it comes from.
#: Each entry is one imperfection of a real head beside the paper's cameras.
REALISTIC_BUDGET: dict[str, tuple[float, str, str]] = {
    "nodal_offset_m": (
        0.020,
        "m",
        "entrance pupil in front of the yaw axis: C-mount lenses of 6-16 mm focal length "
        "have their entrance pupil 10-30 mm in front of the sensor-side flange, and eye "
        "mechanisms put the axis near the sensor (engineering assumption, middle of 10-30 mm)",
    ),
    "side_offset_m": (
        0.001,
        "m",
        "camera mounting: sensor-to-housing placement tolerance of industrial board cameras "
        "is about +-0.1-0.2 mm, the bracket's machined +-0.1 mm, a hand-assembled mount "
        "1 mm (stated engineering assumption); Ca1 +1 mm, Ca2 -0.5 mm",
    ),
    "baseline_error_m": (
        0.0003,
        "m",
        "two bearing bores on one machined plate: ISO 2768-m general tolerance for 30-120 mm "
        "is +-0.3 mm; the true baseline is 150.3 mm, the head believes 150 mm",
    ),
    "neck_error_m": (
        0.0005,
        "m",
        "D-H lengths d1, a2 of an assembled neck (stack of 3-4 parts, +-0.2 mm each, "
        "ISO 2768-m): +0.5 mm on d1, -0.5 mm on a2",
    ),
    "backlash_rad": (
        2.9e-4,
        "rad",
        "one arcminute: a zero-backlash harmonic drive is < 1 arcmin (Harmonic Drive CSF "
        "catalogue); a precision planetary head 1-3 arcmin",
    ),
    "count_error": (
        1.0,
        "count",
        "the true angle is anywhere within the count read (the encoder's quantisation: "
        "the paper's 2 pi / 25600 rad)",
    ),
    "eye_axis_tilt_rad": (
        0.002,
        "rad",
        "bearing bores perpendicular to the plate within 0.1 mm over 50 mm (ISO 1101 "
        "perpendicularity, machined part): 2 mrad; Ca1 +2, Ca2 -1 mrad",
    ),
    "position_noise_m": (
        0.001,
        "m",
        "a tape measure or ruler read to 1 mm (EC class II tape: +-0.3 mm per metre plus "
        "reading), on every coordinate of every calibration target",
    ),
}
