"""Which stripped renders structure from motion links, and where it splits; prints Markdown.

    python bench/sfm_links.py SCENE_DIR [--split street] --work DIR

Copies the RGB images of one split of a rendered scene into a folder of photos (as
``bench/photos_from_renders.py`` does, :func:`dataset.importers.photos.stripped_renders.
strip_renders`), runs the photos source's structure from motion on them
(:func:`dataset.importers.photos.sfm.reconstruct`, its database and models kept under
``--work``; given a ``--work`` that holds them, it reads them again) and reports: every
model COLMAP made, with its photos and their pose errors against the truth after the best
similarity (rotation deg, position m); the SIFT keypoints per photo; and, for each two
models, the verified pairs (photo, photo, inlier matches, COLMAP's two-view configuration)
that join a photo of one to a photo of the other alone.
A diagnosis aid: it reads the truth, which the photos source never does.
"""

from __future__ import annotations

import argparse
import sys
from itertools import combinations
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from dataset.importers.photos.conventions import world_from_camera_gl  # noqa: E402
from dataset.importers.photos.photo_folder import list_photos  # noqa: E402
from dataset.importers.photos.pose_error import pose_errors  # noqa: E402
from dataset.importers.photos.sfm import SfmConfig, reconstruct  # noqa: E402
from dataset.importers.photos.stripped_renders import strip_renders  # noqa: E402
from envelope.protocols import STREET_SPLIT  # noqa: E402
from envelope.scenes.scene import read_scene  # noqa: E402

LINKS_SHOWN = 4
"""Strongest joining pairs listed for each two models."""


def main(argv: list[str] | None = None) -> int:
    import pycolmap

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scene", type=Path, help="a rendered scene folder")
    p.add_argument("--split", default=STREET_SPLIT, help=f"frames to pose (default "
                   f"{STREET_SPLIT})")
    p.add_argument("--work", type=Path, required=True, help="folder for the photos, "
                   "COLMAP's database and models (one that holds them is read again)")
    args = p.parse_args(argv)
    if (args.work / "database.db").is_file():
        truth = {Path(f.file_path).stem + ".jpg": f.world_from_camera
                 for f in read_scene(args.scene).frames if f.split == args.split}
    else:
        truth = strip_renders(args.scene, args.work / "photos", [args.split])
        try:
            reconstruct(list_photos(args.work / "photos"), args.work / "photos", args.work,
                        SfmConfig())
            print("The photos source accepts the largest model.\n")
        except ValueError as exc:
            print(f"The photos source stops: {exc}\n")
    models = [pycolmap.Reconstruction(d) for d in sorted((args.work / "sparse").iterdir())]
    members = [{m.images[i].name for i in m.reg_image_ids()} for m in models]
    print("| model | photos | which | rotation deg (median / max) | position m (median / max) |")
    print("|---|---|---|---|---|")
    for k, (model, names) in enumerate(zip(models, members)):
        names_sorted = sorted(names)
        recovered = np.stack([world_from_camera_gl(model.find_image_with_name(n)
                                                   .cam_from_world().matrix())
                              for n in names_sorted])
        e = pose_errors(recovered, np.stack([truth[n] for n in names_sorted]))
        which = " ".join(Path(n).stem.split("_")[-1] for n in names_sorted)
        print(f"| {k} | {len(names)} | {which}"
              f" | {np.median(e.rotation_deg):.3f} / {e.rotation_deg.max():.3f}"
              f" | {np.median(e.position_m):.3f} / {e.position_m.max():.3f} |")
    db = pycolmap.Database.open(str(args.work / "database.db"))
    name_of = {im.image_id: im.name for im in db.read_all_images()}
    keypoints = [db.num_keypoints_for_image(i) for i in name_of]
    print(f"\nSIFT keypoints per photo: min {min(keypoints)}, median "
          f"{int(np.median(keypoints))}, max {max(keypoints)}\n")
    pair_ids, geometries = db.read_two_view_geometries()
    pairs = []
    for pair_id, geometry in zip(pair_ids, geometries):
        a, b = pycolmap.pair_id_to_image_pair(pair_id)
        if len(geometry.inlier_matches):
            pairs.append((name_of[a], name_of[b], len(geometry.inlier_matches),
                          pycolmap.TwoViewGeometryConfiguration(geometry.config).name))
    db.close()
    print("| models | joining pairs | strongest (photo, photo, inliers, configuration) |")
    print("|---|---|---|")
    for (i, a), (j, b) in combinations(enumerate(members), 2):
        only_a, only_b = a - b, b - a
        joining = sorted((q for q in pairs if (q[0] in only_a and q[1] in only_b)
                          or (q[0] in only_b and q[1] in only_a)), key=lambda q: -q[2])
        shown = "; ".join(f"{Path(x).stem} {Path(y).stem} {n} {c}"
                          for x, y, n, c in joining[:LINKS_SHOWN])
        print(f"| {i}-{j} | {len(joining)} | {shown or '-'} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
