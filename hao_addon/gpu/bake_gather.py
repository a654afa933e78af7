# SPDX-License-Identifier: GPL-3.0-or-later
"""The shadow-map gather baseline that McGraw & Sowers compare against (their Table 1, ATI's
GPU MeshMapper): per direction render a depth map from the light, then rasterize the target
in UV space and test every texel centre against it.

Same interface as ScatterBaker. Differences a user sees: one sample per texel centre (no
area average, no stretch correction needed), shadow-map bias (a slope-scaled offset can hide
contact occlusion thinner than a few light-view pixels), and unlimited distance only.
Sums use ADDITIVE_PREMULT blending into RG32F, exact and order-deterministic.
"""
from __future__ import annotations

import gpu
import numpy as np

from ..core.plan import BakePlan
from . import util
from .light_view import LightViewBaker, bind_light_view, depth_prepass, soup_shader_info
from .shaders import cached_shader, glsl_source


def _gather_info(uniform: bool) -> "gpu.types.GPUShaderCreateInfo":
    info = soup_shader_info("bake_gather", "bake_gather.vert",
                            (('smooth', 'VEC3', "light_pos"), ('flat', 'VEC4', "face_data")),
                            ('VEC4', "gather_out"))
    info.push_constant('IVEC2', "view_size")
    info.push_constant('FLOAT', "pixel_depth")
    info.sampler(0, 'FLOAT_2D', "depth_tex")
    if uniform:
        info.define("UNIFORM_WEIGHTING", "1")
    info.fragment_source(glsl_source("bake_gather.frag"))
    return info


def gather_shader(uniform: bool) -> "gpu.types.GPUShader":
    return cached_shader(("bake_gather", uniform), lambda: _gather_info(uniform))


class GatherBaker(LightViewBaker):
    """Owns the depth map and the UV-space accumulation target of one bake."""

    @staticmethod
    def bytes_needed(plan: BakePlan) -> int:
        """RGBA32F accumulator, view depth and dummy colour."""
        side = plan.max_view_side
        return plan.settings.size**2 * 16 + side * side * 8

    def _allocate(self) -> None:
        plan = self.plan
        if plan.settings.max_distance > 0.0:
            raise ValueError("the gather baseline supports only unlimited distance")
        size, side = plan.settings.size, plan.max_view_side
        self.depth = gpu.types.GPUTexture((side, side), format='DEPTH_COMPONENT32F')
        self.dummy = gpu.types.GPUTexture((side, side), format='R8')
        self.depth_fb = gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=self.dummy)
        self.accum = gpu.types.GPUTexture((size, size), format='RGBA32F')
        self.accum_fb = gpu.types.GPUFrameBuffer(color_slots=self.accum)
        with self.accum_fb.bind():
            gpu.state.active_framebuffer_get().clear(color=(0.0, 0.0, 0.0, 0.0))
        self.gather_prog = gather_shader(plan.settings.weighting == "uniform")
        self.stats = dict(view_pixels=0, directions_done=0)

    def _release(self) -> None:
        self.depth = self.dummy = self.depth_fb = self.accum = self.accum_fb = None
        super()._release()

    def run_direction(self, index: int) -> None:
        plan = self.plan
        view = plan.view(index)
        w, h = view.width, view.height
        size = plan.settings.size
        culling = 'FRONT' if plan.settings.ignore_back_faces else 'NONE'
        with util.scoped_state():
            gpu.state.blend_set('NONE')
            depth_prepass(self.depth_fb, self.all_batch, view, culling)
            with self.accum_fb.bind():
                util.set_overlay_pass_state(size, size, blend='ADDITIVE_PREMULT')  # exact ONE, ONE sums
                shader = self.gather_prog
                bind_light_view(shader, view, size)
                shader.uniform_int("view_size", (w, h))
                shader.uniform_float("pixel_depth", view.pixel_size / (view.depth_far - view.depth_near))
                shader.uniform_sampler("depth_tex", self.depth)
                self.target_batch.draw(shader)
        self.stats["view_pixels"] += w * h
        self.stats["directions_done"] += 1

    def accumulated(self) -> tuple[np.ndarray, np.ndarray]:
        rgba = util.texture_to_numpy(self.accum, np.float32).astype(np.float64)
        return rgba[:, :, 0], rgba[:, :, 1]
