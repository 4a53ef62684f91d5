"""Windows of a camera's image, drawn as the whole frame clipped to the window.

A :class:`Window` is a sub-rectangle of a camera's output image.  It is drawn
with the frame's own projection and four OpenGL user clip planes a few pixels
outside it (:func:`clipped_to`), with the frame's viewport moved by whole
pixels so that the window's corner is the origin of an off-screen buffer only
as large as the window (:class:`WindowBuffer`): every vertex lands where it
does in the frame, less the window's offset, so the window's pixels are the
frame's crop (docs/concepts/servo.md, windows).
"""

from __future__ import annotations

import ctypes
import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import mujoco
import numpy as np

from headsim.sim.backend import RenderBackendError
from headsim.sim.mujoco_renderer import mjr_context


@dataclass(frozen=True)
class Window:
    """A sub-rectangle of a camera's output image: top-left (x0, y0) and size, px."""

    x0: int
    y0: int
    width: int
    height: int

    @property
    def x1(self) -> int:
        return self.x0 + self.width

    @property
    def y1(self) -> int:
        return self.y0 + self.height

    @classmethod
    def around(
        cls, centre_uv: tuple[float, float], half_px: float, image_size: tuple[int, int]
    ) -> Window:
        """The square of half-side ``half_px`` around ``centre_uv``, moved inside the image."""
        width, height = image_size
        side_u = min(width, 2 * math.ceil(half_px) + 1)
        side_v = min(height, 2 * math.ceil(half_px) + 1)
        x0 = min(max(round(centre_uv[0] - side_u / 2), 0), width - side_u)
        y0 = min(max(round(centre_uv[1] - side_v / 2), 0), height - side_v)
        return cls(int(x0), int(y0), int(side_u), int(side_v))


#: Raster pixels kept around a window by the clip planes of :func:`clipped_to`: the
#: edges that clipping makes lie this far outside the window's pixels.
CLIP_MARGIN_PX = 4
#: The OpenGL user clip planes the windows use (MuJoCo uses plane 0 for reflections).
CLIP_PLANES = (1, 2, 3, 4)


@contextmanager
def clipped_to(
    scene: mujoco.MjvScene, rect: Window, k: int, full_size: tuple[int, int]
) -> Iterator[None]:
    """Clip the scene's geometry to ``rect`` (canvas pixels, supersampled ``k`` times, in a
    frame of ``full_size`` raster pixels) plus :data:`CLIP_MARGIN_PX`, for the next
    ``mjr_render`` of the whole frame.

    Four planes through the camera's centre, in eye coordinates, from the frustum
    that ``mjr_render`` will use: geometry outside them is not rasterised, and
    every vertex inside keeps its place in the frame.
    """
    # PyOpenGL (mujoco's own dependency) without OpenGL.GL's wrappers: the raw calls of
    # the versions used, which load in 2 ms where OpenGL.GL takes 50-120 ms.
    from OpenGL.raw.GL.VERSION import GL_1_0 as GL

    full_w, full_h = full_size
    camera = scene.camera[0]
    near = float(camera.frustum_near)
    half_w = float(camera.frustum_width) or 0.5 * full_w / full_h * float(
        camera.frustum_top - camera.frustum_bottom
    )
    left = float(camera.frustum_center) - half_w
    right = float(camera.frustum_center) + half_w
    bottom, top = float(camera.frustum_bottom), float(camera.frustum_top)
    # x_ndc = (sx x + ox z) / (-z), likewise y (glFrustum), eye coordinates.
    sx, ox = 2 * near / (right - left), (right + left) / (right - left)
    sy, oy = 2 * near / (top - bottom), (top + bottom) / (top - bottom)
    m = CLIP_MARGIN_PX
    x_lo = 2 * (k * rect.x0 - m) / full_w - 1
    x_hi = 2 * (k * rect.x1 + m) / full_w - 1
    y_lo = 2 * (full_h - k * rect.y1 - m) / full_h - 1  # OpenGL's y runs up
    y_hi = 2 * (full_h - k * rect.y0 + m) / full_h - 1
    planes = (  # a point is kept where plane . (x, y, z, 1) >= 0
        (sx, 0.0, ox + x_lo, 0.0),
        (-sx, 0.0, -(ox + x_hi), 0.0),
        (0.0, sy, oy + y_lo, 0.0),
        (0.0, -sy, -(oy + y_hi), 0.0),
    )
    GL.glMatrixMode(GL.GL_MODELVIEW)
    GL.glLoadIdentity()  # the planes are given in eye coordinates
    for n, plane in zip(CLIP_PLANES, planes, strict=True):
        GL.glClipPlane(GL.GL_CLIP_PLANE0 + n, np.array(plane, dtype=np.float64))
        GL.glEnable(GL.GL_CLIP_PLANE0 + n)
    try:
        yield
    finally:
        for n in CLIP_PLANES:
            GL.glDisable(GL.GL_CLIP_PLANE0 + n)


#: Depth formats with a stencil and the same depth without one (GL enums).
_WITHOUT_STENCIL = {
    0x8CAD: 0x8CAC,  # GL_DEPTH32F_STENCIL8 -> GL_DEPTH_COMPONENT32F
    0x88F0: 0x81A6,  # GL_DEPTH24_STENCIL8 -> GL_DEPTH_COMPONENT24
}


