"""The head's settings as the exact forward model sees them: one converter to
:class:`headsim.geometry.synthetic.StereoHead`.

The reach checks, the placement helpers and the studies take each eye's
effective initial direction (mount yaw plus the image centre's ray, rad,
positive inwards) from here, so it is computed by the forward model alone.
Not modelled by the forward model: a camera's mount pitch and roll and its
eye's yaw-axis tilt (the simulator renders them).
"""

from __future__ import annotations

from headsim.geometry.synthetic import StereoHead
from headsim.sim.settings import HeadSettings

__all__ = ["effective_directions", "stereo_head"]


def stereo_head(settings: HeadSettings) -> StereoHead:
    """The true head as a :class:`StereoHead`: baseline, m; true intrinsics; mount yaws and
    optical-centre offsets; encoder step, rad; servo goal columns at the image centres."""
    cam1, cam2 = settings.cameras
    return StereoHead(
        baseline=settings.baseline_m,
        cam1=cam1.pinhole(),
        cam2=cam2.pinhole(),
        alpha_e1=cam1.mount_yaw_rad,
        alpha_e2=cam2.mount_yaw_rad,
        encoder_resolution=settings.encoder_resolution_rad,
        nodal1=cam1.nodal_offset_m,
        nodal2=cam2.nodal_offset_m,
        side1=cam1.side_offset_m,
        side2=cam2.side_offset_m,
    )


def effective_directions(settings: HeadSettings) -> tuple[float, float]:
    """Each eye's true effective initial direction at the image centre, rad (Ca1, Ca2).

    The mount yaw plus the horizontal angle of the image centre's ray (at the
    centre row), what Sec. V's calibration with the servo on the image centre
    finds when the camera has no mount pitch or roll.
    """
    return stereo_head(settings).effective_initial_directions()
