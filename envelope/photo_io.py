"""Reading a photo (for the segmenter, and for the photos source of ``dataset.generate``): any
common file in, (H, W, 3) uint8 RGB out, or a clear error.

Photos are not renders: they come grey, 16-bit, CMYK, with an alpha channel or a
palette, stored sideways with an EXIF orientation tag, or cut short by a failed copy.
:func:`read_photo_rgb` gives every one that can be read an upright 8-bit RGB image:

- the EXIF orientation is applied (the image as a viewer shows it), unless the caller
  asks for the pixels as stored (``upright=False``: what COLMAP and nerfstudio read);
- grey (``L``, ``LA``, ``1``), palette (``P``), ``RGBA``, ``CMYK`` (Adobe or not, as
  Pillow decodes it), ``YCbCr`` and ``LAB`` images are converted to RGB; an alpha
  channel is dropped;
- 16-bit grey (``I;16*``, or ``I`` as Pillow opens a 16-bit PNG) is scaled by
  255/65535, not clipped; 32-bit float images are refused (no range to assume);
- a truncated, corrupt or unreadable file, or one over Pillow's decompression-bomb
  limit, raises ``ValueError`` naming the file and what to do.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from PIL import Image, ImageOps, UnidentifiedImageError

_SIXTEEN_BIT_MODES = ("I;16", "I;16B", "I;16L", "I;16N", "I")


def read_photo_rgb(path: str | Path, *, upright: bool = True) -> np.ndarray:
    """The photo at ``path`` as the segmenter reads it: (H, W, 3) uint8 RGB, upright (its
    EXIF orientation applied) unless ``upright`` is false.

    Raises
    ------
    ValueError
        A missing, truncated, corrupt or unsupported file (the message says which).
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such image file")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            with Image.open(path) as img:
                img.load()
                shown = ImageOps.exif_transpose(img) if upright else img.copy()
    except (UnidentifiedImageError, Image.DecompressionBombError,
            Image.DecompressionBombWarning) as exc:
        raise ValueError(f"{path}: not an image Pillow can read ({exc})") from exc
    except (OSError, SyntaxError, ValueError) as exc:
        raise ValueError(f"{path}: truncated or corrupt image ({exc}); copy the file again "
                         f"or re-save it") from exc
    return pil_to_rgb(shown, str(path))


def pil_to_rgb(img: Image.Image, what: str = "image") -> np.ndarray:
    """(H, W, 3) uint8 RGB from a loaded Pillow image of any common mode (module doc).

    Raises
    ------
    ValueError
        A floating-point image, or an empty one.
    """
    if img.width < 1 or img.height < 1:
        raise ValueError(f"{what}: empty image ({img.width}x{img.height})")
    if img.mode == "F":
        raise ValueError(f"{what}: a 32-bit floating-point image has no fixed range; save it "
                         f"as 8- or 16-bit")
    if img.mode in _SIXTEEN_BIT_MODES:
        values = np.asarray(img).astype(np.float64)
        grey = np.clip(np.round(values * (255.0 / 65535.0)), 0, 255).astype(np.uint8)
        return np.ascontiguousarray(np.repeat(grey[..., None], 3, axis=2))
    if img.mode in ("RGBA", "LA", "PA") or (img.mode == "P" and "transparency" in img.info):
        img = img.convert("RGBA")
    return np.array(img.convert("RGB"), dtype=np.uint8)  # a writable copy
