"""The simulator's events (sim/events.py): every image taken reported with its kind and cost."""

from __future__ import annotations

import pytest

from headsim.sim.events import NO_EVENTS, NoEvents
from headsim.sim.simulator import HeadSim


def test_the_default_sink_drops_events_and_the_simulator_uses_it() -> None:
    assert isinstance(NO_EVENTS, NoEvents)
    assert NO_EVENTS.emit(object()) is None
    with HeadSim("default") as sim:
        assert sim.sink is NO_EVENTS


def test_every_image_taken_is_reported_to_the_sink_with_its_kind_and_cost() -> None:
    from headsim.sim.events import ImageKind, ImageTaken
    from headsim.sim.render import Window

    events: list[object] = []

    class Sink:
        def emit(self, event: object) -> None:
            events.append(event)

    with HeadSim("default", sink=Sink()) as sim:
        window = Window(100, 80, 64, 48)
        full = sim.render(1)
        crop = sim.render_window("cam2", window)
        again = sim.retake(2)
        preview = sim.render_preview(1, 4)
        assert [(e.camera, e.kind) for e in events] == [  # type: ignore[attr-defined]
            (1, ImageKind.FULL),
            (2, ImageKind.WINDOW),
            (2, ImageKind.RETAKE),
            (1, ImageKind.PREVIEW),
        ]
        assert all(isinstance(e, ImageTaken) for e in events)
        taken = [e for e in events if isinstance(e, ImageTaken)]
        for event, image in zip(taken, (full, crop, again, preview), strict=True):
            assert event.image is image
        assert taken[1].window == window and crop.shape == (48, 64, 3)
        assert taken[3].binning == 4 and taken[0].window is None
        # What each image cost, in full frames, adds up to the simulator's own count.
        assert taken[0].rendered_frames == 1.0
        assert 0.0 < taken[1].rendered_frames < 0.05
        assert sum(e.rendered_frames for e in taken) == pytest.approx(sim.rendered_frames)
        assert len(taken) == sim.render_count
