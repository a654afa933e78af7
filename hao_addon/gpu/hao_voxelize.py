# SPDX-License-Identifier: GPL-3.0-or-later
"""Voxelization pass of Hybrid Ambient Occlusion: scene triangles -> bit-packed R32UI 3D grid
(bits along z), by fragment-shader image atomics (rules: hao_addon/core/hao/voxel_grid.py),
then its occupancy pyramid (one compute dispatch per level) beside it in the same texture,
for the hierarchical march."""
from __future__ import annotations

import gpu
import numpy as np

from ..core.hao.cascades import atlas_layout
from ..core.hao.view_scene import NEARLY_CLOSED, OPEN
from ..core.hao.voxel_grid import GridSpec, atlas_words, level_count, level_dims, level_offsets
from . import util
from .shaders import cached_shader, glsl_source, shader_variants


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


@shader_variants()
def clear_box_shader() -> "gpu.types.GPUShader":
    """Clears one cascade's box of the grid texture."""
    return cached_shader(("hao_clear_box",), _clear_info)


@shader_variants()
def pyramid_shader() -> "gpu.types.GPUShader":
    """Builds one level of a cascade's occupancy pyramid from the level below."""
    return cached_shader(("hao_pyramid",), _pyramid_info)


@shader_variants()
def unpack_shader() -> "gpu.types.GPUShader":
    """Copies a 3D grid level into 2D for reading back (tests)."""
    return cached_shader(("hao_unpack",), _unpack_info)


@shader_variants(solid=(False, True))
def voxelize_shader(solid: bool) -> "gpu.types.GPUShader":
    return cached_shader(("hao_voxelize", solid), lambda: _voxelize_info(solid))


def _unpack_info() -> "gpu.types.GPUShaderCreateInfo":
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(8, 8, 1)
    info.image(0, 'R32UI', 'UINT_3D', "grid", qualifiers={'READ'})
    info.image(1, 'R32UI', 'UINT_2D', "flat_words", qualifiers={'WRITE'})
    info.push_constant('IVEC4', "grid_dims")
    info.push_constant('INT', "atlas_y")
    info.compute_source("""
void main()
{
  ivec3 c = ivec3(gl_GlobalInvocationID.xyz);
  if (any(greaterThanEqual(c, grid_dims.xyz))) {
    return;
  }
  imageStore(flat_words, ivec2(c.x, c.y + c.z * grid_dims.y), imageLoad(grid, c + ivec3(grid_dims.w, atlas_y, 0)));
}
""")
    return info


def _pyramid_info() -> "gpu.types.GPUShaderCreateInfo":
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(4, 4, 4)
    info.image(0, 'R32UI', 'UINT_3D', "grid", qualifiers={'READ', 'WRITE'})
    info.push_constant('IVEC4', "fine_words")  # x cells, y cells, z words, atlas x offset
    info.push_constant('IVEC4', "coarse_words")
    info.push_constant('INT', "atlas_y")  # the cascade's y offset in the texture
    info.compute_source(glsl_source("hao_pyramid.comp"))
    return info


def _clear_info() -> "gpu.types.GPUShaderCreateInfo":
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(8, 8, 1)
    info.image(0, 'R32UI', 'UINT_3D', "grid", qualifiers={'WRITE'})
    info.push_constant('IVEC4', "box")  # x size, y first, y end, z size
    info.compute_source("""
void main()
{
  ivec3 c = ivec3(gl_GlobalInvocationID.xyz) + ivec3(0, box.y, 0);
  if (c.x < box.x && c.y < box.z && c.z < box.w) {
    imageStore(grid, c, uvec4(0u));
  }
}
""")
    return info


