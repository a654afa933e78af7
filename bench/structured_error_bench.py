# SPDX-License-Identifier: GPL-3.0-or-later
"""Structured error: what of a bake's error an eye sees as shapes, against an analytic truth.

    .venv/bin/python bench/structured_error_bench.py [--out bench/results] [--sizes 1024] [--directions 64 256 1024]

Scene: an 8-unit floor under a ball of radius 0.5 resting on it (64 x 32 UV sphere), the
floor baked; truth 1 - (R / D)^3 (core/scenes.py). Measured where the ball's shadow reaches
(the exact AO below 0.99): the RMSE, and the RMSE after an 8 x 8 box filter (white noise
shrinks 8x under it, the rings and polygons of hard shadows do not).

- bakes: the gather at Texel Sets 2 x 2 (core/bake/interleave.py) and, in the same run, at
  one set for every texel (the default, and the revision before), in-process seconds (one
  warm-up bake first).
- model: the same scene baked by a numpy model of the gather (exact ray-sphere visibility,
  the cosine-weighted estimator, two replicates), 3 seeds, for the direction set designs
  considered: one set for all texels; four independently rotated sets; four classes of one
  lattice for each azimuth step (core/directions.CLASS_LATTICE_STEP); 1024 directions for all.

Writes structured_error_bench.json and structured_error_bench.png (the error maps of the
shadow, x20) into the output folder.
"""
from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from hao_addon.core import scenes  # noqa: E402
from hao_addon.core.directions import fibonacci_sphere, lattice_sphere, random_rotation  # noqa: E402

RADIUS = 0.5
FLOOR = 8.0
BOX = 8
MODEL_SIZE = 1024
MODEL_CROP = 320  # texels each side of the centre the model bakes (the shadow lies within 2.3 units)


def exact_floor(size: int) -> np.ndarray:
    u = ((np.arange(size) + 0.5) / size - 0.5) * FLOOR
    x, y = np.meshgrid(u, u)
    return 1.0 - (RADIUS / np.sqrt(x * x + y * y + RADIUS * RADIUS)) ** 3


def errors(ao: np.ndarray, exact: np.ndarray) -> dict:
    """RMSE and box-filtered RMSE where the shadow reaches."""
    error, size = ao - exact, len(ao)
    blocks = size // BOX
    boxed = error[:blocks * BOX, :blocks * BOX].reshape(blocks, BOX, blocks, BOX).mean(axis=(1, 3))
    shadow = exact < 0.99
    boxed_shadow = exact[:blocks * BOX, :blocks * BOX].reshape(blocks, BOX, blocks, BOX).mean(axis=(1, 3)) < 0.99
    return {"rmse": float(np.sqrt((error[shadow] ** 2).mean())),
            "boxed_rmse": float(np.sqrt((boxed[boxed_shadow] ** 2).mean()))}


def gpu_bakes(sizes: list[int], directions: list[int]) -> tuple[list[dict], dict]:
    from hao_addon.bake import bake
    from hao_addon.core.bake.interleave import CLASSES
    from hao_addon.core.bake.settings import BakeSettings
    from hao_addon.gpu.context import ensure_gpu_context
    ensure_gpu_context()
    floor = scenes.grid_plane(FLOOR, 1, name="floor")
    ball = scenes.uv_sphere(RADIUS, (0.0, 0.0, RADIUS), 64, 32, name="ball")
    bake(floor, [ball], BakeSettings(size=64, directions=16), use_cache=False)  # warm-up: shaders
    rows, maps = [], {}
    for size in sizes:
        exact = exact_floor(size)
        for count in directions:
            for label, sets in (("texel sets 2 x 2", CLASSES), ("one set (the default)", 1)):
                t0 = time.perf_counter()
                result = bake(floor, [ball], BakeSettings(size=size, directions=count, texel_sets=sets),
                              use_cache=False)
                seconds = time.perf_counter() - t0
                rows.append({"size": size, "directions": count, "variant": label, "texel_sets": sets,
                             "seconds": round(seconds, 3), **errors(result.ao, exact)})
                print(rows[-1], flush=True)
                if size == sizes[0] and count == 256:
                    maps[label] = result.ao - exact
    return rows, maps


