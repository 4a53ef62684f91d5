"""Foveal correlation on exact synthetic geometry: a seeded pink-noise texture shifted by
known sub-pixel amounts (cv2.warpAffine), stripes, a plain ramp, an absent patch, and a
half-hidden one."""

from __future__ import annotations

import time

import cv2
import numpy as np
import pytest

from headsim.vision.correspondence import (
    Band,
    MatchConfig,
    MatchStatus,
    Tracker,
    around,
    cut_template,
    epipolar_band,
    find,
)

CONFIG = MatchConfig()


def pink(size: int, seed: int, contrast_grey: float = 40.0) -> np.ndarray:
    """A 1/f ("pink") noise texture, float grey levels around 128 with std ``contrast_grey``."""
    rng = np.random.default_rng(seed)
    f = np.fft.fftfreq(size)
    radius = np.hypot(*np.meshgrid(f, f))
    radius[0, 0] = 1.0
    spectrum = (rng.normal(size=(size, size)) + 1j * rng.normal(size=(size, size))) / radius
    spectrum[0, 0] = 0.0
    texture = np.real(np.fft.ifft2(spectrum))
    return 128.0 + contrast_grey * (texture - texture.mean()) / texture.std()


def shifted(image: np.ndarray, du: float, dv: float) -> np.ndarray:
    """``image`` moved by (du, dv) px: the content at (u, v) goes to (u + du, v + dv)."""
    move = np.array([[1.0, 0.0, du], [0.0, 1.0, dv]], dtype=np.float32)
    size = (image.shape[1], image.shape[0])
    return cv2.warpAffine(
        image.astype(np.float32), move, size, flags=cv2.INTER_CUBIC,
        borderMode=cv2.BORDER_REFLECT,
    )  # fmt: skip


def noisy(image: np.ndarray, rng: np.random.Generator, noise_grey: float = 2.0) -> np.ndarray:
    """The image as a camera gives it: noise, rounded to uint8."""
    return np.clip(np.round(image + rng.normal(0.0, noise_grey, image.shape)), 0, 255).astype(
        np.uint8
    )


