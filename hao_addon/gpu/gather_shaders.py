# SPDX-License-Identifier: GPL-3.0-or-later
"""The gather's shaders (gpu/bake_gather.py): the texel list's raster (every texel's point,
normals and lift as list entries) and the texel test of up to GATHER_MAX_VIEWS directions per
dispatch, their interfaces declared here with the constants and struct layouts that reach
GLSL (the GatherViews block from its numpy dtype, the depth slack, the accumulators)."""
from __future__ import annotations

import gpu
import numpy as np

from ..core.bake.estimators import AMBIENT_OCCLUSION, BENT_NORMALS, Estimator
from ..core.bake.interleave import SIDE
from ..core.bake.normal_bins import BIN_COUNT, OCT_SIDE
from ..core.bake.terminator import MIN_LIFT
from ..core.bake.uv_raster import SAMPLE_INSET
from . import util
from .light_view import LAYERS
from .shaders import cached_shader, glsl_source, glsl_struct, shader_variants

# The list textures' row width (util.LIST_WIDTH); the compute grid is LIST_WIDTH / 64 groups wide.
LIST_WIDTH = util.LIST_WIDTH
GROUP_SIZE = 64
# The texel-list attributes of every corner (plan_batch's face_bins): its face's corners and
# the corner's barycentric unit vector, so a fragment puts its point inside its face
# (core/bake/uv_raster.SAMPLE_INSET); with the terminator lift (lift_corners) also the corners'
# shading normals.
FACE_ATTRIBUTES = ("tri_v0", "tri_v1", "tri_v2", "corner_bary")
LIFT_ATTRIBUTES = ("tri_n0", "tri_n1", "tri_n2")


def _texel_list_info(fill: bool, shading: bool, terminator: bool, side: int) -> "gpu.types.GPUShaderCreateInfo":
    iface = gpu.types.GPUStageInterfaceInfo(f"hao_texel_list_iface_{int(fill)}{int(shading)}{int(terminator)}{side}")
    iface.smooth('VEC3', "world_pos")
    iface.smooth('VEC4', "face_data")
    iface.flat('VEC3', "geometric_normal")
    iface.flat('INT', "face_bin")
    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, 'VEC3', "pos")
    info.vertex_in(1, 'VEC2', "uv")
    info.vertex_in(2, 'VEC4', "face")
    info.vertex_in(3, 'FLOAT', "bin")
    info.vertex_in(4, 'VEC3', "geometric")
    info.define("SAMPLE_INSET", f"{SAMPLE_INSET:.9g}")
    if side > 1:  # texel classes (core/bake/interleave.py): each class's bins after the one before's
        info.define("INTERLEAVE_SIDE", str(side))
        info.define("BIN_COUNT", str(BIN_COUNT))
    for k, name in enumerate(FACE_ATTRIBUTES):
        info.vertex_in(5 + k, 'VEC3', name)
        if name == "corner_bary":
            iface.smooth('VEC3', "face_bary")
        else:
            iface.flat('VEC3', "face_" + name[4:])
    if shading:  # entries binned by their own shading normal
        info.define("SHADING_NORMALS", "1")
        info.define("OCT_SIDE", str(OCT_SIDE))
    if terminator:  # each fragment's Cycles terminator lift (gpu_shaders/bake_terminator.glsl)
        assert shading
        info.define("TERMINATOR_OFFSET", "1")
        for k, name in enumerate(LIFT_ATTRIBUTES):
            info.vertex_in(5 + len(FACE_ATTRIBUTES) + k, 'VEC3', name)
            iface.flat('VEC3', "lift_" + name[4:])
    info.vertex_out(iface)
    info.fragment_out(0, 'VEC4', "list_out")
    info.image(0, 'R32UI', 'UINT_2D', "bin_count", qualifiers={'READ', 'WRITE'})
    if fill:
        info.define("FILL", "1")
        info.define("LIST_WIDTH", str(LIST_WIDTH))
        info.push_constant('INT', "capacity")
        info.image(1, 'RGBA32F', 'FLOAT_2D', "entry_position", qualifiers={'WRITE'})
        info.image(2, 'RGBA32F', 'FLOAT_2D', "entry_normal", qualifiers={'WRITE'})
        info.image(3, 'R32UI', 'UINT_2D', "entry_texel", qualifiers={'WRITE'})
        info.image(4, 'R32F', 'FLOAT_2D', "bin_start", qualifiers={'READ'})
        if terminator:
            info.image(5, 'RGBA32F', 'FLOAT_2D', "entry_lift", qualifiers={'WRITE'})
    info.vertex_source(glsl_source("bake_texel_list.vert"))
    info.fragment_source(glsl_source("octahedral.glsl", "bake_terminator.glsl", "bake_texel_list.frag"))
    return info


