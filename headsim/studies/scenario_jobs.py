"""A scenario run as a campaign's job (a scenario with fields set and a seed) and as its
row: the figures that the sweep's aggregate and the bench's scenario metrics read from one
:class:`~headsim.runs.result.RunResult`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from headsim.runs.result import RunResult
    from headsim.scenario.spec import Scenario


@dataclass(frozen=True)
class Job:
    """One scenario run: its position, a stable id, and the fields it sets (``seed``: the
    run's seed)."""

    index: int
    id: str
    scenario: str
    fast: bool
    params: dict[str, Any]

    def load(self) -> Scenario:
        """The checked scenario: its file (or name) with the fields set."""
        from headsim.scenario.loading import load_scenario

        overrides = {k: v for k, v in self.params.items() if k != "seed"}
        return load_scenario(
            self.scenario, fast=self.fast, seed=self.params.get("seed"), overrides=overrides
        )


def run_row(result: RunResult) -> dict[str, Any]:
    """Status, failures, measurements, errors of the calibrated measurements, renders,
    targets redrawn and the calibration's largest direction error (None where absent).

    Measurements made without the scenario's calibration (its "before" checks) do not
    count in the errors."""
    calibrated = result.calibration is not None
    acceptance = result.scenario.scene.acceptance
    ok = [r.measurement for r in result.records if r.measurement.ok]
    used = [
        r.measurement
        for r in result.records
        if r.measurement.ok and (r.knowledge != "none" or not calibrated)
    ]
    errors_mm = [1000 * float(np.linalg.norm(m.error_head_m)) for m in used]
    pct = [m.error_pct_of_depth for m in used]
    return {
        "status": "ok" if result.ok else "failed",
        "failures": len(result.failures),
        "failure_reasons": list(result.failures),
        "measurements_ok": len(ok),
        "measurements": len(result.records),
        "rms_error_pct_depth": float(np.sqrt(np.mean(np.square(pct)))) if pct else None,
        "mean_error_mm": float(np.mean(errors_mm)) if errors_mm else None,
        "max_error_mm": float(np.max(errors_mm)) if errors_mm else None,
        "renders": result.renders.overall.total,
        "targets_redrawn": acceptance.refused_total if acceptance is not None else 0,
        "calibration_max_error_rad": float(
            np.max(np.abs(np.asarray(result.calibration.alpha_e_error_rad)))
        )
        if result.calibration is not None and result.calibration.layout is not None
        else None,
    }
