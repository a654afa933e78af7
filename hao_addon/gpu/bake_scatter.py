# SPDX-License-Identifier: GPL-3.0-or-later
"""McGraw & Sowers' per-texel AO bake on the GPU: render from D directions, scatter the
visible texels into a histogram (their equations 7 and 8).

Per direction: (1) a depth pre-pass of target and occluders from the light; (2) the target's
triangles again, without depth test: every fragment splats its weight (omega . n)|J|/S_f into
a denominator accumulator, and into a numerator accumulator when it is the visible surface
(see gpu_shaders/bake_splat.frag). The map is numerator / denominator, an estimator whose
value for an unoccluded texel is exactly 1 and whose denominator doubles as the texel's UV
coverage (about 1 inside a chart, less on its rim, 2 where two islands overlap).

Fixed point: numerator and denominator are packed in one R32UI word (16 bits each, see
gpu_shaders/bake_common.glsl). A direction adds about (4 / D) * coverage to a texel's
denominator, so a chunk of C directions adds about 4 C / D; the scale makes that 2^12, which
leaves a factor 16 below 2^16 for overlapping UV islands and the tent's ripple. After each
chunk of CHUNK_DIRECTIONS the word is read back, unpacked into float64 sums and cleared, so D
can grow without overflow. A direction then adds 2^12 / C = 256 units per texel, spread over
a few fragments: rounding to integers costs well under 1 % per addend and averages out. If a
chunk ever fills more than half the field (heavily stacked UV islands), later chunks are
halved, and the stat `max_chunk_fill` reports the peak.
"""
from __future__ import annotations

import gpu
import numpy as np

from ..core.errors import BakeInputError
from ..core.bake.estimators import AMBIENT_OCCLUSION
from ..core.bake.plan import BakePlan
from ..core.bake.receivers import Receivers, receivers_at
from ..core.bake.uv_raster import texel_area_points
from ..core.directions import probe_order
from . import util
from .light_view import (LAYERS, RASTER_VARYINGS, LightViewBaker, layer_lists, bind_light_view, depth_prepass, layers_prepass,
                         soup_shader_info)
from .shaders import cached_shader, glsl_source, shader_variants

CHUNK_DIRECTIONS = 16
CHUNK_TARGET = 2.0**12  # expected denominator per texel per chunk, in fixed-point units
# Depth agreement between the two passes (NDC depth in [0, 1]; the depth range spans a few
# normalized units, so this is ~1e-6 of the scene's radius).
DEPTH_TOLERANCE = 2.0**-21
# Largest split of one pixel's UV footprint per axis (8 x 8 sub-splats). Texels more than
# 12 times smaller than a light-view pixel per side may then get no sample in a direction;
# their coverage drops and seam repair treats them as rim texels.
MAX_FOOTPRINT = 8


def _splat_info(uniform: bool, layered: bool, wendland: bool, footprint: bool,
                shading: bool, spread_cos: float = 0.0) -> "gpu.types.GPUShaderCreateInfo":
    info = soup_shader_info("bake_splat", "bake_raster.vert", RASTER_VARYINGS, ('FLOAT', "dummy_out"))
    if shading:
        info.define("SHADING_NORMALS", "1")
    info.image(0, 'R32UI', 'UINT_2D', "accum", qualifiers={'READ', 'WRITE'})
    info.push_constant('FLOAT', "fixed_scale")
    info.push_constant('FLOAT', "depth_tolerance")
    info.define("MAX_FOOTPRINT", str(MAX_FOOTPRINT if footprint else 1))
    if layered:
        info.image(1, 'R32UI', 'UINT_2D', "layer_count", qualifiers={'READ', 'WRITE'})
        info.image(2, 'R32UI', 'UINT_2D_ARRAY', "layer_depth", qualifiers={'READ', 'WRITE'})
        info.push_constant('FLOAT', "depth_span")
        info.push_constant('FLOAT', "max_distance")
        info.push_constant('FLOAT', "min_distance")
        info.define("MAX_DISTANCE", "1")
        info.define("LAYERS", str(LAYERS))
        if wendland:
            info.define("WENDLAND_FALLOFF", "1")
    else:
        info.sampler(0, 'FLOAT_2D', "depth_tex")
    if uniform:
        info.define("UNIFORM_WEIGHTING", "1")
    if spread_cos > 0.0:
        info.define("SPREAD_COS", repr(float(spread_cos)))
    info.fragment_source("layout(early_fragment_tests) in;\n" + glsl_source("bake_common.glsl", "bake_falloff.glsl",
                                                                            "bake_splat.frag"))
    return info