def _level_words(dims: tuple[int, int, int], level: int) -> tuple[int, int, int, int]:
    nx, ny, nz = level_dims(dims, level)
    return nx, ny, -(-nz // 32), level_offsets(dims)[level]


class VoxelPass(util.GPUPass):
    """Owns the triangle batch of the scene and the cascades' voxel grids with their
    pyramids, in one texture (cascades.atlas_layout)."""

    def __init__(self) -> None:
        super().__init__()
        self.surface_batch = None
        self._fill_positions = np.zeros((0, 3, 3), np.float32)
        self._fill = np.zeros(0, np.int8)
        self._fill_batches: dict[int, object] = {}  # least fill class -> batch of those triangles
        self.grid = None
        self.specs: tuple[GridSpec, ...] = ()
        self.y_offsets: list[int] = []
        self._contents: list = []  # per cascade: the key of what it holds
        self.object_boxes: list[tuple[int, int, np.ndarray, np.ndarray]] = []
        self.triangles = 0
        self._plane, self._plane_fb, self._plane_side = None, None, 0

    @property
    def spec(self) -> GridSpec | None:
        """The finest cascade's grid (the only one with a single cascade)."""
        return self.specs[0] if self.specs else None

    @property
    def levels(self) -> int:
        return level_count(self.spec.dims) if self.spec else 1

    def set_geometry(self, positions: np.ndarray, axes: np.ndarray, fill: np.ndarray,
                     object_faces: list[int] | None = None) -> None:
        """positions: (F, 3, 3) world; axes: (F,) dominant axis; fill: (F,) the fill class of
        each triangle's object (core/hao/view_scene.py: those a voxelization fills also go
        into the parity pass); object_faces: the face count of each object, in order
        (cascades draw only the objects reaching into them)."""
        pos = positions.reshape(-1, 3)
        axis = np.repeat(np.asarray(axes, np.float32), 3)
        self.triangles = len(positions)
        self.surface_batch = util.make_batch('TRIS', {"pos": ('F32', pos), "axis": ('F32', axis)}) if len(pos) else None
        fill = np.asarray(fill, np.int8)
        fillable = fill > OPEN
        self._fill_positions, self._fill = positions[fillable], fill[fillable]
        self._fill_batches = {}
        counts = [len(positions)] if object_faces is None else list(object_faces)
        ends = np.cumsum(counts).astype(int)
        self.object_boxes = []
        for first, end in zip(np.concatenate([[0], ends[:-1]]).astype(int), ends):
            flat = positions[first:end].reshape(-1, 3)
            if len(flat):
                self.object_boxes.append((int(first), int(end), flat.min(0), flat.max(0)))
        # The cascades keep their voxels: each one's key names the objects in it.

    def fill_batch(self, least: int):
        """The batch of the triangles whose fill class is at least `least` (None: none)."""
        if least not in self._fill_batches:
            sp = self._fill_positions[self._fill >= least].reshape(-1, 3)
            self._fill_batches[least] = (util.make_batch('TRIS', {"pos": ('F32', sp), "axis": ('F32', np.zeros(len(sp)))})
                                         if len(sp) else None)  # axis unused: the parity pass projects along z
        return self._fill_batches[least]

    def voxelize(self, spec: "GridSpec | tuple[GridSpec, ...]", fill: int = NEARLY_CLOSED,
                 keys: tuple | None = None) -> int:
        """Voxelize the geometry into the cascades' grids (finest first; one GridSpec: one
        grid) and build their pyramids. fill: objects of at least this fill class are filled
        (core/hao/voxel_grid.py; a column's parity counts every crossing, also those outside a
        cascade's box, so each cascade fills alike). keys: per cascade, what reaches into it
        (None: redo every cascade); a cascade whose grid, key and fill are unchanged keeps its
        voxels. Returns how many cascades were voxelized."""
        specs = (spec,) if isinstance(spec, GridSpec) else tuple(spec)
        keys = tuple(keys) if keys is not None else (None,) * len(specs)
        size, offsets = atlas_layout(specs)
        if self.grid is None or tuple(self.grid_size) != size:
            self.grid = gpu.types.GPUTexture(size, format='R32UI')
            self.grid.clear(format='UINT', value=(0,))
            self._contents = []
        self.grid_size = size
        contents = [(s, y, k, fill) for s, y, k in zip(specs, offsets, keys)]  # the fill too: a march switch
        redo = [i for i, c in enumerate(contents)
                if c[2] is None or i >= len(self._contents) or self._contents[i] != c]
        self.specs, self.y_offsets = specs, offsets
        for i in redo:
            self._clear_cascade(i)
            self._draw_cascade(i, self.fill_batch(fill))
            self._build_pyramid(i)
        self._contents = contents
        return len(redo)

    def _clear_cascade(self, i: int) -> None:
        words = atlas_words(self.specs[i].dims)
        shader = clear_box_shader()
        shader.bind()
        shader.image("grid", self.grid)
        shader.uniform_int("box", (words[0], self.y_offsets[i], self.y_offsets[i] + words[1], words[2]))
        gpu.compute.dispatch(shader, -(-words[0] // 8), -(-words[1] // 8), words[2])
        gpu.shader.unbind()

    def _draw_cascade(self, i: int, fill_batch) -> None:
        spec = self.specs[i]
        side = max(spec.dims)
        if self._plane_side < side:  # the colour target only sizes the raster plane
            self._plane = gpu.types.GPUTexture((side, side), format='R8')  # kept alive with its framebuffer
            self._plane_fb = gpu.types.GPUFrameBuffer(color_slots=self._plane)
            self._plane_side = side
        lo = np.asarray(spec.origin)
        hi = lo + np.asarray(spec.dims) * spec.voxel
        runs = [(first, end) for first, end, blo, bhi in self.object_boxes
                if (blo <= hi).all() and (bhi >= lo).all()]
        with util.scoped_state(), self._plane_fb.bind():
            util.set_overlay_pass_state(side, side)
            # Parity first, then the surface ORed over it: XOR and OR do not commute.
            for solid, batch in ((True, fill_batch), (False, self.surface_batch)):
                if batch is None:
                    continue
                size = (spec.dims[0], spec.dims[1]) if solid else (side, side)  # solid: columns along z
                gpu.state.viewport_set(0, 0, *size)
                shader = voxelize_shader(solid)
                shader.bind()
                shader.uniform_float("grid_origin", (*spec.origin, spec.voxel))
                shader.uniform_int("grid_dims", (*spec.dims, self.y_offsets[i]))
                shader.uniform_float("plane_size", size)
                shader.image("grid", self.grid)
                if solid or not hasattr(batch, "draw_range"):
                    batch.draw(shader)
                else:  # only the objects reaching into this cascade
                    for first, end in runs:
                        batch.draw_range(shader, elem_start=3 * first, elem_count=3 * (end - first))
                util.image_barrier()

    def _build_pyramid(self, i: int) -> None:
        dims = self.specs[i].dims
        shader = pyramid_shader()
        shader.bind()
        shader.image("grid", self.grid)
        shader.uniform_int("atlas_y", self.y_offsets[i])
        for level in range(1, level_count(dims)):
            coarse = _level_words(dims, level)
            shader.uniform_int("fine_words", _level_words(dims, level - 1))
            shader.uniform_int("coarse_words", coarse)
            gpu.compute.dispatch(shader, -(-coarse[0] // 4), -(-coarse[1] // 4), -(-coarse[2] // 4))
        gpu.shader.unbind()

    def read_grid(self, level: int = 0, cascade: int = 0) -> np.ndarray:
        """(nz, ny, nx) bool copy of a level of a cascade's pyramid, 0 the grid (for tests; a
        compute copy into 2D, since GPUTexture.read() returns only the first slice of a 3D
        texture)."""
        dims = self.specs[cascade].dims
        nx, ny, nw, x0 = _level_words(dims, level)
        flat = gpu.types.GPUTexture((nx, ny * nw), format='R32UI')
        shader = unpack_shader()
        shader.bind()
        shader.uniform_int("grid_dims", (nx, ny, nw, x0))
        shader.uniform_int("atlas_y", self.y_offsets[cascade])
        shader.image("grid", self.grid)
        shader.image("flat_words", flat)
        gpu.compute.dispatch(shader, -(-nx // 8), -(-ny // 8), nw)
        gpu.shader.unbind()
        words = util.texture_to_numpy(flat, np.uint32).reshape(nw, ny, nx)
        from ..core.hao.voxel_grid import unpack_bits
        return unpack_bits(words)[:level_dims(dims, level)[2]]

    def _release(self) -> None:
        self.surface_batch = self.grid = None
        self._fill_batches = {}
        self._contents = []
        self._plane, self._plane_fb, self._plane_side = None, None, 0