def _model_sums(points: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """(n, 2) sum of w V and of w over directions above the floor (exact ray-sphere tests)."""
    d = directions[directions[:, 2] > 0.0]
    w = d[:, 2]
    oc = points - np.array([0.0, 0.0, RADIUS])
    b = oc @ d.T
    c = (oc ** 2).sum(axis=1)[:, None] - RADIUS * RADIUS
    hit = (b * b - c > 0.0) & (b < 0.0)
    return np.stack([(~hit * w).sum(axis=1), np.full(len(points), w.sum())], axis=1)


def _design_sets(design: str, count: int, seed: int) -> list[list[np.ndarray]]:
    """[class][replicate] (n, 3) directions of a design, count per texel."""
    half = count // 2
    if design == "one set":
        return [[fibonacci_sphere(half) @ random_rotation(seed, r).T for r in range(2)]]
    if design == "four rotated sets":
        return [[fibonacci_sphere(half) @ random_rotation(seed, r + 2 * k).T for r in range(2)] for k in range(4)]
    step = float(design.split()[-1])
    lattices = [lattice_sphere(4 * half, step) @ random_rotation(seed, r).T for r in range(2)]
    return [[lattice[k::4] for lattice in lattices] for k in range(4)]


def model(count: int, design: str, seed: int) -> dict:
    exact = exact_floor(MODEL_SIZE)
    crop = slice(MODEL_SIZE // 2 - MODEL_CROP, MODEL_SIZE // 2 + MODEL_CROP)
    exact = exact[crop, crop]
    u = ((np.arange(MODEL_SIZE) + 0.5) / MODEL_SIZE - 0.5)[crop] * FLOOR
    x, y = np.meshgrid(u, u)
    points = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1)
    sets = _design_sets(design, count, seed)
    side = int(np.sqrt(len(sets)))
    iy, ix = np.divmod(np.arange(len(points)), len(u))
    texel_class = (ix % side) + side * (iy % side)
    ao = np.zeros(len(points))
    for k, replicates in enumerate(sets):
        at = texel_class == k
        sums = sum(_model_sums(points[at], directions) for directions in replicates)
        ao[at] = sums[:, 0] / sums[:, 1]
    return errors(ao.reshape(exact.shape), exact)


def model_rows() -> list[dict]:
    from hao_addon.core.directions import CLASS_LATTICE_STEP
    golden = (np.sqrt(5.0) - 1.0) / 2.0
    designs = [("one set", 256), ("one set", 1024), ("four rotated sets", 256)]
    designs += [(f"four classes of one lattice, step {(golden + j) / 4:.4f}", 256) for j in range(4)]
    rows = []
    for design, count in designs:
        seeds = [model(count, design, seed) for seed in range(3)]
        rows.append({"design": design, "directions": count, "chosen": design.endswith(f"{CLASS_LATTICE_STEP[4]:.4f}"),
                     "rmse": float(np.mean([s["rmse"] for s in seeds])),
                     "boxed_rmse": float(np.mean([s["boxed_rmse"] for s in seeds]))})
        print(rows[-1], flush=True)
    return rows


def plot(maps: dict, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(maps), figsize=(5 * len(maps), 5))
    for ax, (label, error) in zip(np.atleast_1d(axes), maps.items()):
        size = len(error)
        crop = error[size // 4: 3 * size // 4, size // 4: 3 * size // 4]
        ax.imshow(np.clip(0.5 + 20.0 * crop, 0.0, 1.0), cmap="gray", vmin=0.0, vmax=1.0, origin="lower")
        ax.set_title(f"{label}: error x20")
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(out / "structured_error_bench.png", dpi=80)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "results")
    parser.add_argument("--sizes", type=int, nargs="+", default=[1024])
    parser.add_argument("--directions", type=int, nargs="+", default=[64, 256, 1024])
    parser.add_argument("--no-model", action="store_true", help="only the GPU bakes")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    bakes, maps = gpu_bakes(args.sizes, args.directions)
    result = {"machine": platform.machine(), "python": platform.python_version(), "box": BOX,
              "bakes": bakes, "model": [] if args.no_model else model_rows()}
    (args.out / "structured_error_bench.json").write_text(json.dumps(result, indent=1) + "\n")
    if maps:
        plot(maps, args.out)


if __name__ == "__main__":
    main()
