# SPDX-License-Identifier: GPL-3.0-or-later
"""AO sampling and joint bilateral upsampling passes of Hybrid Ambient Occlusion (compute)."""
from __future__ import annotations

import gpu
import numpy as np

from ..core.hao.ao_pattern import GLSL_DEFINES
from ..core.hao.cascades import MAX_CASCADES
from ..core.hao.voxel_grid import level_count
from ..core.hao.view_settings import ViewAOSettings
from . import util
from .hao_gbuffer import bind_gbuffer_images, declare_gbuffer_images
from .shaders import add_defines, cached_shader, glsl_source, glsl_struct, shader_variants

GROUP = 8


# The cascades of the AO pass: the HaoCascades uniform block, whose GLSL struct is generated
# from this dtype (shaders.glsl_struct; std140: arrays of vec4 and ivec4 need no padding), up
# to MAX_CASCADES (core/hao/cascades.py), finest first, each inside the next. origin_voxel is
# the grid's corner (anchor-relative world) and voxel size, dims its voxels and (w) pyramid
# levels, atlas.x its row in the grid texture; count.x how many are used.
CASCADES_DTYPE = np.dtype([("origin_voxel", "<f4", (MAX_CASCADES, 4)), ("dims", "<i4", (MAX_CASCADES, 4)),
                           ("atlas", "<i4", (MAX_CASCADES, 4)), ("count", "<i4", (4,))])


def cascades_block(specs, rows) -> np.ndarray:
    """The HaoCascades block of the cascades' grids (finest first) at their texture rows."""
    block = np.zeros(1, CASCADES_DTYPE)
    for k, (spec, row) in enumerate(zip(specs, rows)):
        block["origin_voxel"][0, k] = (*spec.origin, spec.voxel)
        block["dims"][0, k] = (*spec.dims, level_count(spec.dims))
        block["atlas"][0, k, 0] = row
    block["count"][0, 0] = len(specs)
    return block


# Cells are looked up this far (voxels) past each boundary a hierarchical march crosses:
# far above float32's rounding of t in a 512-voxel grid (6e-5), far below what matters.
MARCH_NUDGE = 1e-3


def _ao_info(march: str, falloff: str) -> "gpu.types.GPUShaderCreateInfo":
    """march: 'hierarchical' or 'fixed' (hao_march.glsl); falloff: 'none' or 'wendland'."""
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(GROUP, GROUP, 1)
    if march == "hierarchical":
        info.define("MARCH_HIERARCHICAL", "1")
    if falloff == "wendland":
        info.define("WENDLAND_FALLOFF", "1")
    info.define("MARCH_NUDGE", repr(MARCH_NUDGE))
    info.define("MAX_CASCADES", str(MAX_CASCADES))
    info.typedef_source(glsl_struct("HaoCascades", CASCADES_DTYPE))
    info.uniform_buf(0, "HaoCascades", "cascades")
    info.push_constant('IVEC2', "full_size")
    info.push_constant('INT', "scale")
    info.push_constant('INT', "rays")
    info.push_constant('INT', "steps")
    info.push_constant('FLOAT', "spread")
    info.push_constant('FLOAT', "max_distance")
    declare_gbuffer_images(info)
    info.image(2, 'R32UI', 'UINT_3D', "grid", qualifiers={'READ'})
    info.image(3, 'R32F', 'FLOAT_2D', "ao_low", qualifiers={'WRITE'})
    info.image(4, 'R32UI', 'UINT_2D', "counters", qualifiers={'READ', 'WRITE'})
    add_defines(info, GLSL_DEFINES)
    info.compute_source(glsl_source("pcg3d.glsl", "hao_common.glsl", "hao_pick.glsl", "hao_march.glsl", "hao_ao.comp"))
    return info