@shader_variants(valid=lambda a: a["shading"] or not a["terminator"],
                 fill=(False, True), shading=(False, True), terminator=(False, True), side=(1, SIDE))
def texel_list_shader(fill: bool, shading: bool = False, terminator: bool = False, side: int = 1
                      ) -> "gpu.types.GPUShader":
    """shading: entries carry the shading and the face normal (plan.smooth_shading);
    terminator: and their terminator lift (plan.lifts_terminator); side: of the texel classes'
    pattern (core/bake/interleave.py; 1: none)."""
    return cached_shader(("bake_texel_list", fill, shading, terminator, side),
                         lambda: _texel_list_info(fill, shading, terminator, side))


# The light views of one gather dispatch: the GatherViews uniform block, whose GLSL struct is
# generated from this dtype (shaders.glsl_struct; std140, mat4 and vec4 arrays need no
# padding). Its arrays hold GATHER_MAX_VIEWS entries (also a GLSL define), VIEWS_PER_DISPATCH
# <= that of them used. view_proj maps normalized world to the view's clip space; plane_slope.xy
# turns the image of a plane's normal under it into the plane's depth change per pixel
# (core/bake/views.OrthoView.plane_slope); omega points towards the light; view_info is
# (width, height, one pixel's extent in depth units, the depth range in normalized units);
# window is (first x, first y, width, height) of the pixels its depth map holds (a view
# cropped from a whole one, OrthoView.whole: the other fields are the whole view's, and the
# map holds only the crop's pixels). A
# uniform buffer, because four views' push constants would pass the 128 bytes some backends
# guarantee.
GATHER_MAX_VIEWS = 16
GATHER_VIEWS_DTYPE = np.dtype([("view_proj", "<f4", (GATHER_MAX_VIEWS, 4, 4)),
                               ("plane_slope", "<f4", (GATHER_MAX_VIEWS, 4)),
                               ("omega", "<f4", (GATHER_MAX_VIEWS, 4)),
                               ("view_info", "<f4", (GATHER_MAX_VIEWS, 4)),
                               ("window", "<f4", (GATHER_MAX_VIEWS, 4))])
# The gather's depth slack (gpu_shaders/bake_gather.comp, plane_lookup): the receiver's own
# plane is extrapolated to the depth map's pixel centre exactly, and the comparison allows
# DEPTH_BIAS_PIXELS of depth plus SLOPE_BIAS_PIXELS pixels' worth of that plane's slope, for
# the neighbouring facets of a curved surface there. Bias against Cycles at 256 directions
# (Spot smooth / Spot custom normals, offset off / rocker arm): slope slack 0.1: -0.0002 /
# +0.0007 / -0.0005; 0.25: +0.0000 / +0.0015 / -0.0001; without the slack -0.0035 on the custom
# normals (neighbouring facets read as occluders); the old slope-scaled bias (1.5 tan + 0.5,
# no extrapolation, which ignored occluders up to 150 pixels along grazing rays): -0.0010 /
# +0.0039 on Spot.
DEPTH_BIAS_PIXELS = 0.5
SLOPE_BIAS_PIXELS = 0.25
# The accumulator image of an estimator's sums, by channel count (gpu_shaders/bake_estimator.glsl).
# Their names in the shader: "accum", then "accum_high" (bindings ACCUM_BINDINGS).
ACCUM_FORMATS = {2: ('RG32F',), 4: ('RGBA32F',), 8: ('RGBA32F', 'RGBA32F')}
ACCUM_NAMES = ("accum", "accum_high")
FORMAT_CHANNELS = {'RG32F': 2, 'RGBA32F': 4}
ACCUM_BINDINGS = (2, 6)


