"""One building -> one complete scene folder (docs/DESIGN.md layout), written atomically.

The folder holds orbit views (Algorithm 1) split into train/eval, one ideal view
per facade and five multi views per facade (and, with ``--street``, the street frames a car
takes from the road), each with RGB, z-depth, semantics,
normals and facade ids (``instances/``: ground truth for tests and evaluation
only), plus ``transforms.json``, ``building.json`` and ``mesh.ply``. It is
written into a hidden temporary folder and renamed into place when complete
(:func:`envelope.atomic.atomic_directory`), so a folder with the final name is
always finished. ``transforms.json`` records the config and seed under
``generator``, which is how a rerun recognises a finished scene.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from dataset.rendering.context import ViewMeshes
from dataset.rendering.facade_views import FacadeViewConfig, ideal_views, multi_views
from dataset.rendering.orbit_views import OrbitConfig, sample_orbit_views
from dataset.rendering.render import Raycaster, render_view
from dataset.rendering.shading import RgbConfig
from dataset.rendering.street_views import StreetConfig, street_views
from envelope.atomic import atomic_directory
from envelope.camera import Intrinsics
from envelope.executors.worker_pool import worker_pool
from envelope.mesh import write_labelled_ply
from envelope.protocols import (
    EVAL_SPLIT,
    IDEAL_PROTOCOL,
    MULTI_PROTOCOL,
    STREET_SPLIT,
    TRAIN_PROTOCOL,
    Split,
)
from envelope.provenance import (
    Provenance,
    ProvenanceChange,
    code_version,
    make_provenance,
    provenance_changes,
)
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import (
    DEPTH_MAX_UNITS,
    write_depth_m,
    write_facade_ids,
    write_labels,
    write_normals,
    write_rgb,
)
from envelope.scenes.scene import write_transforms
from envelope.truth import Building, write_building

SCENE_CODE = ("dataset", "envelope")  # a scene depends on the code that makes and writes it
SCENE_LIBRARIES = ("numpy", "embreex", "trimesh", "scipy", "shapely", "pillow",
                   "opencv-contrib-python-headless", "mapbox-earcut")
_POOL_CHUNK = 8  # views per task: few enough for a smooth progress bar, enough to amortise


@dataclass(frozen=True)
class GenerateConfig:
    """What a scene holds and how it is rendered.

    ``resolution``: square image size in pixels. ``views``: orbit views, split
    ``train_fraction`` train / rest eval. ``fov_deg``: horizontal (= vertical) field
    of view. ``supersampling``: RGB rays per pixel along each axis (labels and depth
    are always exact at pixel centres). ``depth_unit_scale_factor``: metres per unit
    of the 16-bit depth PNGs; a scene whose views reach farther than 65535 units uses
    the next coarser 1-2-5 step and records it in ``transforms.json``.
    ``ideal``/``multi``: whether to add those facade views. ``context``: render the
    buildings the source places around the building (``Building.context``) as occluders in
    every view, each camera moved in front of the neighbours in its way
    (:mod:`dataset.rendering.context`); the truth is the same either way. ``street``: add
    the street frames (:mod:`dataset.rendering.street_views`, their own lens); ``None`` (the
    default) leaves it out of the recorded config, so scenes without it are as before.
    """

    resolution: int = 512
    views: int = 200
    train_fraction: float = 0.5
    fov_deg: float = 60.0
    supersampling: int = 1
    depth_unit_scale_factor: float = 0.001
    ideal: bool = True
    multi: bool = True
    context: bool = False
    street: StreetConfig | None = None
    orbit: OrbitConfig = field(default_factory=OrbitConfig)
    facade_views: FacadeViewConfig = field(default_factory=FacadeViewConfig)
    rgb: RgbConfig = field(default_factory=RgbConfig)

    def __post_init__(self) -> None:
        if self.resolution < 8:
            raise ValueError(f"resolution must be >= 8 pixels, got {self.resolution}")
        if self.views < 1:
            raise ValueError(f"views must be >= 1, got {self.views}")
        if not 0 <= self.train_fraction <= 1:
            raise ValueError(f"train_fraction must be in [0, 1], got {self.train_fraction}")
        if not 1 <= self.fov_deg <= 150:
            raise ValueError(f"fov_deg must be in [1, 150] degrees, got {self.fov_deg}")
        if self.supersampling < 1:
            raise ValueError(f"supersampling must be >= 1, got {self.supersampling}")
        if self.depth_unit_scale_factor <= 0:
            raise ValueError("depth_unit_scale_factor must be > 0 metres per unit")

    def intrinsics(self) -> Intrinsics:
        """Square-pixel, centred intrinsics of every view."""
        return Intrinsics.from_fov(self.resolution, self.resolution, self.fov_deg)


@dataclass(frozen=True)
class PlannedView:
    """A view to render: its split, file stem, pose (4, 4), facade (ideal/multi only) and
    intrinsics where they are not the config's (street frames)."""

    split: Split
    name: str
    world_from_camera: np.ndarray
    facade_id: int | None = None
    intrinsics: Intrinsics | None = None


