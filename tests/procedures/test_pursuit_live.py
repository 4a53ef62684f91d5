"""The pursuit procedure (procedures/pursuit.py): its results and recording, a target never
present, and the summary's lines."""

from __future__ import annotations

import math
from dataclasses import replace

from headsim.active.measurement import HeadKnowledge
from headsim.codec import encode
from headsim.live import Visibility
from headsim.procedures.pursuit import PursuitFigures, PursuitResult, run_pursuit
from headsim.scenario.loading import load_scenario


def test_pursuit_scenario_writes_results_and_a_recording_of_path_estimates_and_errors(
    tmp_path, capsys
) -> None:
    import json

    from rerun.chunk import RrdReader

    from headsim.cli import main

    rrd = tmp_path / "pursuit.rrd"
    code = main(
        ["run", "pursuit", "--fast", "--out", str(tmp_path), "--rrd", str(rrd), "--no-progress"]
    )
    out = capsys.readouterr().out
    assert code == 0, out
    experiment = json.loads((tmp_path / "results.json").read_text())["experiment"]
    frames = experiment["frames"]
    assert experiment["losses"] == 0 and frames == len(experiment["per_frame"]["error_m"])

    def frames_of(entity: str, component: str) -> list[object]:
        found = []
        for chunk in RrdReader(rrd).stream().filter(content=entity, components=component):
            batch = chunk.to_record_batch()
            names = batch.schema.names
            found += (
                batch.column("frame").to_pylist() if "frame" in names else [None] * batch.num_rows
            )
        return found

    assert frames_of("/world/pursuit/path", "LineStrips3D:strips") == [None]  # static
    errors = frames_of("/measurements/error_mm", "Scalars:scalars")
    assert len(errors) == frames and errors == sorted(
        errors
    )  # one per frame, on the frame timeline
    assert len(frames_of("/world/pursuit/estimates", "Points3D:positions")) == frames
    assert max(experiment["per_frame"]["error_m"]) < 0.02  # m, at about 1 m, 320 x 240


def test_a_target_never_present_is_a_failure_named_before_any_image() -> None:
    scenario = load_scenario("pursuit", fast=True)
    pursuit = scenario.scene.pursuit
    assert pursuit is not None
    late = replace(
        pursuit, visibility=Visibility(((pursuit.duration_s + 1, pursuit.duration_s + 2),))
    )
    scenario = replace(scenario, scene=replace(scenario.scene, pursuit=late))
    events: list[object] = []

    class Sink:
        def emit(self, event: object) -> None:
            events.append(event)

    records, experiment = run_pursuit(scenario, Sink(), HeadKnowledge(), "pursuit")
    assert records == []
    assert experiment.failures == (f"{pursuit.name}: never present in the run",)
    assert encode(experiment) == {"pursuit": experiment.pursuit}
    assert experiment.pursuit["duration_s"] == pursuit.duration_s
    assert [type(e).__name__ for e in events] == ["PhaseStarted"]


def test_the_summary_gives_millimetres_and_milliseconds_and_n_a_for_no_figure() -> None:
    figures = PursuitFigures(
        frames=60,
        frames_present=58,
        frames_lost=2,
        losses=1,
        reacquisitions=1,
        saccades=0,
        time_to_fixation_s=math.nan,
        lag_s=0.0333,
        offset_rms_px=0.5,
        position_rms_m=0.0012,
        position_rms_pct_of_depth=0.2,
        position_max_m=math.nan,
        ended="duration",
    )
    result = PursuitResult(
        pursuit={"path_kind": "sinusoid", "duration_s": 2.0, "predictor": True}, figures=figures
    )
    first, second, third, fourth = result.summary_lines()
    assert first.startswith("pursuit: sinusoid path for 2.0 s;") and "predictor on" in first
    assert second.startswith("frames 60 (target present 58), lost 2")
    assert "RMS along the path 1.20 mm" in third and "(max n/a mm)" in third
    assert "pursuit lag 33.3 ms" in third and "time to fixation n/a ms" in third
    assert fourth.startswith("vergence error") and "median n/a deg, RMS n/a deg" in fourth
    assert PursuitResult(pursuit={}).summary_lines() == []
