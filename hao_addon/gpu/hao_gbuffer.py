# SPDX-License-Identifier: GPL-3.0-or-later
"""G-buffer pass of Hybrid Ambient Occlusion: world position (w: receiver flag), world normal
facing the viewer, and depth of the evaluated meshes, rendered with the view's matrices."""
from __future__ import annotations

import gpu
import numpy as np

from . import util
from .shaders import cached_shader, glsl_source, shader_variants


def _gbuffer_info(back_layer: bool) -> "gpu.types.GPUShaderCreateInfo":
    iface = gpu.types.GPUStageInterfaceInfo(f"hao_gbuffer_iface_{int(back_layer)}")
    iface.smooth('VEC3', "world_pos")
    iface.smooth('VEC3', "world_nrm")
    iface.flat('FLOAT', "receiver")
    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, 'VEC3', "pos")
    info.vertex_in(1, 'VEC3', "nrm")
    info.vertex_in(2, 'FLOAT', "flags")
    info.vertex_out(iface)
    info.push_constant('MAT4', "view_proj")
    info.fragment_out(0, 'VEC4', "gbuf_position")
    info.fragment_out(1, 'VEC4', "gbuf_normal")
    if back_layer:
        info.define("BACK_LAYER", "1")
    info.vertex_source(glsl_source("hao_gbuffer.vert"))
    info.fragment_source(glsl_source("hao_gbuffer.frag"))
    return info


@shader_variants(back_layer=(False, True))
def gbuffer_shader(back_layer: bool = False) -> "gpu.types.GPUShader":
    return cached_shader(("hao_gbuffer", back_layer), lambda: _gbuffer_info(back_layer))


def declare_gbuffer_images(info: "gpu.types.GPUShaderCreateInfo") -> None:
    """Declare the G-buffer as read-only images 0 (gbuf_position) and 1 (gbuf_normal), the
    interface every pass reading the G-buffer shares (bind with bind_gbuffer_images)."""
    info.image(0, 'RGBA32F', 'FLOAT_2D', "gbuf_position", qualifiers={'READ'})
    info.image(1, 'RGBA32F', 'FLOAT_2D', "gbuf_normal", qualifiers={'READ'})


def bind_gbuffer_images(shader: "gpu.types.GPUShader", gbuffer: "GBufferPass") -> None:
    shader.image("gbuf_position", gbuffer.position)
    shader.image("gbuf_normal", gbuffer.normal)


class GBufferPass(util.GPUPass):
    """Owns the mesh batch and the G-buffer textures (reallocated when the size changes).
    back_layer: the nearest back faces with their own normals (front faces culled), the
    second layer of the near-field pass."""

    def __init__(self, back_layer: bool = False) -> None:
        super().__init__()
        self.back_layer = back_layer
        self.batch = None
        self.size = (0, 0)
        self.position = self.normal = self.depth = self.fb = None

    def set_geometry(self, positions: np.ndarray, normals: np.ndarray, flags: np.ndarray) -> None:
        """positions, normals: (F, 3, 3) world corners; flags: (F,) 1 receiver, 0.5 baked."""
        if len(positions) == 0:
            self.batch = None
            return
        self.batch = util.make_batch('TRIS', {"pos": ('F32', positions.reshape(-1, 3)),
                                              "nrm": ('F32', normals.reshape(-1, 3)),
                                              "flags": ('F32', np.repeat(np.asarray(flags, np.float32), 3))})

    def render(self, view_proj: np.ndarray, width: int, height: int) -> None:
        """view_proj: (4, 4) row-major world -> clip matrix."""
        if self.size != (width, height):
            self.position = gpu.types.GPUTexture((width, height), format='RGBA32F')
            self.normal = gpu.types.GPUTexture((width, height), format='RGBA32F')
            self.depth = gpu.types.GPUTexture((width, height), format='DEPTH_COMPONENT32F')
            self.fb = gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=(self.position, self.normal))
            self.size = (width, height)
        with util.scoped_state(), self.fb.bind():
            fb = gpu.state.active_framebuffer_get()
            fb.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
            gpu.state.viewport_set(0, 0, width, height)
            gpu.state.depth_test_set('LESS')
            gpu.state.depth_mask_set(True)
            gpu.state.face_culling_set('FRONT' if self.back_layer else 'NONE')
            gpu.state.blend_set('NONE')
            if self.batch is not None:
                shader = gbuffer_shader(self.back_layer)
                shader.bind()
                shader.uniform_float("view_proj", np.asarray(view_proj, np.float32).T.ravel())
                self.batch.draw(shader)

    def read_depth(self, x: int, y: int, width: int, height: int) -> np.ndarray:
        """(height, width) float32 window depths of a rectangle (1 = background)."""
        buf = self.fb.read_depth(x, y, width, height)
        buf.dimensions = width * height
        return np.frombuffer(buf, np.float32).reshape(height, width).copy()

    def read(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(position (H, W, 4), normal (H, W, 4), depth (H, W)) float32 copies, row 0 bottom."""
        return (util.texture_to_numpy(self.position), util.texture_to_numpy(self.normal),
                util.texture_to_numpy(self.depth))

    def _release(self) -> None:
        self.batch = self.position = self.normal = self.depth = self.fb = None
        self.size = (0, 0)
