"""The Sec. V calibration's report: results.json's ``calibration`` block, declared once.

The block is what results.json's ``calibration`` holds and what a calibration
file (head.json, :mod:`headsim.active.calibration_file`) stores; both are
:func:`headsim.codec.encode` of a :class:`CalibrationReport`, read back by
:func:`headsim.codec.decode`, and documented from the same fields.
Units are in the names: m, rad, px; positions in W unless named otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from headsim.active.failure import Failure
from headsim.active.measurement import HeadKnowledge
from headsim.codec import declared, doc
from headsim.estimators.result import Status
from headsim.sim.events import RenderCounts


@dataclass(frozen=True)
class CalibrationLayout:
    """Where the calibration ball was placed: the layout's kind and settings, and each position."""

    kind: str
    near_fraction: float | None
    depth_m: list[float]
    lateral: float
    vertical: float
    #: (N, 3) as drawn, or as read back from JSON
    positions_world_m: np.ndarray | list[list[float]]


@dataclass(frozen=True)
class VerticalReference:
    """The extended calibration's v0, px, and kx/ky of each camera, beside the truth."""

    v0_px: list[float]
    v0_std_px: list[float]
    v0_truth_px: list[float]
    kx_over_ky: list[float]
    kx_over_ky_std: list[float]
    kx_over_ky_truth: list[float]


@declared
class LinesOfSightFit:
    """The extended line-of-sight fit beside the truth.

    ``std_errors_*``: 1-sigma of alpha_e, rad, and of the offsets s1, s2, m;
    ``covariance``: of (alpha_e1, alpha_e2, s1, s2).
    """

    alpha_e_rad: list[float]
    offset_m: list[float]
    std_errors_alpha_e_rad: list[float] = doc("1-sigma of alpha_e", key="std_errors.alpha_e_rad")
    std_errors_offset_m: list[float] = doc("1-sigma of s1, s2", key="std_errors.offset_m")
    offset_truth_m: list[float] = doc("the true s1, s2")
    covariance: list[list[float]] = doc("of (alpha_e1, alpha_e2, s1, s2)")
    effective_baseline_m: float = doc("the baseline the fit implies")
    effective_baseline_std_m: float = doc("its 1-sigma")
    effective_baseline_truth_m: float = doc("the true one")
    separable: bool = doc("whether the offsets could be told from alpha_e")
    message: str = doc("the fit's remark")


@declared
class KnowledgeReport:
    """What the calibration taught the head (its :class:`HeadKnowledge`, as numbers;
    ``u0_px`` and ``los_offset_m`` default to a file written before they were kept)."""

    alpha_e_rad: list[float]
    v0_px: list[float | None]
    kx_over_ky: list[float]
    u0_px: list[float | None] = doc("", default_factory=lambda: [None, None])
    los_offset_m: list[float] | None = None

    @classmethod
    def of(cls, knowledge: HeadKnowledge) -> KnowledgeReport:
        """``knowledge`` as numbers (the inverse of :meth:`head_knowledge`)."""
        offsets = knowledge.los_offset_m
        return cls(
            alpha_e_rad=list(knowledge.alpha_e),
            v0_px=list(knowledge.v0),
            kx_over_ky=list(knowledge.kx_over_ky),
            u0_px=list(knowledge.u0),
            los_offset_m=None if offsets is None else list(offsets),
        )

    def head_knowledge(self) -> HeadKnowledge:
        """The :class:`HeadKnowledge` these numbers are."""
        a1, a2 = (float(a) for a in self.alpha_e_rad)
        v1, v2 = (None if v is None else float(v) for v in self.v0_px)
        r1, r2 = (float(r) for r in self.kx_over_ky)
        u1, u2 = (None if u is None else float(u) for u in self.u0_px)
        offsets = self.los_offset_m
        return HeadKnowledge(
            alpha_e=(a1, a2),
            v0=(v1, v2),
            kx_over_ky=(r1, r2),
            u0=(u1, u2),
            los_offset_m=None if offsets is None else (float(offsets[0]), float(offsets[1])),
        )


@declared
class PositionOutcome:
    """One calibration position: fixated (``failure`` None) or why not (``status``)."""

    status: str = doc('"ok", or the failure\'s message', init=False, compare=False)
    failure: Failure | None = doc("None: fixated")

    def __post_init__(self) -> None:
        text = "ok" if self.failure is None else self.failure.message
        object.__setattr__(self, "status", text)


@declared
class CalibrationSource:
    """Where a calibration read from a file came from (``[experiment.calibration] from``)."""

    path: str
    scenario: str
    seed: int
    head_hash: str
    #: the renders the calibration took when it ran, by kind (None if the file does not
    #: say: one written before calibration blocks had ``render_counts``, whose
    #: ``renders`` left the previews out)
    render_counts: RenderCounts | None = doc("its renders when it ran")


