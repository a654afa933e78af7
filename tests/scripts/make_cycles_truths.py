# SPDX-License-Identifier: GPL-3.0-or-later
"""Cycles' own AO bakes of tests/shading_scenes.py's cases: the truths of
tests/test_shading_normals.py (Cycles CPU, 1024 samples, no adaptive sampling, no denoising,
AO distance 1e6 = unlimited, margin 0, the mesh's own shading).

    .venv/bin/python tests/scripts/make_cycles_truths.py [case ...]

Writes tests/data/cycles_<case>.npz: ao and ao_seed1 (256, 256) float16 (row 0 at v = 0),
two bakes with Cycles seeds 0 and 1, whose difference measures Cycles' own noise; uvs
(F, 3, 2) float32 (the layout baked); samples; blender (version string). The
Selected-to-Active cases (shading_scenes.HIGH_TO_LOW) also store the low-poly they made:
low_vertices (V, 3) float64 and low_triangles (F, 3) int32.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT), str(ROOT / "tests"), str(ROOT / "tools")]

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import shading_scenes as cases  # noqa: E402
from cycles_bake import cycles_ao_bake  # noqa: E402


def cycles_ao(obj: bpy.types.Object, size: int, samples: int, seed: int = 0, sources: tuple = (),
              cage_extrusion: float = 0.0, max_ray_distance: float = 0.0) -> np.ndarray:
    """Cycles' AO bake of obj (tools/cycles_bake.py); with sources, Selected to Active."""
    return cycles_ao_bake(obj, size, [samples], seed, sources, cage_extrusion, max_ray_distance)[0][2]


def high_to_low_truth(name: str) -> None:
    """Cycles' Selected to Active bake of the case's pair; the low-poly is stored with it."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    low = cases.decimated_low_poly(name)
    low_obj, high = cases.build_high_to_low(name, low)
    _path, _ratio, extrusion, max_ray = cases.HIGH_TO_LOW[name]
    t = time.perf_counter()
    runs = [cycles_ao(low_obj, cases.TRUTH_SIZE, cases.TRUTH_SPP, seed, (high,), extrusion, max_ray) for seed in (0, 1)]
    np.savez_compressed(cases.truth_path(name), ao=runs[0].astype(np.float16), ao_seed1=runs[1].astype(np.float16),
                        uvs=low[2].astype(np.float32), low_vertices=low[0],
                        low_triangles=low[1].astype(np.int32), samples=cases.TRUTH_SPP, blender=bpy.app.version_string)
    print(f"{name}: {len(low[1])} low-poly faces, {time.perf_counter() - t:.1f} s", flush=True)


def main(names: list[str]) -> int:
    for name in names or [*cases.CASES, *cases.HIGH_TO_LOW]:
        if name in cases.HIGH_TO_LOW:
            high_to_low_truth(name)
            continue
        bpy.ops.wm.read_factory_settings(use_empty=True)
        uvs = cases.corner_uvs(name)
        obj = cases.build_object(name, uvs)
        t = time.perf_counter()
        runs = [cycles_ao(obj, cases.TRUTH_SIZE, cases.TRUTH_SPP, seed) for seed in (0, 1)]
        np.savez_compressed(cases.truth_path(name), ao=runs[0].astype(np.float16), ao_seed1=runs[1].astype(np.float16),
                            uvs=uvs.astype(np.float32), samples=cases.TRUTH_SPP, blender=bpy.app.version_string)
        print(f"{name}: {obj.data.polygons.__len__()} faces, {time.perf_counter() - t:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
