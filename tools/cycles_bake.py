# SPDX-License-Identifier: GPL-3.0-or-later
"""Cycles' own AO bake of a Blender object: the truth the benchmark and the test truths
(tests/scripts/make_cycles_truths.py) measure HAO against. CPU, no adaptive sampling (samples
mean samples), no denoising, AO distance 1e6 (unlimited), margin 0, the object's own shading;
with sources, Selected to Active from them (the low-poly hidden from the render, as Blender
does it)."""
from __future__ import annotations

import bpy
import numpy as np

from timing import median_seconds


def cycles_ao_bake(obj: "bpy.types.Object", size: int, samples: list[int], seed: int = 0, sources: tuple = (),
                   cage_extrusion: float = 0.0, max_ray_distance: float = 0.0, warm_up: bool = False,
                   log: bool = False, repeat_under_s: float = 0.0) -> list[tuple[int, float, np.ndarray]]:
    """[(samples, seconds, ao (size, size) float32, row 0 at v = 0)] for each sample count.
    warm_up: one untimed 1-sample bake first (the session's one-off set-up); bakes faster
    than repeat_under_s seconds are repeated and their median time kept (timing.py)."""
    img = bpy.data.images.new(f"cycles_ao_{seed}", size, size, float_buffer=True)
    img.colorspace_settings.name = 'Non-Color'
    mat = bpy.data.materials.new("cycles_bake")
    if mat.node_tree is None:
        mat.use_nodes = True
    tex = mat.node_tree.nodes.new('ShaderNodeTexImage')
    tex.image = img
    mat.node_tree.nodes.active = tex
    obj.data.materials.clear()
    obj.data.materials.append(mat)
    scene = bpy.context.scene
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.seed = seed
    scene.world = bpy.data.worlds.new("cycles_bake")
    scene.world.light_settings.distance = 1e6
    for other in scene.objects:
        other.select_set(False)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    for source in sources:
        source.select_set(True)

    def run(spp: int, repeat_under: float) -> float:
        scene.cycles.samples = spp
        return median_seconds(lambda: bpy.ops.object.bake(
            type='AO', use_clear=True, margin=0, use_selected_to_active=bool(sources), cage_extrusion=cage_extrusion,
            max_ray_distance=max_ray_distance), repeat_under)[0]

    if warm_up:
        run(1, 0.0)
    out = []
    for spp in samples:
        seconds = run(spp, repeat_under_s)
        px = np.empty(size * size * 4, np.float32)
        img.pixels.foreach_get(px)
        out.append((spp, seconds, px.reshape(size, size, 4)[..., 0].copy()))
        if log:
            print(f"  cycles {spp:5d} spp: {seconds:7.2f} s", flush=True)
    return out
