"""Check memory and disk before a run spends them, and refuse an impossible request.

A CLI estimates what its request will need (image size x views x workers,
marching-cubes grid, training pixels) with the per-item costs below, compares
it with what the machine has (``psutil`` if installed, else ``/proc/meminfo``;
``shutil.disk_usage`` for disk) and raises ``ValueError`` with the estimate and
a suggestion when it cannot fit. Where the machine does not say, nothing is refused.
"""

from __future__ import annotations

import shutil
from pathlib import Path

RENDER_BYTES_PER_RAY = 400
"""Peak memory of rendering one ray (one pixel at supersampling 1): measured 310-325 B with
tracemalloc at 128-256 px (rays, hits, shading buffers), plus room for embree's own."""
SCENE_PNG_BYTES_PER_PIXEL = 4.0
"""Disk per pixel of one frame's five PNGs (RGB, depth, labels, normals, facade ids); the
tiny preset at 64-96 px measured 1.4-2.6 B (PNG compresses flat facades well)."""
FACADE_VIEWS_PER_BUILDING = 60
"""Ideal + multi views assumed per building before it is built (6 per facade, 10 facades)."""
TRAIN_BYTES_PER_PIXEL = 200
"""Training pixels in memory: 48 B of tensors per pixel plus the float64 arrays they are made
from (rays, lengths) during loading."""
MESH_BYTES_PER_VOXEL = 16
"""Marching cubes: float32 SDF grid plus skimage's float64 copy and edge caches."""
MEMORY_FRACTION = 0.9
"""Refuse when an estimate exceeds this share of the memory available now."""


def available_memory_bytes() -> int | None:
    """Memory available to a new allocation now (``MemAvailable``), or ``None`` if unknown."""
    try:
        import psutil

        return int(psutil.virtual_memory().available)
    except ImportError:
        pass
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def free_disk_bytes(folder: str | Path) -> int | None:
    """Free bytes on the disk that holds ``folder`` (or its nearest existing parent)."""
    folder = Path(folder).absolute()
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    try:
        return int(shutil.disk_usage(folder).free)
    except OSError:
        return None


def format_bytes(n: float) -> str:
    """``1536`` -> ``"1.5 KiB"``; binary units up to TiB."""
    for unit in ("B", "KiB", "MiB", "GiB"):
        if abs(n) < 1024:
            return f"{n:.1f} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024
    return f"{n:.1f} TiB"


def check_memory(needed_bytes: float, what: str, suggestion: str,
                 available: int | None = None) -> None:
    """Raise ``ValueError`` if ``needed_bytes`` exceeds :data:`MEMORY_FRACTION` of the memory
    available (``available`` overrides the machine's figure, for tests)."""
    available = available_memory_bytes() if available is None else available
    if available is not None and needed_bytes > MEMORY_FRACTION * available:
        raise ValueError(f"{what} needs about {format_bytes(needed_bytes)} of memory but "
                         f"{format_bytes(available)} is available; {suggestion}")


def check_disk(needed_bytes: float, folder: str | Path, what: str, suggestion: str,
               free: int | None = None) -> None:
    """Raise ``ValueError`` if ``needed_bytes`` exceeds the free space where ``folder`` is."""
    free = free_disk_bytes(folder) if free is None else free
    if free is not None and needed_bytes > free:
        raise ValueError(f"{what} needs about {format_bytes(needed_bytes)} of disk in {folder} "
                         f"but {format_bytes(free)} is free; {suggestion}")


def check_generate_resources(resolution: int, supersampling: int, views_per_scene: int,
                             scenes: int, workers: int, out: str | Path) -> None:
    """Memory for ``workers`` renders at once and disk for every scene's PNGs."""
    rays = float(resolution) ** 2 * supersampling**2
    check_memory(RENDER_BYTES_PER_RAY * rays * workers,
                 f"rendering {resolution}x{resolution} px (supersampling {supersampling}) in "
                 f"{workers} worker(s)",
                 "lower --resolution, --supersampling or --workers")
    check_disk(SCENE_PNG_BYTES_PER_PIXEL * float(resolution) ** 2 * views_per_scene * scenes,
               out, f"{scenes} scene(s) of about {views_per_scene} views at {resolution} px",
               "lower --resolution or --views, or choose an --out on a larger disk")


def check_training_resources(pixels: int) -> None:
    """Memory for ``pixels`` training pixels (views x height x width at the image scale)."""
    check_memory(TRAIN_BYTES_PER_PIXEL * float(pixels),
                 f"training on {pixels:,} pixels",
                 "use fewer or smaller train images (the preset's image_scale)")


def check_mesh_resources(resolution: int) -> None:
    """Memory for a marching-cubes grid of ``resolution`` samples per side (at most)."""
    check_memory(MESH_BYTES_PER_VOXEL * float(resolution) ** 3,
                 f"a marching-cubes grid of {resolution}^3 samples",
                 "lower --resolution (256 resolves 5 cm on a 13 m building)")
