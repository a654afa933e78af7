# SPDX-License-Identifier: GPL-3.0-or-later
"""A mesh file without UVs gives a map you can apply: the mesh is written beside the map with
the UV map the bake made (the input's format), and the summary names every file written."""
from __future__ import annotations

import json

import numpy as np

from conftest import DATA, run_hao
from hao_addon.core.bake.charts import overlapping_texels
from bake_helpers import load_image_rgba


def _obj_uv_triangles(path) -> np.ndarray:
    """(F, 3, 2) the UVs of an OBJ's triangles (faces fanned), as a bake reads them."""
    vt, faces = [], []
    for line in path.read_text().splitlines():
        if line.startswith("vt "):
            vt.append([float(x) for x in line.split()[1:3]])
        elif line.startswith("f "):
            corners = [int(c.split("/")[1]) - 1 for c in line.split()[1:]]
            faces += [[corners[0], corners[k], corners[k + 1]] for k in range(1, len(corners) - 1)]
    return np.asarray(vt)[np.asarray(faces)]


def test_an_obj_without_uvs_is_written_beside_its_map_with_the_new_uvs(tmp_path):
    out = tmp_path / "maps" / "suzanne_ao.png"
    done = run_hao(["bake", DATA / "suzanne.obj", "--size", "128", "--directions", "8", "--out", out,
                    "--json", tmp_path / "report.json"], cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    mesh = out.with_suffix(".obj")
    assert f"the mesh with the one baked into ('AO_UV') -> {mesh}" in done.stdout
    report = json.loads((tmp_path / "report.json").read_text())
    assert str(mesh) in report["outputs"] and str(out) in report["outputs"]
    uvs = _obj_uv_triangles(mesh)
    assert uvs.shape == (968, 3, 2)
    overlap, covered = overlapping_texels(uvs, 128)
    assert overlap == 0 and covered > 1000
    # The map is the bake of the mesh with these UVs: baked again from the file written (its
    # UVs as a user would apply them), the same map, texel for texel but at island edges.
    again = tmp_path / "again.png"
    done = run_hao(["bake", mesh, "--size", "128", "--directions", "8", "--out", again], cwd=tmp_path)
    assert done.returncode == 0 and "had no UV map" not in done.stdout, done.stderr
    # (The OBJ keeps six decimals of each UV: a texel centre on an island's edge may change sides.)
    from hao_addon.core.bake.uv_raster import interior_mask, texel_surface_samples
    face, _bary, hits = texel_surface_samples(uvs, 128)
    inside = interior_mask(face, hits, rings=1)
    diff = np.abs(load_image_rgba(out) - load_image_rgba(again))[..., 0][inside]
    # (Up to 4 16-bit steps: positions and normals pass through six decimals too.)
    assert inside.sum() > 1000 and diff.max() < 1e-4, (inside.sum(), diff.max())


def test_a_mesh_with_uvs_writes_no_mesh_file(tmp_path):
    out = tmp_path / "spot_ao.png"
    done = run_hao(["bake", DATA / "spot.obj", "--size", "64", "--directions", "4", "--out", out], cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["spot_ao.png"]
