"""The adapter to mujoco.Renderer's private state: present in this MuJoCo, and named when not."""

from __future__ import annotations

import mujoco
import pytest

from headsim.sim.mujoco_renderer import (
    PRIVATE_ATTRIBUTES,
    RendererInternalsError,
    check_renderer,
    mjr_context,
)

_XML = "<mujoco><worldbody><geom size='1'/></worldbody></mujoco>"


def test_this_mujoco_has_every_private_attribute_headsim_uses() -> None:
    model = mujoco.MjModel.from_xml_string(_XML)
    with mujoco.Renderer(model, height=32, width=32) as renderer:
        check_renderer(renderer)
        assert isinstance(mjr_context(renderer), mujoco.MjrContext)


def test_a_missing_attribute_is_named_with_the_mujoco_version() -> None:
    model = mujoco.MjModel.from_xml_string(_XML)  # a real object without the renderer's state
    with pytest.raises(RendererInternalsError) as caught:
        check_renderer(model)
    message = str(caught.value)
    assert repr(PRIVATE_ATTRIBUTES[0]) in message
    assert mujoco.__version__ in message
