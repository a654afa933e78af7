# SPDX-License-Identifier: GPL-3.0-or-later
"""Auto-unwrap benchmark: the atlas a mesh without UVs gets, against the xatlas atlas it got
before (xatlas' own charts and packing) and Blender's Smart UV Project, in one run.

    .venv/bin/python bench/unwrap_bench.py [--out bench/results] [--sizes 256 1024]

Mesh: the Stanford bunny (69,451 triangles, bench/data). Per atlas and texture size:
- seconds: wall time of the unwrap as a bake runs it (ours: the child process, its start
  included; xatlas: in-process; Smart UV Project: the operator, edit mode excluded);
- utilisation: texel coverage, texel centres inside a triangle / all texels of the texture
  (core/bake/uv_raster.py), the same measure for all three;
- overlapping texels: texel centres inside two triangles at twice the size;
- clear texels: the fewest empty texels between two charts' covered texels (a bake's tent
  and bilinear lookups need 2); xatlas before packed into an atlas of its own size that
  the texture then squeezed;
- seam length: 3D length of the edges cut into two charts, in bounding-box units;
- density p05: the texel density (UV area / surface area, relative to the mesh's mean) that
  5 % of the surface falls below: how unevenly the texels are spread.
Meshes as Blender users have them, without UVs: Suzanne (quads), Suzanne
subdivided once, a cube subdivided once, a 24-sided cylinder (n-gon caps), CesiumMan and
fandisk: the unwrap as a bake runs it, charts of whole polygons, against the same unwrap
with each triangle on its own (before), each written into Blender's per-corner UV map and
measured there: seconds, coverage, and texel centres inside two triangles (overlapping).
Writes unwrap_bench.json and unwrap_bench.png into the output folder.
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

from hao_addon.core.bake.unwrap import DEFAULT_PADDING, run_unwrap, unit_copy  # noqa: E402
from hao_addon.core.bake.uv_raster import texel_surface_samples  # noqa: E402
from hao_addon.core.objfile import read_obj  # noqa: E402

BUNNY = ROOT / "bench" / "data" / "stanford-bunny.obj"
BEFORE_PADDING = 4  # xatlas' padding as the unwrap used it before


def xatlas_own(unit: np.ndarray, triangles: np.ndarray, size: int) -> tuple[np.ndarray, float]:
    """The atlas before: xatlas' chart computation and packing (its default options); returns
    the UVs and the width of the atlas xatlas packed."""
    import xatlas
    atlas = xatlas.Atlas()
    atlas.add_mesh(unit, triangles.astype(np.uint32))
    pack = xatlas.PackOptions()
    pack.resolution, pack.padding, pack.bilinear = size, BEFORE_PADDING, True
    atlas.generate(xatlas.ChartOptions(), pack)
    _vm, indices, uvs = atlas[0]
    return np.asarray(uvs, np.float64)[np.asarray(indices)], float(atlas.width)


def smart_uv_project(vertices: np.ndarray, triangles: np.ndarray, size: int) -> tuple[np.ndarray, float]:
    """Blender's Smart UV Project (angle limit 66 degrees, a margin of two texels); returns the
    UVs and the operator's seconds."""
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    mesh = bpy.data.meshes.new("bunny")
    mesh.from_pydata(vertices.tolist(), [], triangles.tolist())
    obj = bpy.data.objects.new("bunny", mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.select_all(action='SELECT')
    start = time.perf_counter()
    bpy.ops.uv.smart_project(angle_limit=np.radians(66.0), island_margin=2.0 / size)
    seconds = time.perf_counter() - start
    bpy.ops.object.mode_set(mode='OBJECT')
    loops = np.empty(len(mesh.loops) * 2, np.float32)
    mesh.uv_layers.active.data.foreach_get("uv", loops)
    return loops.reshape(-1, 3, 2).astype(np.float64), seconds


def clear_texels(face: np.ndarray, chart: np.ndarray, most: int = 8) -> int:
    """The fewest empty texels between texels of two charts (up to `most`); face: (S, S)
    face per texel centre (-1: none), chart: (F,) chart of each face."""
    size = face.shape[0]
    label = np.where(face >= 0, chart[np.maximum(face, 0)], -1)
    for reach in range(1, most + 1):
        padded = np.pad(label, reach, constant_values=-1)
        for dy in range(-reach, reach + 1):
            for dx in range(-reach, reach + 1):
                other = padded[reach + dy:reach + dy + size, reach + dx:reach + dx + size]
                if ((label >= 0) & (other >= 0) & (other != label)).any():
                    return reach - 1
    return most


def uv_charts(triangles: np.ndarray, uvs: np.ndarray) -> np.ndarray:
    """(F,) chart of each face: faces joined where they share an edge with the same UVs."""
    from hao_addon.core.bake.charts import adjacent_faces, connected_components
    key = np.round(uvs * 2**20).astype(np.int64)  # (F, 3, 2): a corner's UV, exactly
    corner = np.concatenate([triangles[..., None].astype(np.int64), key], axis=2).reshape(-1, 3)
    uv_vertex = np.unique(corner, axis=0, return_inverse=True)[1].reshape(-1, 3)
    return connected_components(len(triangles), adjacent_faces(uv_vertex))


def uv_metrics(unit: np.ndarray, triangles: np.ndarray, uvs: np.ndarray, size: int) -> dict:
    face, _bary, hits = texel_surface_samples(uvs, size)
    charts = uv_charts(triangles, uvs)
    _face2, _bary2, hits2 = texel_surface_samples(uvs, 2 * size)
    p = unit[triangles].astype(np.float64)
    area3 = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    e1, e2 = uvs[:, 1] - uvs[:, 0], uvs[:, 2] - uvs[:, 0]
    area2 = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e2[:, 0] * e1[:, 1])
    density = (area2 / area2.sum()) / (area3 / area3.sum())
    order = np.argsort(density)
    weight = np.cumsum(area3[order]) / area3.sum()
    return {"coverage": float((hits > 0).mean()), "overlapping_texels": int((hits2 > 1).sum()),
            "clear_texels": clear_texels(face, charts), "charts": int(charts.max() + 1),
            "seam_length": seam_length(unit, triangles, uvs),
            "density_p05": float(density[order][np.searchsorted(weight, 0.05)])}