def plan_views(
    building: Building, raycaster: Raycaster, config: GenerateConfig, *, seed: int
) -> list[PlannedView]:
    """All views of a scene: orbit (train/eval interleaved), then ideal, then multi, then
    street (with ``config.street``)."""
    k = config.intrinsics()
    orbit = sample_orbit_views(building, raycaster, k, config.views, config=config.orbit, seed=seed)
    f = config.train_fraction
    views = []
    for i, pose in enumerate(orbit):
        # Interleave so train and eval both cover the whole sphere band.
        split = TRAIN_PROTOCOL if np.floor((i + 1) * f) > np.floor(i * f) else EVAL_SPLIT
        views.append(PlannedView(split, f"{split}_{i:04d}", pose))
    if config.ideal:
        for i, (fid, pose) in enumerate(ideal_views(building, raycaster, k,
                                                    config=config.facade_views)):
            views.append(PlannedView(IDEAL_PROTOCOL, f"{IDEAL_PROTOCOL}_{i:04d}", pose, fid))
    if config.multi:
        for i, (fid, pose) in enumerate(multi_views(building, raycaster, k,
                                                    config=config.facade_views, seed=seed + 1)):
            views.append(PlannedView(MULTI_PROTOCOL, f"{MULTI_PROTOCOL}_{i:04d}", pose, fid))
    if config.street is not None:
        street_k = config.street.intrinsics(config.resolution)
        for i, pose in enumerate(street_views(building, config.street, context=config.context)):
            views.append(PlannedView(STREET_SPLIT, f"{STREET_SPLIT}_{i:04d}", pose,
                                     intrinsics=street_k))
    return views


def depth_unit_for(
    base_unit_m: float, raycaster: Raycaster, poses: list[np.ndarray]
) -> float:
    """``base_unit_m``, or the next coarser 1-2-5 step if some view could see farther than
    the 16-bit range (the bound: farthest bounding-box corner in z-depth)."""
    lo, hi = raycaster.bounds_m
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])
    far = max(float(((corners - p[:3, 3]) @ -p[:3, 2]).max()) for p in poses)
    needed = far / DEPTH_MAX_UNITS
    if needed <= base_unit_m:
        return base_unit_m
    exponent = np.floor(np.log10(needed))
    for step in (1.0, 2.0, 5.0, 10.0):
        unit = float(step * 10.0**exponent)
        if unit >= needed:
            return max(unit, base_unit_m)
    raise AssertionError("unreachable")


def generate_scene(
    building: Building, out_dir: str | Path, config: GenerateConfig, *, seed: int,
    name: str | None = None, progress: bool = True, workers: int = 1,
    inputs: dict[str, Any] | None = None,
) -> Path:
    """Write one complete scene folder ``out_dir / name`` atomically; return its path.

    ``name`` defaults to the building id. ``seed`` fixes the cameras and the
    building's look. An existing folder of that name is replaced. ``workers`` > 1
    renders the frames in that many processes (same files as with one). ``inputs``
    (JSON) says what the building was made from; it goes into the scene's provenance.

    Raises
    ------
    ValueError
        If the name is not a plain folder name, ``workers < 1``, or the building
        cannot be framed.
    """
    name = building.truth.id if name is None else name
    _check_scene_name(name)
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    meshes = ViewMeshes(building, context=config.context)
    k = config.intrinsics()
    # street frames already stand in the street: only the planned views move
    views = [v if v.split == STREET_SPLIT else
             replace(v, world_from_camera=meshes.street_pose(v.world_from_camera))
             for v in plan_views(building, meshes.alone, config, seed=seed)]
    unit = depth_unit_for(config.depth_unit_scale_factor, meshes.rendered,
                          [v.world_from_camera for v in views])
    scene_dir = Path(out_dir) / name
    with atomic_directory(scene_dir) as tmp:
        bar = tqdm(total=len(views), desc=name, unit="view", disable=not progress, leave=False)
        with bar:
            if workers == 1:
                frames = []
                for view in views:
                    frames.append(_render_view(tmp, meshes, k, view, config, seed, unit))
                    bar.update()
            else:
                frames = _render_in_pool(building, tmp, k, views, config, seed, unit, workers,
                                         bar)
        scene = Scene(root=tmp, frames=tuple(frames), depth_unit_scale_factor=unit,
                      extra={"generator": generator_record(config, seed, inputs)})
        write_transforms(tmp, scene)
        write_building(tmp / "building.json", building.truth)
        write_labelled_ply(tmp / "mesh.ply", building.mesh)
    return scene_dir


def generator_record(
    config: GenerateConfig, seed: int, inputs: dict[str, Any] | None = None
) -> dict[str, Any]:
    """What ``transforms.json`` records under ``generator``: config, seed, code version and
    the scene's :class:`~envelope.provenance.Provenance` (``inputs``: what the building was
    made from, e.g. ``{"preset": "tiny", "recipe": "tiny_l_shaped"}`` or a mesh file's
    fingerprint; the seed is added)."""
    record = scene_provenance(config, seed, inputs)
    return {"config": _config_json(config), "seed": int(seed), "code_version": code_version(),
            "provenance": record.to_json_dict()}


