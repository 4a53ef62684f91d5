"""The chessboard of Sec. VI-A measured with Model 2, with real rendering."""

from __future__ import annotations

import numpy as np

from headsim.active.eye_servo import EyeServo
from headsim.head.sim_head import SimHead
from headsim.procedures.chessboard import measure_chessboard
from headsim.sim import names
from headsim.sim.simulator import HeadSim


def test_chessboard_squares_come_out_30_mm() -> None:
    with HeadSim("chessboard") as sim:
        sim.set_body_pose(names.CHESSBOARD, [-0.105, 0.8, 0.285])
        # A 3 x 2 block of corners: 2 widths per row, 3 heights.
        head = SimHead(sim)
        run = measure_chessboard(head, EyeServo(head), corners=[9, 10, 11, 17, 18, 19])
        assert run.measured == 6
        assert len(run.widths_m) == 4 and len(run.heights_m) == 3
        np.testing.assert_allclose(run.true_widths_m, 0.03, atol=1e-9)
        np.testing.assert_allclose(run.widths_m, 0.03, atol=0.0005)
        np.testing.assert_allclose(run.heights_m, 0.03, atol=0.0005)
        assert {m.name for m in run.measurements} == {
            "corner_1_1",
            "corner_2_1",
            "corner_3_1",
            "corner_1_2",
            "corner_2_2",
            "corner_3_2",
        }
