"""Relative positioning of several objects (Sec. III): the reference measured with
Model 2, then each object placed in its area S1..S12 by eq. (12) from the
four images at the two fixations, beside the areas from geometry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from headsim.active.events import FixationStarted, MeasurementDone
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import (
    HeadKnowledge,
    Measurement,
    Target,
)
from headsim.active.model2 import Model2Config, measure_model2
from headsim.estimators.areas import (
    AreaComparison,
    areas_from_geometry,
    areas_from_pixels,
    compare_areas,
)
from headsim.sim.events import EventSink
from headsim.sim.simulator import HeadSim
from headsim.vision.detect import (
    Detection,
    find_markers,
)


@dataclass(frozen=True)
class RelativeRun:
    """Areas S1..S12 of objects around a reference, by eq. (12) on pixels and by geometry.

    ``areas``/``true_areas``: label -> area number (0: unclassified or not
    seen in all four images); ``columns``: label -> (u11, u12, u21, u22), px;
    ``comparison``: the estimator's count of disagreements by margin.
    ``gain_areas``/``gain_comparison``: the same with each camera's offsets
    divided by its gain (px per encoder step, learnt by the servo from the
    images: no intrinsics), so the magnitude tests compare angles, not pixels
    of two different focal lengths; margins in px at the mean gain.
    """

    reference: Measurement
    areas: dict[str, int]
    true_areas: dict[str, int]
    columns: dict[str, tuple[float, float, float, float]]
    missing: tuple[str, ...]
    comparison: AreaComparison | None
    renders: int
    gain_areas: dict[str, int] = field(default_factory=dict)
    gain_comparison: AreaComparison | None = None


def _touching_blobs(found: dict[str, Detection], gap_px: float = 1.5) -> set[str]:
    """Labels of blobs that touch another label's blob in the same image.

    Where one ball partly hides another, both blobs meet and the hidden one's
    centroid moves by up to its radius, which no single image can tell from a
    shift.  Radii come from the blobs' areas (px): image-only.
    """
    blobs = [
        (name, np.array(d.uv), math.sqrt(d.area_px / math.pi))
        for name, d in found.items()
        if d.found and d.uv is not None
    ]
    out = set()
    for i, (name_a, uv_a, r_a) in enumerate(blobs):
        for name_b, uv_b, r_b in blobs[:i]:
            if float(np.linalg.norm(uv_a - uv_b)) < r_a + r_b + gap_px:
                out |= {name_a, name_b}
    return out


def relative_positioning(
    sim: HeadSim,
    servo: EyeServo,
    reference: Target,
    objects: dict[str, str],
    knowledge: HeadKnowledge | None = None,
    sink: EventSink | None = None,
) -> RelativeRun:
    """Measure ``reference`` with Model 2, then place ``objects`` (body -> colour) in areas.

    The four images (each camera at each step) are taken again at the two
    fixations' whole encoder steps, where the lines L11..L22 are.  An object
    whose blob touches another's in any image (one partly hides the other)
    counts as not seen: its centroid would be biased.
    ``sink``: where the reference's fixation and measurement are reported (None:
    the simulator's sink).
    """
    sink = sim.sink if sink is None else sink
    knowledge = knowledge or HeadKnowledge()
    start = sim.render_count
    sink.emit(FixationStarted(reference.name))
    ref = measure_model2(sim, servo, reference, knowledge, Model2Config(midline_px=0.0))
    sink.emit(MeasurementDone(ref))
    if not ref.ok:
        return RelativeRun(ref, {}, {}, {}, tuple(objects), None, sim.render_count - start)
    resolution = sim.settings.encoder_resolution_rad
    # The lines L11..L22 are the cameras' lines of sight at the two fixations
    # (not where a search took a y image).
    steps = (
        round(ref.details["step1_encoder_rad"] / resolution),
        round(ref.details["step2_encoder_rad"] / resolution),
    )
    columns: dict[str, list[float]] = {name: [math.nan] * 4 for name in objects}
    # Order of the four columns: u11 (Ca1, step 1), u12 (Ca1, step 2), u21, u22.
    for step_index, step in enumerate(steps):
        sim.command_eye_steps(step)
        sim.settle()
        for camera in (1, 2):
            found = find_markers(sim.render(camera), objects)
            touching = _touching_blobs(found)
            for name, detection in found.items():
                if detection.found and detection.uv is not None and name not in touching:
                    columns[name][2 * (camera - 1) + step_index] = detection.uv[0]
    seen = [name for name in objects if np.all(np.isfinite(columns[name]))]
    missing = tuple(name for name in objects if name not in seen)
    (u10, _), (u20, _) = knowledge.reference(sim, 1), knowledge.reference(sim, 2)
    alpha1, alpha2 = steps[0] * resolution, steps[1] * resolution
    areas: dict[str, int] = dict.fromkeys(objects, 0)
    true_areas: dict[str, int] = dict.fromkeys(objects, 0)
    comparison = gain_comparison = None
    gain_areas: dict[str, int] = {}
    if seen:
        cols = np.array([columns[name] for name in seen])
        u11, u12, u21, u22 = cols.T
        pixel_areas = areas_from_pixels(u11, u12, u21, u22, u10, u20, alpha1=alpha1, alpha2=alpha2)
        truth_h = np.array([sim.position(name, "head") for name in seen])
        effective = (sim.effective_initial_direction(1), sim.effective_initial_direction(2))
        truth = areas_from_geometry(truth_h, alpha1, alpha2, sim.settings.baseline_m, effective)
        comparison = compare_areas(pixel_areas, truth, u11, u12, u21, u22, u10, u20)
        areas.update(zip(seen, (int(a) for a in pixel_areas), strict=True))
        true_areas.update(zip(seen, (int(a) for a in truth), strict=True))
        g1, g2 = (abs(servo.gains.get(camera) or 0.0) for camera in (1, 2))
        if g1 > 0 and g2 > 0:
            gain = areas_from_pixels(
                u11, u12, u21, u22, u10, u20, alpha1=alpha1, alpha2=alpha2, kx=(g1, g2)
            )
            mean = (g1 + g2) / 2
            scaled = cols.copy()
            scaled[:, :2] = u10 + (cols[:, :2] - u10) * mean / g1
            scaled[:, 2:] = u20 + (cols[:, 2:] - u20) * mean / g2
            s11, s12, s21, s22 = scaled.T
            gain_comparison = compare_areas(gain, truth, s11, s12, s21, s22, u10, u20)
            gain_areas = dict(zip(seen, (int(a) for a in gain), strict=True))
    return RelativeRun(
        reference=ref,
        areas=areas,
        true_areas=true_areas,
        columns={name: (c[0], c[1], c[2], c[3]) for name, c in columns.items()},
        missing=missing,
        comparison=comparison,
        renders=sim.render_count - start,
        gain_areas=gain_areas,
        gain_comparison=gain_comparison,
    )


__all__ = ["RelativeRun", "relative_positioning"]
