# SPDX-License-Identifier: GPL-3.0-or-later
"""The Selected-to-Active projection's ray cast on the GPU: gpu_shaders/bake_ray_cast.comp
walks core/bake/ray_grid.py's uniform grid. The twin of core/bake/projection.project_steps
(mathutils' BVH on the CPU), same signature and results; bakers.ray_caster_for() picks.

Why: the CPU cast runs one Python call per ray (about 2.5 us each, 1.5 s of the bunny pair's
601k rays, a third of its 64-direction bake); here the grid is built by numpy and the rays
are one compute dispatch per RAYS_PER_DISPATCH of them, each a progress step.
"""
from __future__ import annotations

from typing import Generator

import gpu
import numpy as np

from ..core.bake.projection import barycentric_from_uv
from ..core.bake.ray_grid import UniformGrid, build_grid
from ..core.errors import BakeInputError
from . import list_inputs, util
from .shaders import cached_shader, glsl_source, shader_variants

LIST_WIDTH = util.LIST_WIDTH  # the list textures' rows; the compute grid is LIST_WIDTH / GROUP_SIZE wide
GROUP_SIZE = 64
# Rays per dispatch, a progress (and cancel) step: 32 rows, about 0.1 s on llvmpipe.
RAYS_PER_DISPATCH = 32 * LIST_WIDTH
# Barycentric slack at triangle edges (cell units are about a triangle's size): a ray
# through a shared edge or vertex hits one of the triangles there instead of slipping
# between them through float32 rounding.
EDGE_SLACK = 1e-6


# The pass's lists: (name, kind) in their slot order; hit_out is written.
LIST_INPUTS = (("tri_corners", "VEC4"), ("cell_start", "UINT"), ("cell_triangles", "UINT"),
               ("ray_origin", "VEC4"), ("ray_direction", "VEC4"))


def _ray_cast_info(form_name: str) -> "gpu.types.GPUShaderCreateInfo":
    form = list_inputs.FORMS[form_name]
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(GROUP_SIZE, 1, 1)
    info.define("LIST_WIDTH", str(LIST_WIDTH))
    info.define("EDGE_SLACK", repr(EDGE_SLACK))
    info.push_constant('INT', "first_ray")
    info.push_constant('INT', "ray_end")
    info.push_constant('IVEC3', "dims")
    info.push_constant('FLOAT', "reach")
    for slot, (name, kind) in enumerate(LIST_INPUTS):
        form.declare(info, slot, name, kind)
    form.declare(info, form.output_slot(len(LIST_INPUTS)), "hit_out", "VEC4", write=True)
    info.compute_source(form.prelude() + glsl_source("bake_ray_cast.comp"))
    return info


@shader_variants(valid=lambda arguments: arguments["form_name"] in list_inputs.available_forms(),
                 form_name=list_inputs.FORM_NAMES)
def ray_cast_shader(form_name: str = "textures") -> "gpu.types.GPUShader":
    return cached_shader(("bake_ray_cast", form_name), lambda: _ray_cast_info(form_name))


def check_capacity(form, count: int) -> None:
    """Refuse, with one message, a list longer than the form can hold."""
    if count > form.capacity():
        raise BakeInputError(f"the Selected-to-Active projection needs {count} list entries, above this "
                             f"GPU's limit for {form.name}: use a smaller map or fewer high-poly triangles")


