# SPDX-License-Identifier: GPL-3.0-or-later
"""Voxelization pass of Hybrid Ambient Occlusion: scene triangles -> bit-packed R32UI 3D grid
(bits along z), by fragment-shader image atomics (rules: hao_addon/core/hao/voxel_grid.py),
then its occupancy pyramid (one compute dispatch per level) beside it in the same texture,
for the hierarchical march."""
from __future__ import annotations

import gpu
import numpy as np

from ..core.hao.voxel_grid import GridSpec, atlas_words, level_count, level_dims, level_offsets
from . import util
from .shaders import cached_shader, glsl_source


def _voxelize_info(solid: bool) -> "gpu.types.GPUShaderCreateInfo":
    iface = gpu.types.GPUStageInterfaceInfo(f"hao_voxelize_iface_{int(solid)}")
    iface.smooth('VEC3', "grid_pos")
    iface.flat('INT', "axis_id")
    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, 'VEC3', "pos")
    info.vertex_in(1, 'FLOAT', "axis")
    info.vertex_out(iface)
    info.push_constant('VEC4', "grid_origin")  # xyz origin, w voxel size
    info.push_constant('IVEC4', "grid_dims")
    info.push_constant('VEC2', "plane_size")
    info.image(0, 'R32UI', 'UINT_3D', "grid", qualifiers={'READ', 'WRITE'})
    info.fragment_out(0, 'VEC4', "voxel_out")
    if solid:
        info.define("SOLID", "1")
    info.vertex_source(glsl_source("hao_voxelize.vert"))
    info.fragment_source(glsl_source("hao_voxelize.frag"))
    return info


def voxelize_shader(solid: bool) -> "gpu.types.GPUShader":
    return cached_shader(("hao_voxelize", solid), lambda: _voxelize_info(solid))


def _unpack_info() -> "gpu.types.GPUShaderCreateInfo":
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(8, 8, 1)
    info.image(0, 'R32UI', 'UINT_3D', "grid", qualifiers={'READ'})
    info.image(1, 'R32UI', 'UINT_2D', "flat_words", qualifiers={'WRITE'})
    info.push_constant('IVEC4', "grid_dims")
    info.compute_source("""
void main()
{
  ivec3 c = ivec3(gl_GlobalInvocationID.xyz);
  if (any(greaterThanEqual(c, grid_dims.xyz))) {
    return;
  }
  imageStore(flat_words, ivec2(c.x, c.y + c.z * grid_dims.y), imageLoad(grid, c + ivec3(grid_dims.w, 0, 0)));
}
""")
    return info


def _pyramid_info() -> "gpu.types.GPUShaderCreateInfo":
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(4, 4, 4)
    info.image(0, 'R32UI', 'UINT_3D', "grid", qualifiers={'READ', 'WRITE'})
    info.push_constant('IVEC4', "fine_words")  # x cells, y cells, z words, atlas x offset
    info.push_constant('IVEC4', "coarse_words")
    info.compute_source(glsl_source("hao_pyramid.comp"))
    return info


