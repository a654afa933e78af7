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

from .. import compat
from ..core.bake.projection import barycentric_from_uv
from ..core.bake.ray_grid import UniformGrid, build_grid
from ..core.errors import BakeInputError
from . import util
from .shaders import cached_shader, glsl_source, shader_variants

LIST_WIDTH = util.LIST_WIDTH  # the list textures' rows; the compute grid is LIST_WIDTH / GROUP_SIZE wide
GROUP_SIZE = 64
# Rays per dispatch, a progress (and cancel) step: 32 rows, about 0.1 s on llvmpipe.
RAYS_PER_DISPATCH = 32 * LIST_WIDTH
# Barycentric slack at triangle edges (cell units are about a triangle's size): a ray
# through a shared edge or vertex hits one of the triangles there instead of slipping
# between them through float32 rounding.
EDGE_SLACK = 1e-6


def _ray_cast_info() -> "gpu.types.GPUShaderCreateInfo":
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(GROUP_SIZE, 1, 1)
    info.define("LIST_WIDTH", str(LIST_WIDTH))
    info.define("EDGE_SLACK", repr(EDGE_SLACK))
    info.push_constant('INT', "first_ray")
    info.push_constant('INT', "ray_end")
    info.push_constant('IVEC3', "dims")
    info.push_constant('FLOAT', "reach")
    info.sampler(0, 'FLOAT_2D', "tri_corners")
    info.sampler(1, 'FLOAT_2D', "cell_start")
    info.sampler(2, 'FLOAT_2D', "cell_triangles")
    info.sampler(3, 'FLOAT_2D', "ray_origin")
    info.sampler(4, 'FLOAT_2D', "ray_direction")
    info.image(0, 'RGBA32F', 'FLOAT_2D', "hit_out", qualifiers={'WRITE'})
    info.compute_source(glsl_source("bake_ray_cast.comp"))
    return info


@shader_variants()
def ray_cast_shader() -> "gpu.types.GPUShader":
    return cached_shader(("bake_ray_cast",), _ray_cast_info)


def list_texture(values: np.ndarray, fmt: str) -> "gpu.types.GPUTexture":
    """util.list_texture, refused with one message beyond the GPU's texture size."""
    if util.list_rows(len(values)) > gpu.capabilities.max_texture_size_get():
        raise BakeInputError(f"the Selected-to-Active projection needs {len(values)} list entries, above this "
                             f"GPU's texture limit: use a smaller map or fewer high-poly triangles")
    return util.list_texture(values, fmt)


class GpuRayCast(util.GPUPass):
    """Owns the grid's and one batch of rays' textures."""

    def __init__(self, grid: UniformGrid, origins: np.ndarray, directions: np.ndarray) -> None:
        super().__init__()
        tri = grid.local_triangles.astype(np.float64)
        corners = np.stack([tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]], axis=1)  # v0, e1, e2
        quads = np.zeros((len(tri) * 3, 4), np.float32)
        quads[:, :3] = corners.reshape(-1, 3)
        self.tri_corners = list_texture(quads, 'RGBA32F')
        self.cell_start = list_texture(grid.cell_start, 'R32F')
        self.cell_triangles = list_texture(grid.triangle_index, 'R32F')
        rays = np.zeros((len(origins), 4))
        rays[:, :3] = grid.to_local(origins)
        self.ray_origin = list_texture(rays, 'RGBA32F')
        rays[:, :3] = directions
        self.ray_direction = list_texture(rays, 'RGBA32F')
        self.hit = gpu.types.GPUTexture((LIST_WIDTH, util.list_rows(len(origins))), format='RGBA32F')
        self.grid, self.ray_count = grid, len(origins)

    def dispatch(self, first: int, end: int, reach: float) -> None:
        """Cast rays first..end (their rows of the list; invocations past end return)."""
        shader = ray_cast_shader()
        shader.bind()
        names = ("tri_corners", "cell_start", "cell_triangles", "ray_origin", "ray_direction")
        compat.set_shader_inputs(shader, samplers={name: getattr(self, name) for name in names},
                                 ints={"first_ray": first, "ray_end": end,
                                       "dims": tuple(int(d) for d in self.grid.dims)},
                                 floats={"reach": reach})
        shader.image("hit_out", self.hit)
        rows = -(-(end - first) // LIST_WIDTH)
        gpu.compute.dispatch(shader, LIST_WIDTH // GROUP_SIZE, rows, 1)
        gpu.shader.unbind()

    def hits(self) -> tuple[np.ndarray, np.ndarray]:
        """(face (m,) int64, -1 a miss; uv (m, 2) of the hit in that face) of every ray (the
        shader's t, hit_out.y, is for debugging: the point is the face's at uv)."""
        out = util.texture_to_numpy(self.hit).reshape(-1, 4)[:self.ray_count]
        face = out[:, 0].copy().view(np.int32).astype(np.int64)
        return face, out[:, 2:].astype(np.float64)

    def _release(self) -> None:
        self.tri_corners = self.cell_start = self.cell_triangles = None
        self.ray_origin = self.ray_direction = self.hit = None


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
    cast = GpuRayCast(grid, origins, directions)
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
