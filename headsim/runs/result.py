"""A run's result as a user meets it: :class:`RunOutcome`'s data, with a short repr, an
HTML table, the printed summary and a plot, for a notebook."""

from __future__ import annotations

import html
import math
from typing import TYPE_CHECKING

from headsim.runs.accuracy import summarise
from headsim.runs.outcomes import RunOutcome
from headsim.runs.summary import band_figure, summary_text

if TYPE_CHECKING:
    from matplotlib.figure import Figure


class RunResult(RunOutcome):
    """Everything a run found (:class:`RunOutcome`), shown the way a notebook wants it."""

    # -- in a notebook ------------------------------------------------------------

    def _headline(self) -> tuple[str, str, str]:
        """(what ran, "3 of 3 measured", "3-D error RMS 0.156 % of depth" or "")."""
        s = self.scenario
        ran = f"{s.name}{' (fast)' if s.fast else ''}, seed {s.seed}, {s.experiment.procedure}"
        if not self.records:
            return ran, "no measurement records", ""
        stats = summarise(self.records)
        rms = stats.error_pct_of_depth_rms
        error = f"3-D error RMS {rms:.3f} % of depth" if math.isfinite(rms) else ""
        return ran, f"{stats.ok} of {stats.count} measured", error

    def __repr__(self) -> str:
        ran, measured, error = self._headline()
        status = "ok" if self.ok else f"FAILED ({len(self.failures)} problems)"
        return f"<RunResult {ran}: {'; '.join(p for p in (measured, error, status) if p)}>"

    def _repr_html_(self) -> str:
        """A small table for Jupyter: the run, the counts, the error and its depth bands."""
        ran, measured, _ = self._headline()
        rows = [
            ("run", ran),
            ("head", f"{self.scenario.preset} preset, {self.scenario.settings.head.name}"),
            ("measured", measured),
            ("status", "ok" if self.ok else "; ".join(self.failures)),
            ("renders", str(self.renders.overall.total)),
        ]
        if self.records:
            stats = summarise(self.records)
            rms = stats.error_pct_of_depth_rms
            rows.append(("3-D error RMS, % of depth", f"{rms:.3f}" if math.isfinite(rms) else "-"))
            rows += [(f"  {b.band}", band_figure(b)) for b in stats.by_depth]
        cells = "".join(
            f"<tr><th style='text-align:left'>{html.escape(k)}</th>"
            f"<td style='text-align:left'>{html.escape(v)}</td></tr>"
            for k, v in rows
        )
        return f"<table>{cells}</table>"

    def summary(self) -> str:
        """The table ``headsim run`` prints, the same text as summary.txt (without its
        final newline)."""
        return summary_text(self)

    def plot(self) -> Figure:
        """The 3-D error (% of depth) of each measurement against its true depth, one
        series per knowledge, the failed ones marked at 0: a matplotlib ``Figure`` (made
        without pyplot, so it draws under any back-end, Agg included)."""
        from matplotlib.figure import Figure

        figure = Figure(figsize=(6.0, 3.6), layout="constrained")
        axes = figure.add_subplot()
        for label in dict.fromkeys(r.knowledge for r in self.records):
            ok = [r.measurement for r in self.records if r.knowledge == label and r.measurement.ok]
            if ok:
                axes.plot(
                    [m.depth_m for m in ok],
                    [m.error_pct_of_depth for m in ok],
                    "o",
                    label=f"head knew {label} ({len(ok)})",
                )
        failed = [r.measurement for r in self.records if not r.measurement.ok]
        if failed:
            axes.plot(
                [m.depth_m for m in failed],
                [0.0] * len(failed),
                "x",
                label=f"failed ({len(failed)})",
            )
        axes.set_xlabel("true depth, m")
        axes.set_ylabel("3-D error, % of depth")
        axes.set_title(self._headline()[0])
        axes.set_ylim(bottom=0.0)
        if self.records:
            axes.legend()
        return figure


__all__ = ["RunResult"]