def seam_length(unit: np.ndarray, triangles: np.ndarray, uvs: np.ndarray) -> float:
    """3D length of the edges whose two faces give an endpoint different UVs."""
    corner_a = np.concatenate([np.full(len(triangles), k) for k in range(3)])
    faces = np.tile(np.arange(len(triangles)), 3)
    ends = np.stack([triangles[faces, corner_a], triangles[faces, (corner_a + 1) % 3]], axis=1)
    end_uv = np.stack([uvs[faces, corner_a], uvs[faces, (corner_a + 1) % 3]], axis=1)
    flip = ends[:, 0] > ends[:, 1]
    ends[flip], end_uv[flip] = ends[flip][:, ::-1], end_uv[flip][:, ::-1]
    key = ends[:, 0].astype(np.int64) * (int(triangles.max()) + 1) + ends[:, 1]
    order = np.argsort(key, kind="stable")
    same = np.flatnonzero(key[order][1:] == key[order][:-1])
    i, j = order[same], order[same + 1]
    cut = np.abs(end_uv[i] - end_uv[j]).max(axis=(1, 2)) > 1e-6
    return float(np.linalg.norm(unit[ends[i[cut], 0]] - unit[ends[i[cut], 1]], axis=1).sum())


def _polygon_mesh(name: str):
    """A Blender mesh object without UVs, by name (see the module's docstring)."""
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    data = ROOT / "tests" / "data"
    if name.startswith("suzanne"):
        bpy.ops.mesh.primitive_monkey_add()
    elif name == "cube-subdivided":
        bpy.ops.mesh.primitive_cube_add()
    elif name == "cylinder-ngons":
        bpy.ops.mesh.primitive_cylinder_add(vertices=24)
    elif name == "cesium-man":
        bpy.ops.import_scene.gltf(filepath=str(data / "CesiumMan.glb"))
    else:
        bpy.ops.wm.obj_import(filepath=str(data / "fandisk.obj"))
    obj = max((o for o in bpy.data.objects if o.type == 'MESH'), key=lambda o: len(o.data.polygons))
    levels = {"suzanne-subdivided": 1, "cube-subdivided": 1}.get(name, 0)
    if levels:
        modifier = obj.modifiers.new("Subdivision", 'SUBSURF')
        modifier.levels = levels
        with bpy.context.temp_override(object=obj, active_object=obj):
            bpy.ops.object.modifier_apply(modifier=modifier.name)
    while obj.data.uv_layers:
        obj.data.uv_layers.remove(obj.data.uv_layers[0])
    return obj


POLYGON_MESHES = ("suzanne-quads", "suzanne-subdivided", "cube-subdivided", "cylinder-ngons", "cesium-man", "fandisk")


