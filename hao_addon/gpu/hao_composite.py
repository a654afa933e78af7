# SPDX-License-Identifier: GPL-3.0-or-later
"""Composite of Hybrid Ambient Occlusion onto the viewport image (fragment pass)."""
from __future__ import annotations

import gpu
import numpy as np

from .. import compat
from . import util
from .shaders import cached_shader, glsl_source, shader_variants


def _composite_info() -> "gpu.types.GPUShaderCreateInfo":
    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, 'VEC2', "corner")
    info.push_constant('IVEC2', "region_offset")
    info.push_constant('FLOAT', "strength")
    info.sampler(0, 'FLOAT_2D', "ao_tex")
    info.sampler(1, 'FLOAT_2D', "depth_tex")
    info.fragment_out(0, 'VEC4', "frag_color")
    compat.declare_depth_write(info)
    info.vertex_source(glsl_source("hao_composite.vert"))
    info.fragment_source(glsl_source("hao_composite.frag"))
    return info


_TRIANGLE = None


@shader_variants()
def composite_shader() -> "gpu.types.GPUShader":
    """Darkens the viewport's colour by the AO (draw_composite)."""
    return cached_shader(("hao_composite",), _composite_info)


def draw_composite(ao_tex, depth_tex, strength: float, region_offset: tuple[int, int] = (0, 0)) -> None:
    """Darken the bound framebuffer by the AO: colour * (1 - (1 - AO) * strength), depth tested
    LESS_EQUAL against the bound depth buffer (see hao_composite.frag)."""
    global _TRIANGLE
    if _TRIANGLE is None:
        _TRIANGLE = util.make_batch('TRIS', {"corner": ('F32', np.array([[-1.0, -1.0], [3.0, -1.0], [-1.0, 3.0]]))})
    shader = composite_shader()
    with util.scoped_state():
        gpu.state.blend_set('ALPHA')
        gpu.state.depth_test_set('LESS_EQUAL')
        gpu.state.depth_mask_set(False)
        shader.bind()
        compat.set_shader_inputs(shader, samplers={"ao_tex": ao_tex, "depth_tex": depth_tex},
                                  ints={"region_offset": region_offset}, floats={"strength": strength})
        _TRIANGLE.draw(shader)

