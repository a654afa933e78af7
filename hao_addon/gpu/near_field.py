# SPDX-License-Identifier: GPL-3.0-or-later
"""Image-space near-field AO pass (Shanmugam & Arikan, section 4; compute). Rules and the
numpy mirror: hao_addon/core/proxies/near_field.py."""
from __future__ import annotations

import gpu
import numpy as np

from ..core.hao.ao_pattern import GLSL_DEFINES
from ..core.proxies.near_field import camera_terms
from .hao_sampling import GROUP
from .hao_gbuffer import bind_gbuffer_images, declare_gbuffer_images
from .shaders import add_defines, cached_shader, glsl_source, shader_variants


def _near_info(falloff: str) -> "gpu.types.GPUShaderCreateInfo":
    info = gpu.types.GPUShaderCreateInfo()
    if falloff == "wendland":
        info.define("WENDLAND_FALLOFF", "1")
    info.push_constant('FLOAT', "max_distance")
    info.local_group_size(GROUP, GROUP, 1)
    info.push_constant('IVEC2', "full_size")
    info.push_constant('INT', "scale")
    info.push_constant('INT', "samples")
    info.push_constant('FLOAT', "r_far")
    info.push_constant('FLOAT', "proj_scale")
    info.push_constant('VEC4', "view_proj_row3")
    info.push_constant('VEC4', "eye")
    declare_gbuffer_images(info)
    info.image(2, 'RGBA32F', 'FLOAT_2D', "back_position", qualifiers={'READ'})
    info.image(3, 'RGBA32F', 'FLOAT_2D', "back_normal", qualifiers={'READ'})
    info.image(4, 'R32F', 'FLOAT_2D', "ao_low", qualifiers={'WRITE'})
    add_defines(info, GLSL_DEFINES)
    info.compute_source(glsl_source("pcg3d.glsl", "hao_common.glsl", "hao_pick.glsl", "near_field.comp"))
    return info


@shader_variants(falloff=("none", "wendland"))
def near_shader(falloff: str = "wendland") -> "gpu.types.GPUShader":
    return cached_shader(("hao_near_field", falloff), lambda: _near_info(falloff))


def run_near_field(front, back, ao_low, scale: int, view_proj: np.ndarray, r_far: float, samples: int,
                   max_distance: float = 0.0, falloff: str = "wendland") -> None:
    """Write near-field accessibility into ao_low (R32F, the AO-map resolution) from the front
    and back-layer G-buffer passes: samples within r_far, each weighted by the AO's distance
    falloff (max_distance 0 = unlimited)."""
    row3, proj_scale, eye = camera_terms(view_proj)
    width, height = front.size
    shader = near_shader(falloff)
    shader.bind()
    shader.uniform_float("max_distance", max_distance)
    shader.uniform_int("full_size", (width, height))
    shader.uniform_int("scale", scale)
    shader.uniform_int("samples", samples)
    shader.uniform_float("r_far", r_far)
    shader.uniform_float("proj_scale", proj_scale)
    shader.uniform_float("view_proj_row3", tuple(row3))
    shader.uniform_float("eye", tuple(eye))
    bind_gbuffer_images(shader, front)
    shader.image("back_position", back.position)
    shader.image("back_normal", back.normal)
    shader.image("ao_low", ao_low)
    low = (-(-width // scale), -(-height // scale))
    gpu.compute.dispatch(shader, -(-low[0] // GROUP), -(-low[1] // GROUP), 1)
    gpu.shader.unbind()