def _trials(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Errors px, true-match scores and ambiguities, and absent-patch best scores over
    ``n`` seeded textures, sub-pixel shifts up to 6 px and noise of 2 grey levels."""
    rng = np.random.default_rng(0)
    errors, scores, ambiguities, absent = [], [], [], []
    for seed in range(n):
        base = pink(192, seed)
        uv = (96 + rng.uniform(-0.5, 0.5), 96 + rng.uniform(-0.5, 0.5))
        template = cut_template(noisy(base, rng), uv, CONFIG)
        du, dv = rng.uniform(-6.0, 6.0, 2)
        guess = (uv[0] + du + rng.uniform(-3, 3), uv[1] + dv + rng.uniform(-3, 3))
        match = find(template, noisy(shifted(base, du, dv), rng), around(guess, 12.0), CONFIG)
        assert match.status is MatchStatus.OK and match.uv is not None
        errors.append(np.hypot(match.uv[0] - uv[0] - du, match.uv[1] - uv[1] - dv))
        scores.append(match.score)
        ambiguities.append(match.ambiguity)
        other = noisy(pink(192, 1000 + seed), rng)
        absent.append(find(template, other, around((96.0, 96.0), 12.0), CONFIG).score)
    return np.array(errors), np.array(scores), np.array(ambiguities), np.array(absent)


def test_tracking_recovers_sub_pixel_shifts_within_005_px() -> None:
    errors, scores, ambiguities, absent = _trials(40)
    assert np.median(errors) < 0.02
    assert errors.max() < 0.05
    # The thresholds separate the two distributions with room on both sides.
    assert scores.min() > CONFIG.min_score + 0.1
    assert absent.max() < CONFIG.min_score - 0.1
    assert ambiguities.max() < CONFIG.max_ambiguity - 0.2


def test_the_predicted_spread_of_a_template_is_its_measured_one() -> None:
    # The LOW_TEXTURE threshold rests on this: the Cramer-Rao spread predicted from the
    # template's texture and the noise is what matching does, from rich to faint.
    rng = np.random.default_rng(20)
    for contrast_grey in (3.0, 10.0):
        predicted, errors = [], []
        for seed in range(40):
            base = pink(120, seed, contrast_grey)
            template = cut_template(noisy(base, rng), (60.0, 60.0), CONFIG)
            du, dv = rng.uniform(-3.0, 3.0, 2)
            image = noisy(shifted(base, du, dv), rng)
            match = find(template, image, around((60 + du, 60 + dv), 6.0), CONFIG)
            assert match.uv is not None
            predicted.append(template.sigma_px)
            errors.append(match.uv[0] - 60.0 - du)
        measured = float(np.sqrt(np.mean(np.square(errors))))
        assert 0.6 < measured / float(np.median(predicted)) < 1.5, (contrast_grey, measured)


def test_repetitive_stripes_are_ambiguous() -> None:
    # Stripes of 9 px period across a horizontal epipolar band, on rows of 13 px (a
    # 2-D texture: the template places itself, so this is no aperture problem), with
    # pink noise too weak to tell the periods apart: every period matches nearly as well.
    rng = np.random.default_rng(3)
    v, u = np.mgrid[0:192, 0:192].astype(np.float64)
    stripes = 128.0 + 50.0 * np.sin(2 * np.pi * u / 9.0) + 25.0 * np.sin(2 * np.pi * v / 13.0)
    stripes = stripes + pink(192, 5, contrast_grey=1.0)
    template = cut_template(noisy(stripes, rng), (96.3, 95.8), CONFIG)
    assert template.sigma_px < CONFIG.max_sigma_px
    band = Band(((70.0, 96.0), (122.0, 96.0)), 3.0)  # a horizontal epipolar band
    match = find(template, noisy(shifted(stripes, 2.4, 0.0), rng), band, CONFIG)
    assert match.status is MatchStatus.AMBIGUOUS
    assert match.ambiguity > CONFIG.max_ambiguity
    assert match.score > CONFIG.min_score  # confident, yet refused: both kept
    assert match.uv is not None


def test_flat_and_ramp_patches_are_low_texture() -> None:
    rng = np.random.default_rng(4)
    flat = np.full((120, 120), 90.0)
    ramp = 60.0 + 0.8 * np.arange(120, dtype=np.float64)[None, :] + np.zeros((120, 1))
    for plain in (flat, ramp):
        template = cut_template(noisy(plain, rng), (60.0, 60.0), CONFIG)
        assert template.sigma_px > CONFIG.max_sigma_px
        match = find(template, noisy(plain, rng), around((60.0, 60.0), 8.0), CONFIG)
        assert match.status is MatchStatus.LOW_TEXTURE
        assert np.isfinite(match.score)
    rich = cut_template(noisy(pink(120, 6), rng), (60.0, 60.0), CONFIG)
    assert rich.sigma_px < 0.1 * CONFIG.max_sigma_px


def test_an_absent_patch_is_lost_with_its_score() -> None:
    rng = np.random.default_rng(7)
    template = cut_template(noisy(pink(160, 8), rng), (80.0, 80.0), CONFIG)
    match = find(template, noisy(pink(160, 9), rng), around((80.0, 80.0), 15.0), CONFIG)
    assert match.status is MatchStatus.LOST
    assert match.score < CONFIG.min_score and match.uv is not None


def test_a_half_hidden_patch_is_occluded() -> None:
    rng = np.random.default_rng(10)
    base = pink(160, 11)
    template = cut_template(noisy(base, rng), (80.0, 80.0), CONFIG)
    clutter = pink(160, 99)  # a textured object in front, and a plain one
    for occluder in (clutter[:, 80:], np.full((160, 80), 70.0)):
        hidden = base.copy()
        hidden[:, 80:] = occluder  # the right half of the fovea hidden
        match = find(template, noisy(hidden, rng), around((80.0, 80.0), 6.0), CONFIG)
        assert match.status is MatchStatus.OCCLUDED
        assert match.uv is not None and np.isfinite(match.score)
    # Unhidden, the same point is OK: the quadrants agree.
    assert find(template, noisy(base, rng), around((80.0, 80.0), 6.0), CONFIG).ok


def test_the_band_restricts_the_search() -> None:
    rng = np.random.default_rng(12)
    base = pink(192, 13)
    template = cut_template(noisy(base, rng), (96.0, 96.0), CONFIG)
    image = noisy(shifted(base, 20.0, 0.0), rng)
    inside = find(template, image, Band(((90.0, 96.0), (130.0, 96.0)), 2.0), CONFIG)
    assert inside.ok and inside.uv is not None
    np.testing.assert_allclose(inside.uv, (116.0, 96.0), atol=0.05)
    # A band that misses the point finds nothing there: a low peak, not the point.
    beside = find(template, image, Band(((90.0, 120.0), (130.0, 120.0)), 2.0), CONFIG)
    assert beside.status is MatchStatus.LOST


def test_a_window_with_an_origin_answers_in_full_frame_pixels() -> None:
    rng = np.random.default_rng(14)
    base = pink(192, 15)
    template = cut_template(noisy(base, rng), (96.4, 97.2), CONFIG)
    image = noisy(shifted(base, 3.3, -1.7), rng)
    x0, y0 = 60, 50
    window = image[y0 : y0 + 90, x0 : x0 + 90]
    match = find(template, window, around((99.0, 95.0), 8.0), CONFIG, origin_px=(x0, y0))
    assert match.ok and match.uv is not None
    np.testing.assert_allclose(match.uv, (99.7, 95.5), atol=0.05)


def test_the_tracker_keeps_the_original_reference() -> None:
    rng = np.random.default_rng(16)
    base = pink(192, 17)
    tracker = Tracker(cut_template(noisy(base, rng), (96.0, 96.0), CONFIG), CONFIG)
    uv = (96.0, 96.0)
    for k in range(1, 11):  # ten looks, the point moving 0.37 px each
        match = tracker.track(noisy(shifted(base, 0.37 * k, 0.0), rng), around(uv, 6.0))
        assert match.ok and match.uv is not None
        uv = match.uv
    np.testing.assert_allclose(uv, (96.0 + 3.7, 96.0), atol=0.05)  # no drift
    assert tracker.refreshes > 0


def test_epipolar_band_projects_the_believed_ray() -> None:
    focal_px, baseline_m = 500.0, 0.1

    def project(points_cam1: np.ndarray) -> np.ndarray:  # a rectified pair, camera 2 right
        x, y, z = points_cam1.T
        return np.stack([320 + focal_px * (x - baseline_m) / z, 240 + focal_px * y / z], axis=1)

    band = epipolar_band(project, np.array([0.0, 0.0, 1.0]), [0.3, 1.0, 3.0], 2.0)
    np.testing.assert_allclose(band.points_uv[0], (320 - 500 * 0.1 / 0.3, 240.0))
    assert band.rect((640, 480)) == (151, 238, 307, 243)  # x1, y1 exclusive
    assert float(band.distance_px(np.array(250.0), np.array(243.0))) == pytest.approx(3.0)


def test_one_foveal_match_costs_about_a_millisecond() -> None:
    rng = np.random.default_rng(18)
    base = pink(192, 19)
    template = cut_template(noisy(base, rng), (96.0, 96.0), CONFIG)
    image = noisy(shifted(base, 1.3, 0.6), rng)
    start = time.perf_counter()
    for _ in range(20):
        find(template, image, around((97.0, 97.0), 12.0), CONFIG)
    assert (time.perf_counter() - start) / 20 < 0.02  # generous: a loaded 2-core machine


def test_a_template_at_the_border_is_refused() -> None:
    with pytest.raises(ValueError, match="within 20 px of the image border"):
        cut_template(np.zeros((100, 100), np.uint8), (5.0, 50.0), CONFIG)
