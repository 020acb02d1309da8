"""2D-SS's WWR error against the resolution of the label images (pixel quantisation).

    python bench/baselines_resolution.py --data /tmp/h4_paper --family skyscraper --factors 1,2,4

Re-renders the ideal (or multi) views of every scene of one family from its
``mesh.ply`` with ``dataset.rendering.render.render_ground_truth``, at the same poses
and field of view with the intrinsics scaled by each factor, writes them as a
scene folder (label and millimetre-depth PNGs, as the benchmark stores them)
in a temporary folder, and runs the unchanged 2D-SS on it. Prints, per factor,
the building WWR absolute percentage error (mean ± std, as bench/baselines.py)
and the signed per-facade WWR error. Factor 1 reproduces the stored views.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

# Run as a script, this file's folder is sys.path[0] and its name would shadow
# the ``baselines`` package: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import numpy as np  # noqa: E402
import torch  # noqa: E402
from tqdm import tqdm  # noqa: E402

from baselines.wwr2dss import Wwr2dssConfig, run_2dss  # noqa: E402
from dataset.rendering.render import Raycaster, render_ground_truth  # noqa: E402
from dataset.set_roles import refuse_report_only  # noqa: E402
from envelope.mesh import read_labelled_ply  # noqa: E402
from envelope.method_input import MethodInput  # noqa: E402
from envelope.protocols import VIEW_PROTOCOLS  # noqa: E402
from envelope.scene_record import Frame, Scene  # noqa: E402
from envelope.scenes.images import write_depth_m, write_labels  # noqa: E402
from envelope.scenes.scene import (  # noqa: E402
    find_scene_folders,  # noqa: E402
    read_method_input,
    read_scene,
    write_transforms,
)
from metrics.score.errors import building_errors  # noqa: E402


def rerendered_scene(scene: Scene, raycaster: Raycaster, protocol: str, factor: int,
                     root: Path) -> MethodInput:
    """The scene's ``protocol`` views rendered at ``factor`` times the resolution, in ``root``."""
    frames = []
    for n, frame in enumerate(scene.frames_in(protocol)):
        k = frame.intrinsics.scaled(factor)
        gt = render_ground_truth(raycaster, k, frame.world_from_camera)
        stem = f"{protocol}_{n:03d}.png"
        write_labels(root / "semantics" / stem, gt.labels)
        write_depth_m(root / "depth" / stem, gt.depth_z_m, scene.depth_unit_scale_factor)
        frames.append(Frame(frame.file_path, frame.world_from_camera, k, frame.split,
                            facade_id=frame.facade_id, depth_file_path=f"depth/{stem}",
                            semantic_file_path=f"semantics/{stem}"))
    out = replace(scene, root=root, frames=tuple(frames), building=None)
    write_transforms(root, out)
    return read_method_input(root)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, required=True, help="folder of scene folders")
    parser.add_argument("--family", default="skyscraper", help="building type (building.json)")
    parser.add_argument("--views", choices=VIEW_PROTOCOLS, default="ideal")
    parser.add_argument("--factors", default="1,2", help="resolution factors, e.g. 1,2,4")
    parser.add_argument("--max-rectified-px", type=int, default=Wwr2dssConfig.max_rectified_px,
                        help="2D-SS's cap on the rectangle's longer side (raise it for factors "
                             "whose facades exceed it, else the warp downsamples)")
    args = parser.parse_args(argv)
    torch.set_num_threads(1)
    try:
        factors = [int(x) for x in args.factors.split(",")]
        if min(factors) < 1:
            raise ValueError("factors must be integers >= 1")
        config = Wwr2dssConfig(max_rectified_px=args.max_rectified_px)
        refuse_report_only(find_scene_folders(args.data, with_images=True),
                           "choose 2D-SS's resolution")
        folders = [f for f in find_scene_folders(args.data, with_images=True)
                   if getattr(read_scene(f).building, "type", None) == args.family]
        if not folders:
            raise ValueError(f"no scene of family {args.family!r} in {args.data}")
    except ValueError as exc:
        print(f"bench/baselines_resolution.py: error: {exc}", file=sys.stderr)
        return 2
    building_ape = {f: [] for f in factors}
    facade_err = {f: [] for f in factors}
    with tempfile.TemporaryDirectory(prefix="bench_resolution_") as tmp:
        for folder in tqdm(folders, desc="scenes"):
            scene = read_scene(folder)
            raycaster = Raycaster(read_labelled_ply(folder / "mesh.ply"))
            for factor in factors:
                root = Path(tmp) / f"{folder.name}_x{factor}"
                result = run_2dss(rerendered_scene(scene, raycaster, args.views, factor, root),
                                  args.views, config)
                building_ape[factor].append(building_errors(result, scene.building).wwr_ape)
                facade_err[factor] += [100 * (f.wwr / scene.building.facade(f.id).wwr - 1)
                                       for f in result.facades if not f.missing]
    print(f"2D-SS, {args.views} views of {len(folders)} {args.family} buildings\n")
    print("| factor | building WWR error (%) | per-facade signed WWR error (%) |")
    print("|---|---|---|")
    for factor in factors:
        b, e = np.array(building_ape[factor]), np.array(facade_err[factor])
        print(f"| {factor} | {b.mean():.2f} ± {b.std():.2f} | {e.mean():+.2f} ± {e.std():.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
