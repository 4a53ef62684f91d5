"""results.json from the typed results: enums write today's strings, blocks keep their key order."""

from __future__ import annotations

import json

import numpy as np
import pytest

from headsim.active.calibration_report import (
    CalibrationLayout,
    CalibrationReport,
    CalibrationSource,
    KnowledgeReport,
    LinesOfSightFit,
    PositionOutcome,
    VerticalReference,
)
from headsim.codec import decode, encode
from headsim.estimators.result import Method, Status
from headsim.files import to_jsonable
from headsim.procedures.model2 import Model2Result
from headsim.procedures.pursuit import PursuitResult
from headsim.procedures.tracking import TrackingResult
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.serialise import MEASUREMENT_KEYS, MeasurementEntry, experiment_block
from headsim.sim.events import RenderCounts

from .helpers import LOST, measurement

#: How results.json writes helpers.LOST.
LOST_WRITTEN = {
    "cause": "lost",
    "stage": "step 1",
    "camera": 2,
    "detail": "and at 12 eye angles searched",
}


def _full_report() -> CalibrationReport:
    return CalibrationReport(
        status=Status.OK,
        detail="",
        targets=3,
        fixated=2,
        renders=RenderCounts(images=10, windows=20, retakes=1, previews=9),
        positions=(PositionOutcome(None), PositionOutcome(LOST), PositionOutcome(None)),
        layout=CalibrationLayout(
            "near_far", 0.5, [0.4, 1.2], 0.16, 0.08, [[0.0, 0.5, 0.4], [0.1, 0.6, 0.9]]
        ),
        depth_noise_m=0.001,
        alpha_e_rad=[0.0578, -0.0254],
        alpha_e_std_rad=[1e-4, 2e-4],
        alpha_e_covariance_rad2=[[1e-8, 0.0], [0.0, 4e-8]],
        alpha_e_truth_rad=[0.0577, -0.0255],
        alpha_e_error_rad=[1e-4, 1e-4],
        alpha_e_paper_rad=[0.0578, -0.0254],
        converged=True,
        depth_residual_rms_m=0.002,
        vertical_reference=VerticalReference(
            [240.0, 241.0], [0.3, 0.3], [239.5, 240.5], [1.0, 1.01], [0.01, 0.01], [1.0, 1.0]
        ),
        lines_of_sight=LinesOfSightFit(
            [0.0578, -0.0254],
            [0.001, 0.002],
            [1e-3, 1e-3],
            [1e-3, 1e-3],
            [0.0005, 0.0002],
            np.eye(4).tolist(),
            0.15,
            0.0004,
            0.1498,
            True,
            "",
        ),
        knowledge=KnowledgeReport(
            [0.0578, -0.0254], [240.0, 241.0], [1.0, 1.01], [303.8, 345.1], None
        ),
        rendered_frames=12.5,
    )


def test_the_enums_write_the_strings_results_json_always_had() -> None:
    assert [m.value for m in Method] == ["model1", "model2", "fixation", "stereo_triangulation"]
    assert [s.value for s in Status] == ["ok", "failed"]
    assert to_jsonable([Method.MODEL1, Status.FAILED]) == ["model1", "failed"]


def test_a_measurement_writes_its_method_status_and_failure_as_documented() -> None:
    ok = encode(MeasurementEntry.of(MeasurementRecord(measurement(0.003, 0.5), "none", 0)))
    assert list(ok) == list(MEASUREMENT_KEYS)
    assert ok["method"] == "model2" and ok["status"] == "ok" and ok["failure"] is None
    assert ok["error_m"] == pytest.approx(0.003)
    lost = encode(MeasurementEntry.of(MeasurementRecord(measurement(0.0, 0.5, LOST), "none", 1)))
    assert lost["status"] == "Ca2 at step 1: target lost (and at 12 eye angles searched)"
    assert lost["failure"] == LOST_WRITTEN


def test_a_calibration_that_could_not_lay_out_its_positions_writes_five_keys() -> None:
    report = CalibrationReport(Status.FAILED, "failed: no room", 8, 0, RenderCounts())
    block = encode(report)
    assert block == {
        "status": "failed: no room",
        "targets": 8,
        "fixated": 0,
        "render_counts": {"images": 0, "windows": 0, "retakes": 0, "previews": 0, "total": 0},
        "positions": [],
    }


def test_a_calibration_block_reads_back_to_the_same_report_and_bytes() -> None:
    report = _full_report()
    text = json.dumps(to_jsonable(encode(report)), indent=2)
    block = json.loads(text)
    assert list(block)[:5] == ["status", "targets", "fixated", "render_counts", "layout"]
    assert block["render_counts"] == {
        "images": 10,
        "windows": 20,
        "retakes": 1,
        "previews": 9,
        "total": 40,
    }
    assert list(block)[-2:] == ["positions", "rendered_frames"]
    assert block["positions"][1] == {"status": LOST.message, "failure": LOST_WRITTEN}
    assert decode(CalibrationReport, block) == report
    source = CalibrationSource("/tmp/head.json", "quickstart", 0, "abc", report.renders)
    stored = decode(CalibrationReport, block, renders=RenderCounts(), source=source)
    assert stored.renders.total == 0 and stored.ok
    again = encode(stored)
    assert list(again)[-1] == "from" and again["from"]["render_counts"]["total"] == 40
    # What results.json held before the typed report: the block, no renders, then "from".
    nothing = {"images": 0, "windows": 0, "retakes": 0, "previews": 0, "total": 0}
    assert json.dumps(to_jsonable(again)) == json.dumps(
        to_jsonable({**block, "render_counts": nothing, "from": again["from"]})
    )


def test_a_block_from_before_renders_counted_previews_says_nothing_of_them() -> None:
    # head.json written by a headsim whose "renders" left the previews out: its count is
    # not today's, so a calibration read from it reports none rather than a wrong one.
    block = {k: v for k, v in encode(_full_report()).items() if k != "render_counts"}
    old = {**block, "renders": 31}
    with pytest.raises(KeyError, match="render_counts"):
        decode(CalibrationReport, old)
    assert decode(CalibrationReport, old, renders=RenderCounts()).renders == RenderCounts()


def test_each_experiment_writes_the_procedure_first() -> None:
    assert experiment_block("model2", Model2Result()) == {"procedure": "model2"}
    assert experiment_block("chessboard", None) == {"procedure": "chessboard"}
    tracking = TrackingResult(
        np.array([0.0, 1.0]), [(0.0, 0.5, 0.6)], np.array([1e-3, 2e-3]), 12, 4.0
    )
    assert list(experiment_block("tracking", tracking)) == [
        "procedure",
        "times_s",
        "waypoints_world_m",
        "errors_world_m",
        "renders_first",
        "renders_after_mean",
    ]
    never = PursuitResult({"mode": "smooth"}, failures=("ball: never present in the run",))
    assert experiment_block("pursuit", never) == {
        "procedure": "pursuit",
        "pursuit": {"mode": "smooth"},
    }