class GpuRayCast(util.GPUPass):
    """Owns the grid's and one batch of rays' lists (in form: gpu/list_inputs.py)."""

    def __init__(self, grid: UniformGrid, origins: np.ndarray, directions: np.ndarray, form=None) -> None:
        super().__init__()
        self.form = form or list_inputs.chosen_form()
        tri = grid.local_triangles.astype(np.float64)
        corners = np.stack([tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]], axis=1)  # v0, e1, e2
        quads = np.zeros((len(tri) * 3, 4), np.float32)
        quads[:, :3] = corners.reshape(-1, 3)
        rays = np.zeros((len(origins), 4))
        rays[:, :3] = grid.to_local(origins)
        aims = np.zeros((len(origins), 4))
        aims[:, :3] = directions
        values = {"tri_corners": quads, "cell_start": grid.cell_start, "cell_triangles": grid.triangle_index,
                  "ray_origin": rays, "ray_direction": aims}
        for name, _kind in LIST_INPUTS:
            check_capacity(self.form, len(values[name]))
        self.lists = {name: self.form.upload(values[name], kind) for name, kind in LIST_INPUTS}
        self.hit = self.form.output(len(origins))
        self.grid, self.ray_count = grid, len(origins)

    def dispatch(self, first: int, end: int, reach: float) -> None:
        """Cast rays first..end (their entries of the lists; invocations past end return)."""
        shader = ray_cast_shader(self.form.name)
        shader.bind()
        self.form.bind(shader, self.lists, {"hit_out": self.hit},
                       ints={"first_ray": first, "ray_end": end, "dims": tuple(int(d) for d in self.grid.dims)},
                       floats={"reach": reach})
        rows = -(-(end - first) // LIST_WIDTH)
        gpu.compute.dispatch(shader, LIST_WIDTH // GROUP_SIZE, rows, 1)
        gpu.shader.unbind()

    def hits(self) -> tuple[np.ndarray, np.ndarray]:
        """(face (m,) int64, -1 a miss; uv (m, 2) of the hit in that face) of every ray (the
        shader's t, hit_out.y, is for debugging: the point is the face's at uv)."""
        out = self.form.read(self.hit, self.ray_count)
        face = out[:, 0].copy().view(np.int32).astype(np.int64)
        return face, out[:, 2:].astype(np.float64)

    def _release(self) -> None:
        self.lists = {}
        self.hit = None


def project_steps(origins: np.ndarray, directions: np.ndarray, triangles: np.ndarray, max_ray_distance: float
                  ) -> Generator[float, None, tuple[np.ndarray, np.ndarray]]:
    """core/bake/projection.project_steps on the GPU: the first hit of each ray (origins,
    unit directions (m, 3) world) on triangles (Fs, 3, 3) (either side, within
    max_ray_distance, 0 = no limit); yields the fraction cast after each dispatch. Returns
    (face (m,) int64, -1 for a miss or a zero direction; bary (m, 3) float64)."""
    if len(origins) == 0:
        return np.zeros(0, np.int64), np.zeros((0, 3))
    grid = build_grid(triangles)
    reach = max_ray_distance / grid.cell if max_ray_distance > 0.0 else 3.0e38
    cast = GpuRayCast(grid, origins, directions)  # its lists in list_inputs.chosen_form()
    try:
        with util.scoped_state():
            for first in range(0, len(origins), RAYS_PER_DISPATCH):
                end = min(first + RAYS_PER_DISPATCH, len(origins))
                cast.dispatch(first, end, reach)
                yield end / len(origins)
        face, uv = cast.hits()
    finally:
        cast.free()
    bary = np.zeros((len(origins), 3))
    hit = face >= 0
    bary[hit] = barycentric_from_uv(uv[hit])
    return face, bary


def first_hit_distances(origins: np.ndarray, directions: np.ndarray, triangles: np.ndarray, reach: float
                        ) -> np.ndarray:
    """The distance to each ray's first hit (origins, unit directions (m, 3)) on triangles
    (F, 3, 3), either side, within reach; inf for none: mathutils' BVH ray cast of
    core/reference.first_hits for a batch of rays at once (core/bake/reference_baker.py's
    run_directions: a contact's or a floor check's rays along every direction, one dispatch
    per RAYS_PER_DISPATCH of them and one read-back instead of a Python call per ray)."""
    distances = np.full(len(origins), np.inf)
    if len(origins) == 0 or len(triangles) == 0:
        return distances
    grid = build_grid(np.asarray(triangles, np.float64))
    cast = GpuRayCast(grid, origins, directions)
    try:
        with util.scoped_state():
            for first in range(0, len(origins), RAYS_PER_DISPATCH):
                cast.dispatch(first, min(first + RAYS_PER_DISPATCH, len(origins)), min(reach / grid.cell, 3.0e38))
        out = cast.form.read(cast.hit, cast.ray_count)
    finally:
        cast.free()
    hit = out[:, 0].copy().view(np.int32) >= 0
    distances[hit] = out[hit, 1].astype(np.float64) * grid.cell
    return distances
