"""Training-time augmentation of one (RGB, labels) frame: scale, crop, flip, perspective,
occluders, shadows, colour, blur, noise and JPEG compression, so that the segmenter learns
shapes and context rather than the renderer's exact colours and sharpness.

Geometry (scale, crop, flip, perspective) moves RGB and labels together (labels by
nearest neighbour); photometric changes (shadows included) touch the RGB only; an
occluder (a pole, trunk or sign in front of the facade) paints both, its pixels
labelled background as the real sets label what hides a facade. Pixels that a crop or a
warp takes from outside the image get the label :data:`IGNORE_LABEL`, which the loss
skips. Perspective, occluders and shadows are off by default (the render training's
recipe); :data:`REAL_PHOTO_AUGMENT` turns them on for training on real photos.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from envelope.classes import SemanticClass

IGNORE_LABEL = 255
"""Label of pixels that carry no training signal (outside the image after a crop)."""


@dataclass(frozen=True)
class AugmentConfig:
    """Ranges of the random changes; each is drawn per frame.

    ``crop_px``: side of the square training crop. ``scale``: (min, max) zoom factor,
    drawn log-uniformly (0.5: the building looks half as large; zooming out shows the
    crop the wide sky and ground of a large image). ``building_centre_p``:
    probability that the crop is centred on a building pixel rather than anywhere.
    ``brightness``, ``contrast``, ``saturation``, ``channel_gain``, ``gamma``: (min, max)
    factors. ``blur_p`` / ``blur_sigma_px``, ``noise_p`` / ``noise_sigma``, ``jpeg_p`` /
    ``jpeg_quality``: probability and range of Gaussian blur, Gaussian noise (in units of
    full scale) and JPEG re-compression. ``perspective_p`` / ``perspective_share``: a
    homography moving each crop corner by up to that share of the crop side (a camera not
    square to the facade). ``occluder_p`` / ``occluder_width_share``: one vertical bar of
    a random flat colour, that share of the crop wide, labelled background. ``shadow_p``
    / ``shadow_gain``: the RGB beyond a random straight edge (soft, a few pixels) times a
    gain in that range (a cast shadow).
    """

    crop_px: int = 128
    scale: tuple[float, float] = (0.25, 2.0)
    building_centre_p: float = 0.5
    flip_p: float = 0.5
    brightness: tuple[float, float] = (0.6, 1.4)
    contrast: tuple[float, float] = (0.7, 1.3)
    saturation: tuple[float, float] = (0.5, 1.5)
    channel_gain: tuple[float, float] = (0.9, 1.1)
    gamma: tuple[float, float] = (0.7, 1.4)
    blur_p: float = 0.3
    blur_sigma_px: tuple[float, float] = (0.3, 1.5)
    noise_p: float = 0.5
    noise_sigma: tuple[float, float] = (0.0, 0.04)
    jpeg_p: float = 0.3
    jpeg_quality: tuple[int, int] = (40, 95)
    perspective_p: float = 0.0
    perspective_share: float = 0.12
    occluder_p: float = 0.0
    occluder_width_share: tuple[float, float] = (0.04, 0.2)
    shadow_p: float = 0.0
    shadow_gain: tuple[float, float] = (0.35, 0.8)

    def __post_init__(self) -> None:
        if self.crop_px < 8 or not 0 < self.scale[0] <= self.scale[1]:
            raise ValueError(f"crop_px must be >= 8 and scale a (min, max) > 0, got {self}")


def augment_frame(rgb: np.ndarray, labels: np.ndarray, config: AugmentConfig,
                  rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """One augmented training sample of a frame.

    Parameters
    ----------
    rgb : (H, W, 3) uint8
    labels : (H, W) uint8 class ids

    Returns
    -------
    (crop_px, crop_px, 3) float32 RGB in [0, 1] and (crop_px, crop_px) int64 labels
    (:data:`IGNORE_LABEL` outside the image).
    """
    rgb, labels = _scaled_crop(rgb, labels, config, rng)
    if rng.uniform() < config.flip_p:
        rgb, labels = rgb[:, ::-1], labels[:, ::-1]
    rgb, labels = np.ascontiguousarray(rgb), np.ascontiguousarray(labels)
    # A change that is off draws nothing: the render recipe's random sequence is unchanged.
    if config.perspective_p and rng.uniform() < config.perspective_p:
        rgb, labels = _perspective(rgb, labels, config.perspective_share, rng)
    if config.occluder_p and rng.uniform() < config.occluder_p:
        rgb, labels = _occluder(rgb, labels, config.occluder_width_share, rng)
    x = _photometric(rgb, config, rng)
    return x, labels.astype(np.int64)


def _perspective(rgb: np.ndarray, labels: np.ndarray, share: float,
                 rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Warp a square crop by a homography that moves each corner by up to ``share`` of its
    side; pixels from outside the crop are black, and every pixel they reach (bilinear
    blending included) is :data:`IGNORE_LABEL`."""
    side = labels.shape[0]
    corners = np.float32([[0, 0], [side, 0], [side, side], [0, side]])
    moved = corners + rng.uniform(-share, share, (4, 2)).astype(np.float32) * side
    h = cv2.getPerspectiveTransform(corners, moved)
    size = (labels.shape[1], labels.shape[0])
    warp = dict(borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    out_rgb = cv2.warpPerspective(rgb, h, size, flags=cv2.INTER_LINEAR, **warp)
    out_labels = cv2.warpPerspective(labels, h, size, flags=cv2.INTER_NEAREST, **warp)
    inside = cv2.warpPerspective(np.full(labels.shape, 255, np.uint8), h, size,
                                 flags=cv2.INTER_LINEAR, **warp)
    out_labels[inside < 255] = IGNORE_LABEL  # a pixel any outside colour reached
    return out_rgb, out_labels


def _occluder(rgb: np.ndarray, labels: np.ndarray, width_share: tuple[float, float],
              rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A full-height vertical bar of one random colour, labelled background."""
    w = labels.shape[1]
    width = max(1, int(round(rng.uniform(*width_share) * w)))
    left = int(rng.integers(0, max(1, w - width + 1)))
    rgb, labels = rgb.copy(), labels.copy()
    rgb[:, left:left + width] = rng.integers(0, 256, 3, dtype=np.uint8)
    labels[:, left:left + width] = SemanticClass.BACKGROUND
    return rgb, labels


def _shadow(x: np.ndarray, gain: tuple[float, float], rng: np.random.Generator) -> np.ndarray:
    """(H, W, 3) float RGB times a gain beyond a random straight edge, blended over ~3 px."""
    h, w = x.shape[:2]
    angle = rng.uniform(0, 2 * np.pi)
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    cy, cx = rng.uniform(0, h), rng.uniform(0, w)
    distance = (xx - cx) * np.cos(angle) + (yy - cy) * np.sin(angle)
    inside = np.clip(0.5 + distance / 3.0, 0.0, 1.0)[..., None]
    return x * (1.0 - inside * (1.0 - rng.uniform(*gain)))


def _scaled_crop(rgb: np.ndarray, labels: np.ndarray, config: AugmentConfig,
                 rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A ``crop_px`` square of the frame zoomed by a random scale (RGB uint8, labels uint8)."""
    scale = float(np.exp(rng.uniform(*np.log(config.scale))))
    side = max(2, int(round(config.crop_px / scale)))  # source pixels the crop spans
    h, w = labels.shape
    building = np.flatnonzero(labels.ravel() != SemanticClass.BACKGROUND)
    if len(building) and rng.uniform() < config.building_centre_p:
        centre = divmod(int(building[rng.integers(len(building))]), w)
    else:
        centre = (int(rng.integers(h)), int(rng.integers(w)))
    top, left = centre[0] - side // 2, centre[1] - side // 2
    src_rgb = np.zeros((side, side, 3), np.uint8)
    src_lab = np.full((side, side), IGNORE_LABEL, np.uint8)
    y0, y1, x0, x1 = max(top, 0), min(top + side, h), max(left, 0), min(left + side, w)
    src_rgb[y0 - top:y1 - top, x0 - left:x1 - left] = rgb[y0:y1, x0:x1]
    src_lab[y0 - top:y1 - top, x0 - left:x1 - left] = labels[y0:y1, x0:x1]
    size = (config.crop_px, config.crop_px)
    # Shrinking: area averaging (a camera's pixels) or point sampling (an unfiltered render).
    shrink = cv2.INTER_AREA if rng.uniform() < 0.5 else cv2.INTER_NEAREST
    interp = shrink if side > config.crop_px else cv2.INTER_LINEAR
    return (cv2.resize(src_rgb, size, interpolation=interp),
            cv2.resize(src_lab, size, interpolation=cv2.INTER_NEAREST))


def _photometric(rgb: np.ndarray, config: AugmentConfig,
                 rng: np.random.Generator) -> np.ndarray:
    """Colour, blur, noise and JPEG changes of a uint8 RGB crop -> float32 in [0, 1]."""
    if rng.uniform() < config.jpeg_p:
        quality = int(rng.integers(config.jpeg_quality[0], config.jpeg_quality[1] + 1))
        ok, buf = cv2.imencode(".jpg", np.ascontiguousarray(rgb[..., ::-1]),
                               [cv2.IMWRITE_JPEG_QUALITY, quality])  # OpenCV wants BGR
        if ok:
            rgb = cv2.imdecode(buf, cv2.IMREAD_COLOR)[..., ::-1]
    x = rgb.astype(np.float32) / 255.0
    if config.shadow_p and rng.uniform() < config.shadow_p:
        x = _shadow(x, config.shadow_gain, rng).astype(np.float32)
    if rng.uniform() < config.blur_p:
        x = cv2.GaussianBlur(x, (0, 0), float(rng.uniform(*config.blur_sigma_px)))
    grey = x.mean(axis=2, keepdims=True)
    x = grey + (x - grey) * rng.uniform(*config.saturation)
    x = x * rng.uniform(*config.channel_gain, size=3).astype(np.float32)
    mean = float(x.mean())
    x = mean + (x - mean) * rng.uniform(*config.contrast)
    x = x * rng.uniform(*config.brightness)
    x = np.clip(x, 0.0, 1.0) ** rng.uniform(*config.gamma)
    if rng.uniform() < config.noise_p:
        x = x + rng.normal(0.0, rng.uniform(*config.noise_sigma), x.shape).astype(np.float32)
    return np.clip(x, 0.0, 1.0).astype(np.float32)


REAL_PHOTO_AUGMENT = AugmentConfig(
    brightness=(0.5, 1.6), channel_gain=(0.8, 1.2), perspective_p=0.5, occluder_p=0.25,
    shadow_p=0.3)
"""Augmentation for training on real photos (:mod:`segment.train` with real sets): wider
exposure and white balance than the render recipe, perspective, occluders and shadows."""
