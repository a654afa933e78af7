# SPDX-License-Identifier: GPL-3.0-or-later
"""List forms benchmark (issue 41): the GPU Selected-to-Active ray cast with its lists as list
textures (every release) against storage buffers (Blender 5.3, gpu/list_inputs.py), in one
run, with the same rays.

    .venv/bin/python bench/list_forms_bench.py [--out bench/results] [--rays N]

Rays: N (default 600,000, about the bunny pair's 601k at 1024^2) towards random points of the
Stanford bunny's 69,451 triangles from 1 % of its size out, jittered up to grazing (as
tests/test_ray_cast.py casts). Each form casts them REPEATS times, the forms interleaved, after
one untimed cast each (shader compilation); the median is kept. Hits must be identical.
Writes list_forms_bench.json.
"""
from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import bpy  # noqa: E402

from hao_addon.bakers import ray_caster_for  # noqa: E402
from hao_addon.core.objfile import read_obj  # noqa: E402
from hao_addon.core.steps import drain  # noqa: E402
from hao_addon.gpu import list_inputs  # noqa: E402
from test_ray_cast import surface_rays  # noqa: E402

REPEATS = 5
BUNNY = ROOT / "bench" / "data" / "stanford-bunny.obj"


def cast_seconds(form: str, origins, dirs, tri) -> tuple[float, tuple]:
    with list_inputs.using_form(form):
        t0 = time.perf_counter()
        hits = drain(ray_caster_for("gpu")(origins, dirs, tri, 0.0))
        return time.perf_counter() - t0, hits


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    ap.add_argument("--rays", type=int, default=600_000)
    args = ap.parse_args()
    forms = list_inputs.available_forms()
    if len(forms) < 2:
        print("list_forms_bench: needs Blender 5.3 or newer (storage buffers)", file=sys.stderr)
        return 2
    v, t, _uv, _tu = read_obj(BUNNY)
    tri = v[t]
    origins, dirs = surface_rays(tri, args.rays, 0.01 * float(np.ptp(v, axis=0).max()))
    first = {form: cast_seconds(form, origins, dirs, tri)[1] for form in forms}  # compile, warm
    same = all(np.array_equal(first[f][0], first[forms[0]][0]) and np.array_equal(first[f][1], first[forms[0]][1])
               for f in forms)
    times = {form: [] for form in forms}
    for _ in range(REPEATS):
        for form in forms:
            times[form].append(cast_seconds(form, origins, dirs, tri)[0])
    seconds = {form: round(statistics.median(times[form]), 4) for form in forms}
    result = {"machine": {"platform": platform.platform(), "python": platform.python_version(),
                          "blender": bpy.app.version_string},
              "mesh": "stanford-bunny", "triangles": len(tri), "rays": args.rays, "repeats": REPEATS,
              "hits_identical": bool(same), "seconds": seconds,
              "runs": {form: [round(s, 4) for s in times[form]] for form in forms},
              "speedup_storage_over_textures": round(seconds["textures"] / seconds["storage"], 3)}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "list_forms_bench.json").write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps(result, indent=2))
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