def _level_words(dims: tuple[int, int, int], level: int) -> tuple[int, int, int, int]:
    nx, ny, nz = level_dims(dims, level)
    return nx, ny, -(-nz // 32), level_offsets(dims)[level]


class VoxelPass(util.GPUPass):
    """Owns the triangle batches of the scene and the voxel grid."""

    def __init__(self) -> None:
        super().__init__()
        self.surface_batch = self.solid_batch = None
        self.grid = None
        self.spec: GridSpec | None = None
        self.levels = 1
        self.triangles = 0
        self._plane, self._plane_fb, self._plane_side = None, None, 0

    def set_geometry(self, positions: np.ndarray, axes: np.ndarray, solid: np.ndarray) -> None:
        """positions: (F, 3, 3) world; axes: (F,) dominant axis; solid: (F,) bool, triangles
        of closed objects that also go into the solid (parity) pass."""
        pos = positions.reshape(-1, 3)
        axis = np.repeat(np.asarray(axes, np.float32), 3)
        self.triangles = len(positions)
        self.surface_batch = util.make_batch('TRIS', {"pos": ('F32', pos), "axis": ('F32', axis)}) if len(pos) else None
        sp = positions[np.asarray(solid, bool)].reshape(-1, 3)
        self.solid_batch = (util.make_batch('TRIS', {"pos": ('F32', sp), "axis": ('F32', np.zeros(len(sp)))})
                            if len(sp) else None)

    def voxelize(self, spec: GridSpec, solids: bool = True) -> None:
        """Voxelize the geometry into a grid of spec (solids: the closed objects filled, see
        core/hao/voxel_grid.py), then build its pyramid."""
        words = atlas_words(spec.dims)
        if self.grid is None or self.spec is None or atlas_words(self.spec.dims) != words:
            self.grid = gpu.types.GPUTexture(words, format='R32UI')
        self.spec = spec
        self.levels = level_count(spec.dims)
        self.grid.clear(format='UINT', value=(0,))
        side = max(spec.dims)
        if self._plane_side != side:  # the colour target only sizes the raster plane
            self._plane = gpu.types.GPUTexture((side, side), format='R8')  # kept alive with its framebuffer
            self._plane_fb = gpu.types.GPUFrameBuffer(color_slots=self._plane)
            self._plane_side = side
        with util.scoped_state(), self._plane_fb.bind():
            util.set_overlay_pass_state(side, side)
            # Parity first, then the surface ORed over it: XOR and OR do not commute.
            for solid, batch in ((True, self.solid_batch), (False, self.surface_batch)):
                if batch is None or (solid and not solids):
                    continue
                size = (spec.dims[0], spec.dims[1]) if solid else (side, side)  # solid: columns along z
                gpu.state.viewport_set(0, 0, *size)
                shader = voxelize_shader(solid)
                shader.bind()
                shader.uniform_float("grid_origin", (*spec.origin, spec.voxel))
                shader.uniform_int("grid_dims", (*spec.dims, 0))
                shader.uniform_float("plane_size", size)
                shader.image("grid", self.grid)
                batch.draw(shader)
                util.image_barrier()
        self._build_pyramid()

    def _build_pyramid(self) -> None:
        shader = cached_shader(("hao_pyramid",), _pyramid_info)
        shader.bind()
        shader.image("grid", self.grid)
        for level in range(1, self.levels):
            coarse = _level_words(self.spec.dims, level)
            shader.uniform_int("fine_words", _level_words(self.spec.dims, level - 1))
            shader.uniform_int("coarse_words", coarse)
            gpu.compute.dispatch(shader, -(-coarse[0] // 4), -(-coarse[1] // 4), -(-coarse[2] // 4))
        gpu.shader.unbind()

    def read_grid(self, level: int = 0) -> np.ndarray:
        """(nz, ny, nx) bool copy of a level of the pyramid, 0 the grid (for tests; a compute
        copy into 2D, since GPUTexture.read() returns only the first slice of a 3D texture)."""
        nx, ny, nw, x0 = _level_words(self.spec.dims, level)
        flat = gpu.types.GPUTexture((nx, ny * nw), format='R32UI')
        shader = cached_shader(("hao_unpack",), _unpack_info)
        shader.bind()
        shader.uniform_int("grid_dims", (nx, ny, nw, x0))
        shader.image("grid", self.grid)
        shader.image("flat_words", flat)
        gpu.compute.dispatch(shader, -(-nx // 8), -(-ny // 8), nw)
        gpu.shader.unbind()
        words = util.texture_to_numpy(flat, np.uint32).reshape(nw, ny, nx)
        from ..core.hao.voxel_grid import unpack_bits
        return unpack_bits(words)[:level_dims(self.spec.dims, level)[2]]

    def _release(self) -> None:
        self.surface_batch = self.solid_batch = self.grid = None
        self._plane, self._plane_fb, self._plane_side = None, None, 0