class WindowBuffer:
    """A multisampled off-screen buffer like the context's own (same formats and
    samples), of another size, and its single-sample resolve buffer."""

    def __init__(
        self, context: mujoco.MjrContext, size: tuple[int, int], stencil: bool = True
    ) -> None:
        """``stencil``: False for a scene that never uses the stencil (MuJoCo's
        only use is reflections): then a depth buffer without one, of the depth the
        context's own holds (32F + stencil 8 -> 32F), and less memory to clear."""
        from OpenGL.raw.GL.VERSION import GL_3_0 as GL

        def parameter(renderbuffer: int, name: int) -> int:
            GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, renderbuffer)
            value = np.zeros(1, dtype=np.int32)
            GL.glGetRenderbufferParameteriv(GL.GL_RENDERBUFFER, name, value)
            return int(value[0])

        colour = parameter(context.offColor, GL.GL_RENDERBUFFER_INTERNAL_FORMAT)
        samples = parameter(context.offColor, GL.GL_RENDERBUFFER_SAMPLES)
        depth = parameter(context.offDepthStencil, GL.GL_RENDERBUFFER_INTERNAL_FORMAT)
        depth_attachment = GL.GL_DEPTH_STENCIL_ATTACHMENT
        if not stencil and depth in _WITHOUT_STENCIL:
            depth, depth_attachment = _WITHOUT_STENCIL[depth], GL.GL_DEPTH_ATTACHMENT
        width, height = size
        names = np.zeros(5, dtype=np.uint32)
        GL.glGenRenderbuffers(3, names[:3])
        GL.glGenFramebuffers(2, names[3:])
        self.renderbuffers = [int(r) for r in names[:3]]
        self.framebuffers = [int(f) for f in names[3:]]
        storage = (
            (samples, colour, GL.GL_COLOR_ATTACHMENT0, 0),
            (samples, depth, depth_attachment, 0),
            (0, colour, GL.GL_COLOR_ATTACHMENT0, 1),
        )
        for renderbuffer, (n, fmt, attachment, framebuffer) in zip(
            self.renderbuffers, storage, strict=True
        ):
            GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, renderbuffer)
            GL.glRenderbufferStorageMultisample(GL.GL_RENDERBUFFER, n, fmt, width, height)
            GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, self.framebuffers[framebuffer])
            GL.glFramebufferRenderbuffer(
                GL.GL_FRAMEBUFFER, attachment, GL.GL_RENDERBUFFER, renderbuffer
            )
        for framebuffer in self.framebuffers:
            GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, framebuffer)
            status = GL.glCheckFramebufferStatus(GL.GL_FRAMEBUFFER)
            if status != GL.GL_FRAMEBUFFER_COMPLETE:
                raise RenderBackendError(f"window buffer {size} incomplete (status {status})")


def draw_window(
    renderer: mujoco.Renderer, rect: Window, k: int, full_size: tuple[int, int]
) -> np.ndarray:
    """Raster pixels (k h, k w, 3) of ``rect`` (canvas pixels, supersampled ``k``
    times) of the scene, drawn as the whole frame of ``full_size`` raster pixels
    clipped to the window (:func:`clipped_to`).

    The frame's viewport is moved by whole pixels so that the window's corner is
    the origin of a buffer of the window's own size, made for it and deleted after
    the read, not the context's: ``mjr_render`` clears all of its viewport that the
    buffer holds, and a whole frame's multisampled buffer costs more to clear than a
    small window to draw.  Making and deleting the buffer costs about 0.12 ms of a
    window's 1.9 ms of CPU on llvmpipe; buffers kept and reused per size made no window
    faster, and rounding sizes up to share them made windows slower (a larger buffer
    to clear).
    """
    from OpenGL.raw.GL.VERSION import GL_1_0, GL_3_0

    full_w, full_h = full_size
    context = mjr_context(renderer)
    width, height = k * rect.width, k * rect.height
    # MuJoCo's only use of the stencil: reflective geoms (a material's reflectance).
    stencil = bool(np.any(renderer.model.mat_reflectance > 0))
    buffer = WindowBuffer(context, (width, height), stencil)
    # The window's corner in the frame's raster (OpenGL's rows run bottom-up).
    x, y = k * rect.x0, full_h - k * rect.y1
    pixels = np.empty((height, width, 3), dtype=np.uint8)
    try:
        GL_3_0.glBindFramebuffer(GL_3_0.GL_FRAMEBUFFER, buffer.framebuffers[0])
        with clipped_to(renderer.scene, rect, k, full_size):
            mujoco.mjr_render(mujoco.MjrRect(-x, -y, full_w, full_h), renderer.scene, context)
        GL_3_0.glBindFramebuffer(GL_3_0.GL_READ_FRAMEBUFFER, buffer.framebuffers[0])
        GL_3_0.glBindFramebuffer(GL_3_0.GL_DRAW_FRAMEBUFFER, buffer.framebuffers[1])
        GL_3_0.glBlitFramebuffer(
            0, 0, width, height, 0, 0, width, height, GL_1_0.GL_COLOR_BUFFER_BIT, GL_1_0.GL_NEAREST
        )
        GL_3_0.glBindFramebuffer(GL_3_0.GL_READ_FRAMEBUFFER, buffer.framebuffers[1])
        GL_1_0.glPixelStorei(GL_1_0.GL_PACK_ALIGNMENT, 1)
        GL_1_0.glReadPixels(
            0,
            0,
            width,
            height,
            GL_1_0.GL_RGB,
            GL_1_0.GL_UNSIGNED_BYTE,
            pixels.ctypes.data_as(ctypes.c_void_p),
        )
    finally:
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, context)
        GL_3_0.glDeleteFramebuffers(2, np.array(buffer.framebuffers, dtype=np.uint32))
        GL_3_0.glDeleteRenderbuffers(3, np.array(buffer.renderbuffers, dtype=np.uint32))
    return pixels