def polygon_rows(sizes: list[int]) -> list[dict]:
    """Per mesh and size: the unwrap of whole polygons and of single triangles (before),
    measured as written into the mesh's UV map."""
    from hao_addon.blender.mesh_data import add_uv_layer, base_mesh_triangles, written_triangle_uvs
    from hao_addon.core.bake.charts import overlapping_texels
    rows = []
    for name in POLYGON_MESHES:
        obj = _polygon_mesh(name)
        positions, triangles, loops, polygons = base_mesh_triangles(obj)
        for size in sizes:
            for charts, given in (("whole polygons", polygons), ("single triangles (before)", None)):
                start = time.perf_counter()
                uvs = run_unwrap(positions, triangles, size, polygons=given)
                seconds = time.perf_counter() - start
                layer = add_uv_layer(obj.data, "bench", loops, uvs)
                written = written_triangle_uvs(obj.data, layer, loops)
                obj.data.uv_layers.remove(obj.data.uv_layers[layer])
                overlap, covered = overlapping_texels(written, size)
                rows.append({"mesh": name, "polygons": len(obj.data.polygons), "triangles": int(len(triangles)),
                             "charts": charts, "size": size, "seconds": seconds,
                             "coverage": covered / size ** 2, "overlapping_texels": overlap,
                             "overlap_fraction": overlap / max(covered, 1)})
                print(json.dumps(rows[-1]), flush=True)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "bench" / "results"))
    parser.add_argument("--sizes", type=int, nargs="+", default=[256, 1024])
    parser.add_argument("--polygons-only", action="store_true",
                        help="only the meshes of polygons (the bunny's rows are kept from the last run)")
    args = parser.parse_args()
    out = Path(args.out)
    if args.polygons_only:
        result = json.loads((out / "unwrap_bench.json").read_text())
        result["polygon_meshes"] = polygon_rows(args.sizes)
        (out / "unwrap_bench.json").write_text(json.dumps(result, indent=1) + "\n")
        return
    vertices, triangles, _uv, _tuv = read_obj(BUNNY)
    triangles = np.asarray(triangles, np.int64)
    unit = unit_copy(vertices, triangles)
    rows = []
    for size in args.sizes:
        start = time.perf_counter()
        ours = run_unwrap(vertices, triangles, size)
        rows.append({"atlas": "HAO (planar charts, xatlas packing)", "size": size,
                     "seconds": time.perf_counter() - start, **uv_metrics(unit, triangles, ours, size)})
        start = time.perf_counter()
        before, atlas_width = xatlas_own(unit, triangles, size)
        rows.append({"atlas": "xatlas (its charts and packing; before)", "size": size,
                     "seconds": time.perf_counter() - start, "xatlas_atlas_width": atlas_width,
                     **uv_metrics(unit, triangles, before, size)})
        smart, seconds = smart_uv_project(unit.astype(np.float64), triangles, size)
        rows.append({"atlas": "Blender Smart UV Project", "size": size, "seconds": seconds,
                     **uv_metrics(unit, triangles, smart, size)})
        print(json.dumps(rows[-3:], indent=1), flush=True)
    import bpy
    result = {"mesh": "stanford-bunny.obj", "triangles": int(len(triangles)), "padding_texels": DEFAULT_PADDING,
              "machine": {"cpu_count": __import__("os").cpu_count(), "python": platform.python_version(),
                          "blender": bpy.app.version_string},
              "rows": rows, "polygon_meshes": polygon_rows(args.sizes)}
    out.mkdir(parents=True, exist_ok=True)
    (out / "unwrap_bench.json").write_text(json.dumps(result, indent=1) + "\n")
    plot(result, out / "unwrap_bench.png")


def plot(result: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for atlas, marker in zip(dict.fromkeys(r["atlas"] for r in result["rows"]), "os^"):
        rows = [r for r in result["rows"] if r["atlas"] == atlas]
        ax.plot([r["seconds"] for r in rows], [r["coverage"] for r in rows], marker, label=atlas)
        for r in rows:
            ax.annotate(f"{r['size']}", (r["seconds"], r["coverage"]), textcoords="offset points", xytext=(5, 3))
    ax.set_xscale("log")
    ax.set_xlabel("unwrap time (s, log)")
    ax.set_ylabel("texel coverage (texel centres inside a chart)")
    ax.set_title(f"Auto-unwrap of the bunny ({result['triangles']:,} triangles), by texture size")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
