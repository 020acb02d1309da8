"""What neural3d's two shortcuts leave out, measured along a real training.

    python bench/neural3d_skips.py --scene DIR [--steps 2000] [--check 300 1000 2000]
        [--rays 4096] [--guesses 1e-4 1e-5 1e-6] [--threads 2] [--json FILE]

Trains the ``fast`` preset on one scene and, at every ``--check`` step, renders a
fixed batch of ``--rays`` random pixels twice in one go:

- **Samples guessed light** (``TrainConfig.min_estimated_weight``): every sample is
  evaluated with its SDF gradient, giving its NeuS weight; the guess from the SDF at
  the section ends (``neural3d.rendering.neus.edge_alpha``) is taken beside it. Per
  threshold: the share of samples the guess keeps, the share of heavy samples
  (weight above ``min_sample_weight``) it keeps (recall), and the share of the
  rendering weight it would drop.
- **Block-first occupancy refresh** (``OccupancyGrid.near_surface``): at every refresh
  of the training, the block-first grid against the grid of every cell: cells that
  differ, and SDF queries relative to every cell.

The training itself runs with the preset's settings (``--set`` overrides them), so
what is checked is the field as the default training makes it.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

# Run as a script, this file's folder is sys.path[0]: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import torch  # noqa: E402

from bench.neural3d import training_state, with_overrides  # noqa: E402
from bench.tables import markdown_table  # noqa: E402
from envelope.atomic import write_json_atomic  # noqa: E402
from neural3d.config import preset_config  # noqa: E402
from neural3d.rendering.neus import edge_alpha, neus_alpha, weights_from_alpha  # noqa: E402
from neural3d.rendering.occupancy import OccupancyGrid  # noqa: E402
from neural3d.rendering.sampling import (  # noqa: E402
    neus_upsample,
    ray_box_near_far,
    uniform_samples,
)


def guess_check(state, step: int, rays: int, guesses: list[float]) -> dict:
    """The guess against the NeuS weights on ``rays`` random pixels (drawn from ``step``)."""
    config, field = state.config, state.field
    gen = torch.Generator().manual_seed(step)
    idx = torch.randint(len(state.pixels), (rays,), generator=gen)
    o, d = state.pixels.origins[idx], state.pixels.dirs[idx]
    near, far, hit = ray_box_near_far(o, d, state.box_min, state.box_max)
    if state.occupancy is not None:
        near, far, hit = state.occupancy.clip_rays(o, d, near, far, hit)
    o, d, near, far = o[hit], d[hit], near[hit], far[hit]
    t = uniform_samples(near, far, config.samples_uniform, perturb=True, generator=gen)
    t, sdf_edges = neus_upsample(field.sdf, o, d, t, config.samples_importance,
                                 config.upsample_steps)
    mid, lengths = (t[:, 1:] + t[:, :-1]) * 0.5, t[:, 1:] - t[:, :-1]
    pts = (o[:, None] + d[:, None] * mid[..., None]).reshape(-1, 3)
    sdf, _, grad = field.sdf_feature_gradient(pts, create_graph=False)
    with torch.no_grad():
        inv_s = field.inv_s()
        cos = (grad.reshape(*mid.shape, 3) * d[:, None]).sum(-1)
        weights = weights_from_alpha(neus_alpha(sdf.reshape(mid.shape), cos, lengths, inv_s))
        guess = weights_from_alpha(edge_alpha(sdf_edges, inv_s))
    heavy = weights > config.min_sample_weight
    row = {"step": step, "inv_s": float(inv_s), "rays_hit": int(hit.sum()),
           "heavy_share": float(heavy.float().mean())}
    for g in guesses:
        kept = guess > g
        row[f"guess {g:g}"] = {
            "kept_share": float(kept.float().mean()),
            "recall": float((heavy & kept).sum() / heavy.sum().clamp(min=1)),
            "weight_dropped_share": float((weights * ~kept).sum() / weights.sum()),
        }
    return row


def with_refresh_check(grid: OccupancyGrid, log: list[dict]) -> None:
    """Make every refresh of ``grid`` also build the every-cell grid and log the difference."""
    near_surface = grid.near_surface

    def checked(sdf_fn, *, margin: float, blocks: bool = True) -> torch.Tensor:
        queries = []

        def counted(p: torch.Tensor) -> torch.Tensor:
            queries.append(len(p))
            return sdf_fn(p)

        fast = near_surface(counted, margin=margin)
        n_fast = sum(queries)
        every = near_surface(sdf_fn, margin=margin, blocks=False)
        log.append({"cells_differing": int((fast != every).sum()),
                    "near_surface_cells": int(every.sum()),
                    "query_share": n_fast / every.numel()})
        return fast

    grid.near_surface = checked


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", type=Path, required=True, help="a scene folder")
    parser.add_argument("--steps", type=int, default=2000, help="training steps (2000)")
    parser.add_argument("--check", type=int, nargs="+", default=[300, 1000, 2000],
                        help="steps at which the guess is checked")
    parser.add_argument("--rays", type=int, default=4096, help="pixels per check (4096)")
    parser.add_argument("--guesses", type=float, nargs="+", default=[1e-4, 1e-5, 1e-6],
                        help="guess thresholds to compare")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override a fast-preset field (model.KEY for the field)")
    parser.add_argument("--threads", type=int, default=2, help="torch CPU threads (2)")
    parser.add_argument("--json", type=Path, help="also write the figures here")
    args = parser.parse_args(argv)
    if not (args.scene / "transforms.json").is_file():
        print(f"error: {args.scene} is not a scene folder (no transforms.json)", file=sys.stderr)
        return 2
    torch.set_num_threads(args.threads)
    config = replace(with_overrides(preset_config("fast"), args.set), iterations=args.steps)
    state = training_state(args.scene, config, torch.device("cpu"))
    refreshes: list[dict] = []
    if state.occupancy is not None:
        with_refresh_check(state.occupancy, refreshes)
    checks = []
    for i in range(args.steps + 1):
        if i in args.check:
            checks.append(guess_check(state, i, args.rays, args.guesses))
            print(f"  step {i}: {checks[-1]}", file=sys.stderr, flush=True)
        if i < args.steps:
            state.step(i)
    print(f"{args.scene.name}, fast{' ' + ' '.join(args.set) if args.set else ''}, "
          f"{args.steps} steps\n")
    rows = [[c["step"], c["rays_hit"], f"{c['heavy_share']:.3f}", *[
        f"{c[f'guess {g:g}']['kept_share']:.3f}, {c[f'guess {g:g}']['recall']:.4f}, "
        f"{c[f'guess {g:g}']['weight_dropped_share']:.1e}" for g in args.guesses]]
        for c in checks]
    print(markdown_table(
        "Samples guessed light, at each check",
        ["step", "rays hit", "heavy share",
         *(f"guess {g:g}: kept, recall, weight dropped" for g in args.guesses)], rows))
    if refreshes:
        shares = sorted(r["query_share"] for r in refreshes)
        print(f"\nblock-first refresh: {len(refreshes)} refreshes, "
              f"{sum(r['cells_differing'] for r in refreshes)} cells differing in all, SDF "
              f"queries {shares[0]:.2f}-{shares[-1]:.2f} (median "
              f"{shares[len(shares) // 2]:.2f}) of every cell's")
    if args.json:
        write_json_atomic(args.json, {"scene": args.scene.name, "settings": args.set,
                                      "checks": checks, "refreshes": refreshes})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
