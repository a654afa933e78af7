# SPDX-License-Identifier: GPL-3.0-or-later
"""A shader's push constants keep their values when its samplers are set (compat.set_shader_inputs).
Blender 5.3's uniform_sampler overwrites the first push constant set before it with the
sampler's slot: every Selected-to-Active ray of the GPU cast missed (its first push constant
is the first ray), and the viewport's composite lost its region offset."""
from __future__ import annotations

import gpu
import numpy as np

from hao_addon import compat


def _probe_shader() -> "gpu.types.GPUShader":
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(1, 1, 1)
    info.push_constant('INT', "first")
    info.push_constant('FLOAT', "second")
    info.sampler(0, 'FLOAT_2D', "tex0")
    info.sampler(1, 'FLOAT_2D', "tex1")
    info.image(0, 'RGBA32F', 'FLOAT_2D', "out_values", qualifiers={'WRITE'})
    info.compute_source("void main() { vec4 unused = texelFetch(tex0, ivec2(0), 0) + texelFetch(tex1, ivec2(0), 0);"
                        " imageStore(out_values, ivec2(0), vec4(float(first), second, 0.0, 0.0 * unused.x)); }")
    return gpu.shader.create_from_info(info)


def test_push_constants_survive_the_samplers(gpu_context):
    shader = _probe_shader()
    out = gpu.types.GPUTexture((1, 1), format='RGBA32F')
    textures = [gpu.types.GPUTexture((1, 1), format='RGBA32F') for _ in range(2)]
    shader.bind()
    compat.set_shader_inputs(shader, samplers={"tex0": textures[0], "tex1": textures[1]}, ints={"first": 7},
                             floats={"second": 3.5})
    shader.image("out_values", out)
    gpu.compute.dispatch(shader, 1, 1, 1)
    gpu.shader.unbind()
    assert np.array(out.read().to_list(), np.float32).ravel()[:2].tolist() == [7.0, 3.5]