def scene_provenance(
    config: GenerateConfig, seed: int, inputs: dict[str, Any] | None = None
) -> Provenance:
    """The provenance record the current code writes for a scene."""
    return make_provenance(_config_json(config), modules=SCENE_CODE,
                           inputs={**(inputs or {}), "seed": int(seed)},
                           libraries=SCENE_LIBRARIES)


def scene_changes(
    scene_dir: str | Path, config: GenerateConfig, seed: int,
    inputs: dict[str, Any] | None = None,
) -> list[ProvenanceChange]:
    """Why ``scene_dir`` is not the scene the current code would make; ``[]``: it is.

    A folder without ``transforms.json`` or with an unreadable generator record
    gives one change of part ``"record"``.
    """
    tf = Path(scene_dir) / "transforms.json"
    if not tf.is_file():
        return [ProvenanceChange("record", "no scene")]
    try:
        record = json.loads(tf.read_text()).get("generator", {}).get("provenance")
        stored = None if record is None else Provenance.from_json_dict(record)
    except (ValueError, AttributeError) as exc:
        return [ProvenanceChange("record", f"unreadable generator record: {exc}")]
    return provenance_changes(stored, scene_provenance(config, seed, inputs))


def only_code_changed(changes: list[ProvenanceChange]) -> bool:
    """Whether a scene differs only by the code or libraries that made it (same config, seed
    and inputs): then re-rendering it in place loses nothing a user chose."""
    return bool(changes) and all(c.part in ("code", "environment") for c in changes)


def scene_is_finished(
    scene_dir: str | Path, config: GenerateConfig, seed: int,
    inputs: dict[str, Any] | None = None,
) -> bool:
    """Whether ``scene_dir`` is the finished scene this code makes with this config, seed and
    inputs (its provenance record matches: same config, dataset code, inputs, libraries)."""
    return not scene_changes(scene_dir, config, seed, inputs)


def _render_view(
    tmp: Path, meshes: ViewMeshes, k: Intrinsics, view: PlannedView, config: GenerateConfig,
    seed: int, unit: float,
) -> Frame:
    k = k if view.intrinsics is None else view.intrinsics
    gt, rgb = render_view(meshes.rendered, k, view.world_from_camera, config=config.rgb,
                          seed=seed, supersampling=config.supersampling,
                          textures=meshes.textures)
    paths = {folder: f"{folder}/{view.name}.png"
             for folder in ("images", "depth", "semantics", "normals", "instances")}
    write_rgb(tmp / paths["images"], rgb)
    write_depth_m(tmp / paths["depth"], gt.depth_z_m, unit)
    write_labels(tmp / paths["semantics"], gt.labels)
    write_normals(tmp / paths["normals"], gt.normals_world)
    write_facade_ids(tmp / paths["instances"], gt.facade_ids)
    return Frame(
        file_path=paths["images"], world_from_camera=view.world_from_camera, intrinsics=k,
        split=view.split, facade_id=view.facade_id, depth_file_path=paths["depth"],
        semantic_file_path=paths["semantics"], normal_file_path=paths["normals"],
        instance_file_path=paths["instances"],
    )


def _render_in_pool(
    building: Building, tmp: Path, k: Intrinsics, views: list[PlannedView],
    config: GenerateConfig, seed: int, unit: float, workers: int, bar: tqdm,
) -> list[Frame]:
    """Render ``views`` in chunks over ``workers`` processes; frames in view order."""
    chunk = max(1, min(_POOL_CHUNK, len(views) // workers))
    jobs = [(building, tmp, k, views[i : i + chunk], config, seed, unit)
            for i in range(0, len(views), chunk)]
    frames: list[Frame] = []
    with worker_pool(min(workers, len(jobs))) as pool:
        for done in pool.imap(_render_chunk, jobs):
            frames.extend(done)
            bar.update(len(done))
    return frames


def _render_chunk(job: tuple) -> list[Frame]:
    building, tmp, k, views, config, seed, unit = job
    # BVHs per chunk: milliseconds for a building, a fraction of a second with its context
    meshes = ViewMeshes(building, context=config.context)
    return [_render_view(tmp, meshes, k, view, config, seed, unit) for view in views]


def _check_scene_name(name: str) -> None:
    if not name or name.startswith(".") or "/" in name or "\\" in name or name != name.strip():
        raise ValueError(
            f"scene name {name!r} is not a plain folder name (no slashes, no leading dot)"
        )


def _config_json(config: GenerateConfig) -> dict[str, Any]:
    record = json.loads(json.dumps(asdict(config)))
    if config.street is None:  # scenes without street frames record what they always did
        del record["street"]
    if config.rgb.look == "plain":  # as do scenes in the plain look
        del record["rgb"]["look"]
    return record
