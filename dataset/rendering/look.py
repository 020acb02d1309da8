"""One building's appearance, as the renderer draws it: sun, sky, ground and materials.

Drawn from a seed by :func:`dataset.rendering.shading.sample_look`; read by the plain
shading (:mod:`dataset.rendering.shading`) and the photo look
(:mod:`dataset.rendering.photo_look`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np


@dataclass(frozen=True)
class Look:
    """One building's appearance; colours are linear RGB (3,) arrays, ``sun_dir`` a unit vector."""

    sun_dir: np.ndarray
    sun_rgb: np.ndarray
    sky_zenith_rgb: np.ndarray
    sky_horizon_rgb: np.ndarray
    ground_rgb: np.ndarray
    wall_material: Literal["plaster", "brick"]
    wall_rgb: np.ndarray
    mortar_rgb: np.ndarray
    roof_rgb: np.ndarray
    frame_rgb: np.ndarray
    door_rgb: np.ndarray
    other_rgb: np.ndarray
    interior_rgb: np.ndarray
    texture_seed: int