def _bilateral_info(axis: int, upsample: bool) -> "gpu.types.GPUShaderCreateInfo":
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(GROUP, GROUP, 1)
    info.define("AXIS", str(axis))
    if upsample:
        info.define("UPSAMPLE", "1")
    info.push_constant('IVEC2', "full_size")
    info.push_constant('INT', "scale")
    info.push_constant('INT', "filter_size")
    info.push_constant('FLOAT', "max_distance")
    declare_gbuffer_images(info)
    info.image(2, 'R32F', 'FLOAT_2D', "ao_src", qualifiers={'READ'})
    info.image(3, 'R32F', 'FLOAT_2D', "ao_dst", qualifiers={'WRITE'})
    if upsample:
        info.image(4, 'RGBA32F', 'FLOAT_2D', "low_position", qualifiers={'READ'})
        info.image(5, 'RGBA32F', 'FLOAT_2D', "low_normal", qualifiers={'READ'})
    info.compute_source(glsl_source("pcg3d.glsl", "hao_common.glsl", "hao_bilateral.comp"))
    return info


def _pick_low_info() -> "gpu.types.GPUShaderCreateInfo":
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(GROUP, GROUP, 1)
    info.push_constant('IVEC2', "full_size")
    info.push_constant('INT', "scale")
    declare_gbuffer_images(info)
    info.image(2, 'RGBA32F', 'FLOAT_2D', "low_position", qualifiers={'WRITE'})
    info.image(3, 'RGBA32F', 'FLOAT_2D', "low_normal", qualifiers={'WRITE'})
    info.compute_source(glsl_source("hao_pick.glsl", "hao_pick_low.comp"))
    return info


