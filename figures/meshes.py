"""Reconstructed semantic meshes (neural3d's) rendered from a few angles, beside the true mesh.

Reads the ``<method>_runs.json`` files that ``metrics.compare`` writes for
methods that keep a mesh (neural3d; :mod:`metrics.run.mesh_pointers`) and, when
the scene is there, the scene's true ``mesh.ply``.
Rendering is exact ray casting (:mod:`dataset.rendering.render`) with class colours and
simple Lambert shading.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from dataset.rendering.render import Raycaster, render_ground_truth
from envelope.camera import Intrinsics, look_at
from envelope.classes import NO_FACADE
from envelope.mesh import LabelledMesh, read_labelled_ply
from envelope.semantic_ply import read_semantic_ply
from figures.style import CLASS_RGB_ARRAY, MissingInput
from metrics.report.plots import save_figure
from metrics.run.mesh_pointers import read_mesh_pointers


@dataclass(frozen=True)
class MeshViewConfig:
    """Views of a mesh: azimuths and elevation (degrees), image size, field of view."""

    azimuths_deg: tuple[float, ...] = (30.0, 150.0, 270.0)
    elevation_deg: float = 25.0
    size_px: int = 256
    fov_deg: float = 40.0
    ambient: float = 0.35  # share of light that reaches faces turned away from the light


def face_labels_from_vertices(faces: np.ndarray, vertex_labels: np.ndarray) -> np.ndarray:
    """(F,) class per face: the label at least two of its vertices share, else the first's.

    Parameters
    ----------
    faces : (F, 3) int
    vertex_labels : (V,) int
    """
    lab = np.asarray(vertex_labels)[np.asarray(faces)]
    return np.where(lab[:, 1] == lab[:, 2], lab[:, 1], lab[:, 0]).astype(np.uint8)


def render_mesh_views(
    mesh: LabelledMesh, config: MeshViewConfig = MeshViewConfig()
) -> list[np.ndarray]:
    """(H, W, 3) uint8 class-colour, Lambert-shaded views from each azimuth; white background."""
    raycaster = Raycaster(mesh)
    lo, hi = mesh.vertices_m.min(axis=0), mesh.vertices_m.max(axis=0)
    centre = (lo + hi) / 2
    radius = 0.5 * float(np.linalg.norm(hi - lo))
    distance = radius / np.sin(np.deg2rad(config.fov_deg) / 2) * 1.05
    intrinsics = Intrinsics.from_fov(config.size_px, config.size_px, config.fov_deg)
    elev = np.deg2rad(config.elevation_deg)
    images = []
    for az in np.deg2rad(config.azimuths_deg):
        direction = np.array([np.cos(az) * np.cos(elev), np.sin(az) * np.cos(elev), np.sin(elev)])
        eye = centre + distance * direction
        gt = render_ground_truth(raycaster, intrinsics, look_at(eye, centre))
        light = direction + np.array([0.0, 0.0, 0.5])  # from the camera side, a little above
        light /= np.linalg.norm(light)
        lambert = np.clip(gt.normals_world @ light, 0, 1)
        shade = config.ambient + (1 - config.ambient) * lambert
        rgb = CLASS_RGB_ARRAY[np.minimum(gt.labels, len(CLASS_RGB_ARRAY) - 1)] * shade[..., None]
        rgb[gt.depth_z_m <= 0] = 255
        images.append(np.clip(rgb, 0, 255).astype(np.uint8))
    return images


def read_reconstruction(path: str | Path) -> LabelledMesh:
    """A neural3d ``mesh.ply`` (per-vertex labels) as a mesh with per-face labels."""

    vertices, faces, labels, _ = read_semantic_ply(path)
    return LabelledMesh(vertices, faces, face_labels_from_vertices(faces, labels),
                        np.full(len(faces), NO_FACADE))


def reconstructed_meshes(compare_out: Path,
                         data: Path | None) -> list[tuple[str, Path, Path | None]]:
    """(label, reconstructed mesh, true mesh or None) of each method's run with a mesh;
    the label is ``scene\nmethod (protocol)``."""
    out = []
    for run in read_mesh_pointers(compare_out):
        if run.mesh.is_file():
            truth = data / run.scene / "mesh.ply" if data is not None else None
            out.append((f"{run.scene}\n{run.method} ({run.protocol})", run.mesh,
                        truth if truth and truth.is_file() else None))
    if not out:
        raise MissingInput("no reconstructed mesh yet (no finished run of a method that "
                           "keeps one, such as neural3d, in the comparison)")
    return out


def plot_reconstructed_meshes(
    meshes: Sequence[tuple[str, Path, Path | None]], stem: str | Path,
    config: MeshViewConfig = MeshViewConfig(),
) -> list[Path]:
    """Rows: each scene's reconstruction (and its true mesh below it), one column per angle."""
    rows = []
    for label, recon, truth in meshes:
        rows.append((label, render_mesh_views(read_reconstruction(recon), config)))
        if truth is not None:
            scene = label.split("\n")[0]
            rows.append((f"{scene}\ntruth", render_mesh_views(read_labelled_ply(truth), config)))
    cols = len(config.azimuths_deg)
    fig = Figure(figsize=(2.0 * cols, 2.0 * len(rows)), layout="constrained")
    axes = np.atleast_2d(fig.subplots(len(rows), cols))
    for ax_row, (label, images) in zip(axes, rows):
        for ax, image in zip(ax_row, images):
            ax.imshow(image)
            ax.set_xticks([])
            ax.set_yticks([])
        ax_row[0].set_ylabel(label, fontsize="small")
    return save_figure(fig, stem)