@shader_variants(uniform=(False, True), layered=(False, True), wendland=(False, True),
                 footprint=(False, True), shading=(False, True), spread_cos=(0.0, 0.5))
def splat_shader(uniform: bool, layered: bool, wendland: bool, footprint: bool,
                 shading: bool = False, spread_cos: float = 0.0) -> "gpu.types.GPUShader":
    """shading: weight by interpolated shading normals, with the terminator rule (plan.smooth_shading);
    spread_cos: the spread cone's cut-off (settings.spread_cos; 0: the hemisphere, no variant)."""
    key = ("bake_splat", uniform, layered, wendland, footprint and MAX_FOOTPRINT, shading, spread_cos)
    return cached_shader(key, lambda: _splat_info(uniform, layered, wendland, footprint, shading, spread_cos))


# Points per texel of the scatter's floor check (sample_receivers). One point alone varies with
# the AO across its texel, and the floor's estimate swung by 0.86-1.23x between seeds (Spot at
# 48^2, 4096 directions; with 4, 0.86-0.99); a stratified grid would weigh a texel's partly
# covered cells as whole.
AREA_POINTS = 4


class ScatterBaker(LightViewBaker):
    """Owns the accumulator and the light-view targets of one bake."""

    METHOD = "scatter"
    FRESH_DRAWS = True  # sample_receivers draws new points each time (hao_addon/floor_check.py)

    @classmethod
    def check_limits(cls, plan: BakePlan) -> None:
        """Also refuse an estimator its accumulator cannot hold, declared or not: it packs
        (numerator, denominator) with numerator <= denominator in one word
        (gpu_shaders/bake_common.glsl), the ambient-occlusion estimator's sums only."""
        super().check_limits(plan)
        if plan.estimator is not AMBIENT_OCCLUSION:
            raise BakeInputError(f"the histogram scatter bakes ambient occlusion only, not {plan.estimator.name}; "
                                 f"use the gather (Shadow-Map Gather) or the reference")

    def __init__(self, plan: BakePlan) -> None:
        super().__init__(plan)
        # Each replicate's floor probe first (hao_addon/floor_check.py).
        self.direction_order = np.concatenate(probe_order(len(plan.directions)))

    def sample_receivers(self, cells: np.ndarray, draw: int = 0) -> Receivers:
        """Receivers at `cells` (flat texel indices) whose exact AO has this bake's texel
        values as its mean: its texels are averages over their covered area, so AREA_POINTS
        points a texel, each uniform over that area (core/bake/uv_raster.texel_area_points),
        new ones for each draw. Texels where no point landed on a triangle are left out."""
        plan = self.plan
        cells = np.asarray(cells, np.int64)
        face, bary = texel_area_points(plan.target_uvs, plan.settings.size, cells,
                                       seed=(2 * plan.seed + draw) % 2**31, points=AREA_POINTS)
        found = face >= 0
        return receivers_at(plan.target_positions, plan.target_faces, plan.target_corners,
                            np.repeat(cells, AREA_POINTS)[found.ravel()], face[found], bary[found],
                            plan.lifts_terminator)

    @staticmethod
    def bytes_needed(plan: BakePlan) -> int:
        """The packed accumulator, the view depth and a dummy colour, and for max-distance
        bakes the per-pixel layer lists."""
        side = plan.max_view_side
        layered = plan.layered
        per_pixel = 4 + 4 + (4 + 4 * LAYERS if layered else 0)
        return plan.settings.size**2 * 4 + side * side * per_pixel

    def _allocate(self) -> None:
        plan = self.plan
        settings = plan.settings
        size = settings.size
        side = plan.max_view_side
        self.layered = plan.layered
        self.accum = gpu.types.GPUTexture((size, size), format='R32UI')
        self.accum.clear(format='UINT', value=(0,))
        self.dummy = gpu.types.GPUTexture((side, side), format='R8')
        self.splat_fb = gpu.types.GPUFrameBuffer(color_slots=self.dummy)
        if self.layered:
            # Skip what the scene does not need: only max-distance bakes pay for layer lists.
            self.layer_count = gpu.types.GPUTexture((side, side), format='R32UI')
            self.layer_depth = layer_lists(side)
            self.overflow = gpu.types.GPUTexture((1, 1), format='R32UI')
            self.overflow.clear(format='UINT', value=(0,))
            self.depth = self.depth_fb = None
        else:
            self.depth = gpu.types.GPUTexture((side, side), format='DEPTH_COMPONENT32F')
            self.depth_fb = gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=self.dummy)
            self.layer_count = self.layer_depth = self.overflow = None
        self.splat_prog = splat_shader(settings.weighting == "uniform", self.layered,
                                       plan.layered_falloff == "wendland", plan.needs_footprint_splat,
                                       plan.smooth_shading, settings.spread_cos)
        self.chunk = min(CHUNK_DIRECTIONS, plan.direction_count)
        self.fixed_scale = float(CHUNK_TARGET * plan.direction_count / (4.0 * self.chunk))
        self.num = np.zeros((size, size), dtype=np.float64)
        self.den = np.zeros((size, size), dtype=np.float64)
        self.pending = 0
        self.stats = dict(view_pixels=0, directions_done=0, layered=self.layered, layer_overflow_pixels=0,
                          footprint_splat=plan.needs_footprint_splat, shading_normals=plan.smooth_shading,
                          max_chunk_fill=0.0)

    def _release(self) -> None:
        self.accum = self.depth = self.dummy = None
        self.layer_count = self.layer_depth = self.overflow = None
        self.depth_fb = self.splat_fb = None
        super()._release()

    def run_direction(self, index: int) -> None:
        """Render light view `index` and splat its target fragments into the accumulators."""
        plan = self.plan
        view = self.view(index)
        w, h = view.width, view.height
        # Ignoring back faces: a ray from a texel towards the light meets the back of a face
        # exactly when that face looks towards the light, i.e. faces the light camera. So the
        # pre-pass culls FRONT faces; the splat pass draws only light-facing target faces.
        # Closed surfaces: see plan.depth_map_culls_back_faces.
        culling = 'FRONT' if plan.settings.ignore_back_faces else 'NONE'
        prepass_culling = 'FRONT' if plan.depth_map_culls_back_faces else 'NONE'
        with util.scoped_state():
            gpu.state.blend_set('NONE')
            alpha = self._alpha(index)
            if self.layered:
                layers_prepass(self.splat_fb, self.all_batch, view, culling, self.layer_count, self.layer_depth,
                               self.overflow, alpha)
            else:
                depth_prepass(self.depth_fb, self.all_batch, view, prepass_culling, alpha=alpha)
            with self.splat_fb.bind():
                # Target faces turned away from the light add nothing (cos <= 0, or with shading
                # normals a terminator direction, carried by above_fraction: bake_splat.frag):
                # cull them instead of rasterizing and discarding. Front = counter-clockwise = facing it.
                util.set_overlay_pass_state(w, h, 'BACK')
                shader = self.splat_prog
                bind_light_view(shader, view, plan.settings.size)
                shader.image("accum", self.accum)
                shader.uniform_float("fixed_scale", self.fixed_scale)
                shader.uniform_float("depth_tolerance", DEPTH_TOLERANCE)
                if self.layered:
                    shader.image("layer_count", self.layer_count)
                    shader.image("layer_depth", self.layer_depth)
                    shader.uniform_float("depth_span", view.depth_far - view.depth_near)
                    shader.uniform_float("max_distance", plan.layered_reach)
                    shader.uniform_float("min_distance", plan.min_distance_normalized)
                else:
                    shader.uniform_sampler("depth_tex", self.depth)
                self.target_batch.draw(shader)
        self.stats["view_pixels"] += w * h
        self.stats["directions_done"] += 1
        self.pending += 1
        if self.pending >= self.chunk:
            self.flush()

    def flush(self) -> None:
        """Move the integer accumulators into the float64 sums and clear them."""
        if self.pending:
            # Fragment image atomics are not ordered with later reads by the framebuffer
            # rules; an empty dispatch issues the image/texture-fetch barrier first.
            util.image_barrier()
            packed = util.texture_to_numpy(self.accum, np.uint32)
            self.accum.clear(format='UINT', value=(0,))
            den = packed >> 16
            fill = float(den.max()) / 65535.0
            self.stats["max_chunk_fill"] = max(self.stats["max_chunk_fill"], fill)
            if fill > 0.5 and self.chunk > 1:
                self.chunk //= 2  # stacked UV islands: keep later chunks far from overflow
            self.den += den.astype(np.float64) / self.fixed_scale
            self.num += (packed & 0xFFFF).astype(np.float64) / self.fixed_scale
            self.pending = 0

    def restart(self) -> None:
        """Zero the sums (after accumulated()): the next directions are summed apart."""
        self.flush()
        self.num[:] = 0.0
        self.den[:] = 0.0

    def accumulated(self) -> np.ndarray:
        """(size, size, 2) float64: the ambient-occlusion estimator's sums (numerator, weight)
        over the directions so far."""
        self.flush()
        if self.layered:  # pixels whose depth list overflowed, counted over the whole bake
            self.stats["layer_overflow_pixels"] = int(util.texture_to_numpy(self.overflow, np.uint32).ravel()[0])
        return np.stack([self.num, self.den], axis=-1)
