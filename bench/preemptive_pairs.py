"""Which pairs preemptive matching keeps, against what matching every pair finds; prints a
Markdown table (the tuning of
:class:`dataset.importers.photos.preemptive_pairs.PreemptiveMatching`).

    python bench/preemptive_pairs.py SCENE --work DIR [--split S ...]
        [--top-features K ...] [--min-matches T ...]

Strips the renders of ``--split`` (default train and eval) of the rendered ``SCENE`` to
photos (:func:`dataset.importers.photos.stripped_renders.strip_renders`), extracts their
SIFT features as the photos source does (:class:`~dataset.importers.photos.sfm.SfmConfig`'s
defaults) and matches every pair with geometric verification (COLMAP's exhaustive matcher):
a pair's verified inliers are the reference. Then, for each ``--top-features`` K and
``--min-matches`` T (each photo keeping its default best partners too), the pairs
preemptive matching keeps: how many (share of all), the share of the pairs with 100 or more
verified inliers kept (the pairs that hold a model together), the share of pairs with 15 or
more (COLMAP's least) kept, the share of all verified inliers kept, and the fewest pairs a
photo keeps. The photos, database and matches stay in ``--work`` and are read again.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.tables import markdown_table  # noqa: E402
from dataset.importers.photos.photo_folder import list_photos  # noqa: E402
from dataset.importers.photos.preemptive_pairs import (  # noqa: E402
    PreemptiveMatching,
    selected_pairs,
)
from dataset.importers.photos.sfm import (  # noqa: E402
    SfmConfig,
    extract_features,
    preliminary_counts,
)
from dataset.importers.photos.stripped_renders import strip_renders  # noqa: E402
from envelope.protocols import EVAL_SPLIT, TRAIN_PROTOCOL  # noqa: E402

STRONG_INLIERS = 100
LEAST_INLIERS = 15
"""COLMAP's ``min_num_inliers``: fewer and a pair is not used."""
COLUMNS = ("top features", "min matches", "pairs kept", f">= {STRONG_INLIERS} inliers kept",
           f">= {LEAST_INLIERS} inliers kept", "inliers kept", "fewest pairs a photo keeps")


def verified_inliers(database: Path, names: list[str]) -> np.ndarray:
    """(n, n) symmetric: the verified inlier matches of each pair of ``names`` (sorted image
    names) in COLMAP's ``database``; 0 where a pair has none."""
    import pycolmap

    index = {name: k for k, name in enumerate(names)}
    db = pycolmap.Database.open(database)
    try:
        by_id = {im.image_id: index[im.name] for im in db.read_all_images()}
        pair_ids, geometries = db.read_two_view_geometries()
    finally:
        db.close()
    inliers = np.zeros((len(names), len(names)), np.int64)
    for pair_id, geometry in zip(pair_ids, geometries):
        a, b = (by_id[i] for i in pycolmap.pair_id_to_image_pair(pair_id))
        inliers[a, b] = inliers[b, a] = len(geometry.inlier_matches)
    return inliers


def table_row(counts: np.ndarray, inliers: np.ndarray, top: int, min_matches: int) -> list[str]:
    """One row: what ``selected_pairs`` keeps of the pairs, weighed by ``inliers``."""
    n = len(counts)
    kept = np.zeros((n, n), bool)
    for i, j in selected_pairs(counts, min_matches, PreemptiveMatching().min_partners):
        kept[i, j] = kept[j, i] = True
    upper = np.triu_indices(n, 1)
    k, v = kept[upper], inliers[upper]

    def share(mask: np.ndarray) -> str:
        return f"{100 * (k & mask).sum() / max(mask.sum(), 1):.0f} % of {mask.sum()}"

    return [str(top), str(min_matches), f"{k.sum()} of {len(k)} ({100 * k.mean():.0f} %)",
            share(v >= STRONG_INLIERS), share(v >= LEAST_INLIERS),
            f"{100 * v[k].sum() / max(v.sum(), 1):.0f} %", str(kept.sum(axis=1).min())]


def main(argv: list[str] | None = None) -> int:
    import pycolmap

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scene", type=Path, help="a rendered scene folder")
    p.add_argument("--work", type=Path, required=True, help="folder for the photos and "
                   "COLMAP's database (one that holds them is read again)")
    p.add_argument("--split", nargs="+", default=[TRAIN_PROTOCOL, EVAL_SPLIT])
    defaults = PreemptiveMatching()
    p.add_argument("--top-features", type=int, nargs="+", default=[100, 200, 300])
    p.add_argument("--min-matches", type=int, nargs="+", default=[3, 4, 6, 8, 12])
    args = p.parse_args(argv)
    photos_dir, database = args.work / "photos", args.work / "database.db"
    if not database.is_file():
        strip_renders(args.scene, photos_dir, args.split)
        partial = database.with_suffix(".partial.db")
        partial.unlink(missing_ok=True)
        extract_features(list_photos(photos_dir), photos_dir, partial, SfmConfig())
        pycolmap.match_exhaustive(partial, device=pycolmap.Device.cpu)
        partial.rename(database)
    rows = []
    for top in args.top_features:
        names, counts = preliminary_counts(database, top, defaults.max_ratio)
        inliers = verified_inliers(database, names)
        rows += [table_row(counts, inliers, top, t) for t in args.min_matches]
    print(markdown_table(f"Preemptive matching on {args.scene.name} ({len(names)} photos)",
                         COLUMNS, rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