class LowGBufferPass(util.GPUPass):
    """The G-buffer at the AO-map resolution (see hao_pick_low.comp)."""

    def __init__(self) -> None:
        super().__init__()
        self.position = self.normal = None
        self.size = (0, 0)

    def run(self, gbuffer, scale: int) -> None:
        width, height = gbuffer.size
        low = (-(-width // scale), -(-height // scale))
        if self.size != low:
            self.position = gpu.types.GPUTexture(low, format='RGBA32F')
            self.normal = gpu.types.GPUTexture(low, format='RGBA32F')
            self.size = low
        shader = pick_low_shader()
        shader.bind()
        shader.uniform_int("full_size", (width, height))
        shader.uniform_int("scale", scale)
        bind_gbuffer_images(shader, gbuffer)
        shader.image("low_position", self.position)
        shader.image("low_normal", self.normal)
        gpu.compute.dispatch(shader, -(-low[0] // GROUP), -(-low[1] // GROUP), 1)
        gpu.shader.unbind()

    def _release(self) -> None:
        self.position = self.normal = None
        self.size = (0, 0)


@shader_variants()
def pick_low_shader() -> "gpu.types.GPUShader":
    """Picks each AO-map pixel's G-buffer sample (the low-resolution G-buffer)."""
    return cached_shader(("hao_pick_low",), _pick_low_info)


@shader_variants(march=("hierarchical", "fixed"), falloff=("none", "wendland"))
def ao_shader(march: str, falloff: str) -> "gpu.types.GPUShader":
    return cached_shader(("hao_ao", march, falloff), lambda: _ao_info(march, falloff))


@shader_variants(axis=(0, 1), upsample=(False, True))
def bilateral_shader(axis: int, upsample: bool) -> "gpu.types.GPUShader":
    return cached_shader(("hao_bilateral", axis, upsample), lambda: _bilateral_info(axis, upsample))


def _set_optional(shader, name: str, value, integer: bool = False) -> None:
    """Push constants the compiler dropped (a variant not using them) raise on set."""
    try:
        (shader.uniform_int if integer else shader.uniform_float)(name, value)
    except ValueError:
        pass


class AOSamplingPass(util.GPUPass):
    """Owns the low-resolution AO map."""

    def __init__(self) -> None:
        super().__init__()
        self.ao_low = None
        self.low_size = (0, 0)
        self.counter = None
        self.cascades_block = None

    def _ensure(self, gbuffer, k: int) -> tuple[int, int]:
        width, height = gbuffer.size
        low = (-(-width // k), -(-height // k))
        if self.low_size != low:
            self.ao_low = gpu.types.GPUTexture(low, format='R32F')
            self.low_size = low
        return low

    def clear(self, gbuffer, k: int) -> None:
        """An AO map of 1s (open everywhere), for passes that only multiply into it."""
        self._ensure(gbuffer, k)
        self.ao_low.clear(format='FLOAT', value=(1.0,))
        if self.counter is not None:
            self.counter.clear(format='UINT', value=(0,))

    def run(self, gbuffer, voxels, settings: ViewAOSettings) -> None:
        width, height = gbuffer.size
        k = settings.scale
        low = self._ensure(gbuffer, k)
        if self.counter is None:
            self.counter = gpu.types.GPUTexture((2, 1), format='R32UI')
        self.counter.clear(format='UINT', value=(0,))
        block = cascades_block(voxels.specs, voxels.y_offsets)
        if self.cascades_block is None:
            self.cascades_block = gpu.types.GPUUniformBuf(block.view(np.float32))
        else:
            self.cascades_block.update(block.view(np.float32))
        shader = ao_shader(settings.march, settings.falloff)
        shader.bind()
        shader.uniform_block("cascades", self.cascades_block)
        shader.uniform_int("full_size", (width, height))
        shader.uniform_int("scale", k)
        shader.uniform_int("rays", settings.rays)
        shader.uniform_int("steps", settings.steps)
        shader.uniform_float("spread", settings.spread)
        shader.uniform_float("max_distance", settings.max_distance)
        bind_gbuffer_images(shader, gbuffer)
        shader.image("grid", voxels.grid)
        shader.image("ao_low", self.ao_low)
        shader.image("counters", self.counter)
        gpu.compute.dispatch(shader, -(-low[0] // GROUP), -(-low[1] // GROUP), 1)
        gpu.shader.unbind()

    def read(self) -> np.ndarray:
        return util.texture_to_numpy(self.ao_low)

    def counts(self) -> tuple[int, int]:
        """(AO-map pixels the last pass marched, rays that spent their step budget)."""
        if self.counter is None:
            return 0, 0
        values = util.texture_to_numpy(self.counter, np.uint32).ravel()
        return int(values[0]), int(values[1])

    def sampled_pixels(self) -> int:
        return self.counts()[0]

    def _release(self) -> None:
        self.ao_low = self.counter = self.cascades_block = None
        self.low_size = (0, 0)


class BilateralPass(util.GPUPass):
    """Owns the intermediate and the full-resolution AO."""

    def __init__(self) -> None:
        super().__init__()
        self.middle = self.ao = None
        self.size = (0, 0)

    def run(self, gbuffer, low_gbuffer, ao_low, settings: ViewAOSettings, position_range: float) -> None:
        """low_gbuffer: the samples of the AO map (LowGBufferPass); position_range: the
        distance at which the position weight w_p reaches 0."""
        width, height = gbuffer.size
        if self.size != (width, height):
            self.middle = gpu.types.GPUTexture((width, height), format='R32F')
            self.ao = gpu.types.GPUTexture((width, height), format='R32F')
            self.size = (width, height)
        for axis, src, dst in ((0, ao_low, self.middle), (1, self.middle, self.ao)):
            shader = bilateral_shader(axis, axis == 0)
            shader.bind()
            shader.uniform_int("full_size", (width, height))
            _set_optional(shader, "scale", settings.scale, integer=True)
            shader.uniform_int("filter_size", settings.filter_size)
            shader.uniform_float("max_distance", position_range)
            bind_gbuffer_images(shader, gbuffer)
            shader.image("ao_src", src)
            shader.image("ao_dst", dst)
            if axis == 0:
                shader.image("low_position", low_gbuffer.position)
                shader.image("low_normal", low_gbuffer.normal)
            gpu.compute.dispatch(shader, -(-width // GROUP), -(-height // GROUP), 1)
        gpu.shader.unbind()

    def read(self) -> np.ndarray:
        return util.texture_to_numpy(self.ao)

    def _release(self) -> None:
        self.middle = self.ao = None
        self.size = (0, 0)