def _status(text: str) -> dict[str, Any]:
    ok = text == "ok"
    return {"status": Status.OK if ok else Status.FAILED, "detail": "" if ok else text}


#: Written only where the layout was made (the fit's fields after it).
_LAID = "layout"


@declared
class CalibrationReport:
    """The Sec. V calibration: results.json's ``calibration`` block.

    ``status``: OK, or FAILED with ``detail`` "failed: why".  ``layout`` is None
    when the ball positions could not be laid out (nothing below it was tried, nor
    written); the fit's fields are None when the fit did not run.  ``renders``: every
    image the calibration drew, by kind (previews included; none for one read from a
    file).  ``rendered_frames`` (pixels rendered, in full frames) is set by
    ``headsim calibrate`` only; ``source`` only for a calibration read from a file.
    """

    status: Status = doc(
        "`ok`, or its failure's cause (too few positions seen because ..., a degenerate "
        "layout because ..., no vertical spread for the extended fit)",
        write=lambda r: r.status_text,
        read=_status,
    )
    detail: str = doc("why it failed", skip=True)
    targets: int = doc("layout positions")
    fixated: int = doc("positions fixated")
    renders: RenderCounts = doc(
        "as the run's, for the calibration (in `from`, a stored calibration's, `null` for "
        "one written before schema 2)",
        key="render_counts",
        whole=True,
    )
    layout: CalibrationLayout | None = doc(
        "the positions: `kind` (a layout, or `given`), `near_fraction`, `depth_m`, "
        "`lateral`, `vertical`, `positions_world_m`",
        default=None,
        whole=True,
        only_with=_LAID,
    )
    depth_noise_m: float = doc(
        "error of the tape-measured depth of each ball, m", default=0.0, only_with=_LAID
    )
    position_noise_m: float = doc(
        "error of every measured coordinate of every ball, m", default=0.0, only_with=_LAID
    )
    lines_of_sight_fit: bool = doc(
        "whether the extended line-of-sight fit was asked for", default=False, only_with=_LAID
    )
    extended: bool = doc("whether the extended fit (v0, kx/ky) ran", default=False, only_with=_LAID)
    alpha_e_rad: list[float] | None = doc(
        "the fitted alpha_e of each camera, rad", default=None, only_with=_LAID
    )
    alpha_e_std_rad: list[float] | None = doc("its 1-sigma, rad", default=None, only_with=_LAID)
    alpha_e_covariance_rad2: list[list[float]] | None = doc(
        "its covariance, rad^2", default=None, only_with=_LAID
    )
    alpha_e_truth_rad: list[float] | None = doc(
        "the true alpha_e, rad", default=None, only_with=_LAID
    )
    alpha_e_error_rad: list[float] | None = doc(
        "fitted minus true, rad", default=None, only_with=_LAID
    )
    alpha_e_paper_rad: list[float] | None = doc("the paper's, rad", default=None, only_with=_LAID)
    converged: bool = doc("whether the fit converged", default=False, only_with=_LAID)
    depth_residual_rms_m: float | None = doc(
        "RMS of the fit's depth residuals, m", default=None, only_with=_LAID
    )
    vertical_reference: VerticalReference | None = doc(
        "`v0_px`, `kx_over_ky` with their `_std` and `_truth` (`null`: not extended)",
        default=None,
        whole=True,
        only_with=_LAID,
    )
    lines_of_sight: LinesOfSightFit | None = doc(
        "the extended fit: `alpha_e_rad`, `offset_m`, `std_errors`, `covariance` of "
        "(alpha_e1, alpha_e2, s1, s2), `offset_truth_m`, `effective_baseline_m` with "
        "`_std_m` and `_truth_m`, `separable`, `message` (`null`: not asked for)",
        default=None,
        whole=True,
        only_with=_LAID,
    )
    knowledge: KnowledgeReport | None = doc(
        "what the head measured with afterwards (`los_offset_m` included)",
        default=None,
        whole=True,
        only_with=_LAID,
    )
    positions: tuple[PositionOutcome, ...] = doc(
        "each layout position's `status` and `failure`, as a measurement's",
        default=(),
        whole=True,
    )
    rendered_frames: float | None = doc(
        "pixels rendered, in full frames (`headsim calibrate` only)",
        default=None,
        omit_if_none=True,
    )
    source: CalibrationSource | None = doc(
        "a stored calibration's origin: its `path`, `scenario`, `seed`, `head_hash` and "
        "`render_counts` (absent: it ran here)",
        key="from",
        default=None,
        omit_if_none=True,
        whole=True,
    )

    @property
    def ok(self) -> bool:
        return self.status is Status.OK

    @property
    def status_text(self) -> str:
        """ "ok", or "failed: why" (results.json's "status")."""
        return "ok" if self.ok else self.detail


__all__ = [
    "CalibrationLayout",
    "CalibrationReport",
    "CalibrationSource",
    "KnowledgeReport",
    "LinesOfSightFit",
    "PositionOutcome",
    "VerticalReference",
]