def _gather_info(uniform: bool, views: int, shading: bool, falloff: str | None, terminator: bool,
                 estimator: Estimator, spread_cos: float = 0.0, alpha_taps: bool = False, difference: bool = False
                 ) -> "gpu.types.GPUShaderCreateInfo":
    """falloff: None for unlimited distance (depth maps), else the max-distance falloff
    ('none', 'wendland'), tested against per-pixel depth lists; terminator: entries carry
    their terminator lift (image entry_lift); estimator: what each direction adds."""
    info = gpu.types.GPUShaderCreateInfo()
    info.define(estimator.define, "1")
    info.define("ESTIMATOR_CHANNELS", str(estimator.channel_count))
    if shading:
        info.define("SHADING_NORMALS", "1")
    if terminator:
        assert shading
        info.define("TERMINATOR_OFFSET", "1")
        info.define("MIN_LIFT", repr(MIN_LIFT))
        info.image(5, 'RGBA32F', 'FLOAT_2D', "entry_lift", qualifiers={'READ'})
        info.push_constant('FLOAT', "terminator_offset")
    info.local_group_size(GROUP_SIZE, 1, 1)
    info.define("LIST_WIDTH", str(LIST_WIDTH))
    # Every view's test, written out: each reads its own sampler (GATHER_VIEW in the shader).
    info.define("GATHER_ALL_VIEWS", " ".join(f"GATHER_VIEW(depth_tex{k}, {k})" for k in range(views)))
    info.define("GATHER_MAX_VIEWS", str(GATHER_MAX_VIEWS))
    info.define("DEPTH_BIAS_PIXELS", repr(float(DEPTH_BIAS_PIXELS)))
    info.define("SLOPE_BIAS_PIXELS", repr(float(SLOPE_BIAS_PIXELS)))
    if uniform:
        info.define("UNIFORM_WEIGHTING", "1")
    if spread_cos > 0.0:
        info.define("SPREAD_COS", repr(float(spread_cos)))
    if alpha_taps:
        info.define("ALPHA_TAPS", "1")
    if difference:
        info.define("DIFFERENCE", "1")
    info.push_constant('INT', "first_entry")
    info.push_constant('INT', "entry_end")
    info.typedef_source(glsl_struct("GatherViews", GATHER_VIEWS_DTYPE))
    info.uniform_buf(0, "GatherViews", "views")
    info.image(0, 'RGBA32F', 'FLOAT_2D', "entry_position", qualifiers={'READ'})
    info.image(1, 'RGBA32F', 'FLOAT_2D', "entry_normal", qualifiers={'READ'})
    for binding, name, fmt in zip(ACCUM_BINDINGS, ACCUM_NAMES, ACCUM_FORMATS[estimator.channel_count]):
        info.image(binding, fmt, 'FLOAT_2D', name, qualifiers={'READ', 'WRITE'})
    if falloff is None:
        for k in range(views):
            info.sampler(k, 'FLOAT_2D', f"depth_tex{k}")
    else:
        assert views == 1
        info.define("MAX_DISTANCE", "1")
        info.define("LAYERS", str(LAYERS))
        if falloff == "wendland":
            info.define("WENDLAND_FALLOFF", "1")
        info.image(3, 'R32UI', 'UINT_2D', "layer_count", qualifiers={'READ'})
        info.image(4, 'R32UI', 'UINT_2D_ARRAY', "layer_depth", qualifiers={'READ'})
        info.push_constant('FLOAT', "max_distance")
        info.push_constant('FLOAT', "min_distance")
    info.compute_source(glsl_source("octahedral.glsl", "bake_falloff.glsl", "bake_terminator.glsl",
                                    "bake_estimator.glsl", "bake_gather.comp"))
    return info


@shader_variants(valid=lambda a: (a["shading"] or not a["terminator"]) and (a["falloff"] is None or a["views"] == 1),
                 uniform=(False, True), views=(GATHER_MAX_VIEWS, 4, 1), shading=(False, True),
                 falloff=(None, "none", "wendland"), terminator=(False, True),
                 estimator=(AMBIENT_OCCLUSION, BENT_NORMALS), spread_cos=(0.0, 0.5), alpha_taps=(False, True))
def gather_shader(uniform: bool, views: int = 1, shading: bool = False, falloff: str | None = None,
                  terminator: bool = False, estimator: Estimator = AMBIENT_OCCLUSION,
                  spread_cos: float = 0.0, alpha_taps: bool = False, difference: bool = False
                  ) -> "gpu.types.GPUShader":
    """The texel test of `views` (1 to GATHER_MAX_VIEWS) directions per dispatch; shading:
    entries carry shading normals (plan.smooth_shading); falloff, terminator, estimator: see
    _gather_info; spread_cos: the spread cone's cut-off (0: the hemisphere); alpha_taps: each
    depth test the mean of four pixels (plan.alpha 'blend': four draws of its stochastic
    keeping for the noise of one); difference: views of the scene before an edit (omega.w <
    0) subtract (hao_addon/rebake_difference.py)."""
    key = ("bake_gather", uniform, views, shading, falloff, terminator, estimator.define, spread_cos, alpha_taps,
           difference)
    return cached_shader(key, lambda: _gather_info(uniform, views, shading, falloff, terminator, estimator, spread_cos,
                                                   alpha_taps, difference))
