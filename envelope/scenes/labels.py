"""Source class ids and mask colours -> ours.

Every method reads a scene's semantic masks through
:func:`envelope.scenes.scene_validation.read_frame_labels`, which uses the mapping here
that matches the scene's class list (``Scene.semantic_classes``): a scene that
declares the project's classes holds our ids (:mod:`envelope.classes`); a scene
that declares a source's classes (read from ``meta_data.json`` with its ids
still on disk) is remapped, and a class list that no known source has is an
error, never a silent misreading.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from envelope.classes import CLASS_NAMES, SemanticClass

ClassIds = Literal["renderer", "generator", "envelope_bench"]


@dataclass(frozen=True)
class ClassMapping:
    """A source's class ids and mask colours, and our class for each.

    ``names[i]``, ``to_ours[i]`` and ``colours[i]`` (RGB, 0-255) describe source id ``i``;
    ``colours`` is ``None`` when the source never writes colour-coded masks.
    """

    source: ClassIds
    names: tuple[str, ...]
    to_ours: tuple[int, ...]
    colours: tuple[tuple[int, int, int], ...] | None


_B, _WA, _WI, _R, _D, _O = (int(c) for c in SemanticClass)
_MAPPINGS: dict[str, ClassMapping] = {
    # EPFL-IMOS/buildnet3d BlenderProc renderer (bproc_generator/render/generate.py): the public
    # BuildNet3D image data. Vegetation, vehicles and furniture are not the envelope.
    "renderer": ClassMapping(
        "renderer",
        ("background", "wall", "door", "window", "roof", "chimney",
         "vegetation", "vehicle", "furniture", "misc"),
        (_B, _WA, _D, _WI, _R, _O, _B, _B, _B, _O),
        ((0, 0, 0), (175, 200, 0), (0, 200, 200), (125, 0, 200), (175, 0, 200),
         (0, 50, 200), (0, 200, 50), (150, 50, 50), (50, 175, 50), (50, 50, 175)),
    ),
    # Schindler-EPFL-Lab/BuildNet3D-dataset procedural generator (config/segmentation_config.json).
    "generator": ClassMapping(
        "generator",
        ("background", "wall", "window", "roof"),
        (_B, _WA, _WI, _R),
        ((0, 0, 0), (177, 206, 0), (0, 206, 206), (177, 0, 206)),
    ),
    # Our own scenes exported with write_meta_data: ids are already ours.
    "envelope_bench": ClassMapping(
        "envelope_bench", CLASS_NAMES, tuple(range(len(CLASS_NAMES))), None
    ),
}


def class_mapping(class_ids: ClassIds) -> ClassMapping:
    """The :class:`ClassMapping` of ``"renderer"``, ``"generator"`` or ``"envelope_bench"``."""
    if class_ids not in _MAPPINGS:
        raise ValueError(
            f"unknown class_ids {class_ids!r}; choose one of {', '.join(_MAPPINGS)}"
        )
    return _MAPPINGS[class_ids]


def remap_labels(labels: np.ndarray, mapping: ClassMapping) -> np.ndarray:
    """A source's label image in our class ids.

    Parameters
    ----------
    labels : (H, W) int, or (H, W, 3) / (H, W, 4) uint8 colour-coded mask
        Source class ids, or the source's mask colours (alpha ignored).
    mapping
        From :func:`class_mapping`.

    Returns
    -------
    (H, W) uint8 our class ids.

    Raises
    ------
    ValueError
        An id or colour the source does not define, or a colour mask for a source without
        colours.
    """
    a = np.asarray(labels)
    if a.ndim == 3 and a.shape[2] in (3, 4):
        a = _ids_from_colours(a[..., :3], mapping)
    elif a.ndim != 2:
        raise ValueError(f"labels must be (H, W) ids or (H, W, 3) colours, got shape {a.shape}")
    if not np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"label ids must be integers, got dtype {a.dtype}")
    lut = np.asarray(mapping.to_ours, dtype=np.uint8)
    bad = (a < 0) | (a >= len(lut))
    if bad.any():
        raise ValueError(
            f"label image holds ids {sorted(set(np.unique(a[bad]).tolist()))[:10]} that the "
            f"{mapping.source!r} classes (0..{len(lut) - 1}: {', '.join(mapping.names)}) do "
            "not define; pick the class_ids the data was made with"
        )
    return lut[a]


def read_remapped_labels(path: str | Path, mapping: ClassMapping) -> np.ndarray:
    """(H, W) uint8 our class ids of a source's segmentation PNG (ids or colour-coded).

    Single-channel (and palette) images hold ids; RGB(A) images are colour-coded masks.
    """
    from PIL import Image

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"segmentation image {path} does not exist")
    with Image.open(path) as img:
        labels = np.asarray(img.convert("RGB") if img.mode == "RGBA" else img)
    return remap_labels(labels, mapping)


def _ids_from_colours(rgb: np.ndarray, mapping: ClassMapping) -> np.ndarray:
    """(H, W) int64 source ids of a colour-coded (H, W, 3) mask."""
    if mapping.colours is None:
        raise ValueError(
            f"the {mapping.source!r} classes have no mask colours; pass a single-channel "
            "label image of class ids"
        )
    if rgb.dtype != np.uint8:
        raise ValueError(f"colour masks must be uint8 RGB, got dtype {rgb.dtype}")
    key = _pack(rgb.astype(np.int64))
    palette = _pack(np.asarray(mapping.colours, dtype=np.int64))
    order = np.argsort(palette)
    pos = np.clip(np.searchsorted(palette[order], key), 0, len(palette) - 1)
    ids = order[pos]
    bad = palette[ids] != key
    if bad.any():
        colours = np.unique(rgb[bad].reshape(-1, 3), axis=0)[:5].tolist()
        raise ValueError(
            f"mask holds colours {colours} that the {mapping.source!r} palette does not "
            "define; pick the class_ids the data was made with (masks must be saved "
            "without anti-aliasing or lossy compression)"
        )
    return ids


def _pack(rgb: np.ndarray) -> np.ndarray:
    return (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]


def mapping_for_classes(semantic_classes: tuple[str, ...]) -> ClassMapping | None:
    """The known source whose class list is ``semantic_classes`` (``None`` for ours)."""
    if tuple(semantic_classes) == CLASS_NAMES:
        return None
    for mapping in _MAPPINGS.values():
        if tuple(semantic_classes) == mapping.names:
            return mapping
    raise ValueError(
        f"the scene declares classes {list(semantic_classes)}, which are neither the "
        f"project's ({', '.join(CLASS_NAMES)}) nor a known source's; re-import it with "
        "`python -m dataset.generate --buildnet3d`"
    )
