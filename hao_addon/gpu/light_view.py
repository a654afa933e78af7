# SPDX-License-Identifier: GPL-3.0-or-later
"""Pieces shared by both bakers: the triangle-soup shader interface, the soup batch, and the
light-view depth pre-pass."""
from __future__ import annotations

import gpu
import numpy as np

from ..core.bake.plan import BakePlan
from ..core.bake.views import OrthoView
from . import util
from .shaders import cached_shader, glsl_source, shader_variants


def soup_shader_info(name: str, vertex_file: str, varyings: tuple[tuple[str, str, str], ...],
                     fragment_out: tuple[str, str]) -> "gpu.types.GPUShaderCreateInfo":
    """Create-info for a shader drawing a plan batch (pos, uv, face per vertex) from a light
    view: push constants view_proj, omega, tex_size; varyings as (mode, type, name) with mode
    'smooth' or 'flat'; one fragment output (type, name)."""
    iface = gpu.types.GPUStageInterfaceInfo(f"hao_{name}_iface")
    for mode, typ, var in varyings:
        getattr(iface, mode)(typ, var)
    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, 'VEC3', "pos")
    info.vertex_in(1, 'VEC2', "uv")
    info.vertex_in(2, 'VEC4', "face")
    info.vertex_in(3, 'FLOAT', "above")
    info.vertex_out(iface)
    info.push_constant('MAT4', "view_proj")
    info.push_constant('VEC4', "omega")
    info.push_constant('VEC2', "tex_size")
    info.fragment_out(0, *fragment_out)
    info.vertex_source(glsl_source(vertex_file))
    return info


# face_data: the shading normal (not unit length between corners) and 1 / S, interpolated;
# above_fraction: plan.target_above, interpolated.
RASTER_VARYINGS = (('smooth', 'VEC2', "uv_texel"), ('smooth', 'VEC4', "face_data"),
                   ('smooth', 'FLOAT', "above_fraction"))


# Depth layers kept per light-view pixel for max-distance bakes. A ray through a closed mesh
# crosses an even number of surfaces; 16 holds eight nested shells. Overflow is counted.
LAYERS = 16


def layer_lists(side: int) -> "gpu.types.GPUTexture":
    """The (side, side) pixels' depth lists, LAYERS deep: a 2D array texture, whose sides may
    reach the GPU's 2D limit (a 3D texture's are lower: 2048 on Mesa's OpenGL, where a
    1024^2 max-distance bake's views of 2053 pixels failed)."""
    return gpu.types.GPUTexture((side, side), layers=LAYERS, format='R32UI')


def _layers_info() -> "gpu.types.GPUShaderCreateInfo":
    info = soup_shader_info("bake_layers", "bake_raster.vert", RASTER_VARYINGS, ('FLOAT', "dummy_out"))
    info.image(0, 'R32UI', 'UINT_2D', "layer_count", qualifiers={'READ', 'WRITE'})
    info.image(1, 'R32UI', 'UINT_2D_ARRAY', "layer_depth", qualifiers={'READ', 'WRITE'})
    info.image(2, 'R32UI', 'UINT_2D', "overflow", qualifiers={'READ', 'WRITE'})
    info.define("LAYERS", str(LAYERS))
    info.fragment_source(glsl_source("bake_layers.frag"))
    return info


@shader_variants()
def layers_shader() -> "gpu.types.GPUShader":
    return cached_shader(("bake_layers", LAYERS), _layers_info)


def layers_prepass(framebuffer, batch, view: OrthoView, culling: str, count, depth, overflow,
                   alpha: tuple[AlphaPass, int] | None = None) -> None:
    """The depth of every fragment of `batch` into per-pixel lists (count (side, side) and
    depth (side, side) x LAYERS R32UI images (layer_lists); overflow counts pixels with more than LAYERS):
    what max-distance bakes search for the occluder nearest to a receiver. Call inside
    util.scoped_state(); the lists are ready for imageLoad when it returns."""
    count.clear(format='UINT', value=(0,))
    view, window = drawn_view(view)
    with framebuffer.bind():
        util.set_overlay_pass_state(view.width, view.height, culling)
        gpu.state.scissor_set(*window)
        gpu.state.scissor_test_set(True)
        shader = layers_shader() if alpha is None else alpha_shader(layered=True)
        bind_light_view(shader, view, 0, prepass=True)
        if alpha is not None:  # batch: an alpha_batch; alpha: (its pass, the direction's seed)
            alpha[0].bind(shader, alpha[1])
        shader.image("layer_count", count)
        shader.image("layer_depth", depth)
        shader.image("overflow", overflow)
        batch.draw(shader)
        gpu.state.scissor_test_set(False)
    util.image_barrier()


def _depth_info() -> "gpu.types.GPUShaderCreateInfo":
    info = soup_shader_info("bake_depth", "bake_raster.vert", RASTER_VARYINGS, ('FLOAT', "dummy_out"))
    info.fragment_source(glsl_source("bake_depth.frag"))
    return info


@shader_variants()
def depth_shader() -> "gpu.types.GPUShader":
    return cached_shader(("bake_depth",), _depth_info)


def _depth_positions_info() -> "gpu.types.GPUShaderCreateInfo":
    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, 'VEC3', "pos")
    info.push_constant('MAT4', "view_proj")
    info.fragment_out(0, 'FLOAT', "dummy_out")
    info.vertex_source(glsl_source("bake_depth_positions.vert"))
    info.fragment_source(glsl_source("bake_depth.frag"))
    return info


@shader_variants()
def depth_positions_shader() -> "gpu.types.GPUShader":
    """Depth-only drawing of a positions_batch."""
    return cached_shader(("bake_depth_positions",), _depth_positions_info)


def _alpha_info(fragment: str, layered: bool) -> "gpu.types.GPUShaderCreateInfo":
    """A depth (or, layered, depth-list) pass over an alpha_batch: fragments that the light
    passes (core/bake/alpha.py) are left out."""
    iface = gpu.types.GPUStageInterfaceInfo("hao_bake_alpha_iface")
    iface.smooth('VEC2', "alpha_uv_v")
    iface.flat('VEC2', "alpha_face_v")
    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, 'VEC3', "pos")
    info.vertex_in(1, 'VEC2', "alpha_uv")
    info.vertex_in(2, 'VEC2', "alpha_face")
    info.vertex_out(iface)
    info.push_constant('MAT4', "view_proj")
    info.push_constant('FLOAT', "alpha_seed")
    info.push_constant('FLOAT', "alpha_clip")
    info.sampler(0, 'FLOAT_2D_ARRAY', "alpha_tex")
    info.fragment_out(0, 'FLOAT', "dummy_out")
    info.define("ALPHA")
    if layered:
        info.image(0, 'R32UI', 'UINT_2D', "layer_count", qualifiers={'READ', 'WRITE'})
        info.image(1, 'R32UI', 'UINT_2D_ARRAY', "layer_depth", qualifiers={'READ', 'WRITE'})
        info.image(2, 'R32UI', 'UINT_2D', "overflow", qualifiers={'READ', 'WRITE'})
        info.define("LAYERS", str(LAYERS))
    info.vertex_source(glsl_source("bake_alpha.vert"))
    info.fragment_source(glsl_source("pcg3d.glsl", "bake_alpha.glsl", fragment))
    return info


@shader_variants(layered=(False, True))
def alpha_shader(layered: bool) -> "gpu.types.GPUShader":
    """The depth pass (or, layered, the depth-list pass) that leaves out what the light passes."""
    if layered:
        return cached_shader(("bake_layers_alpha", LAYERS), lambda: _alpha_info("bake_layers.frag", True))
    return cached_shader(("bake_depth_alpha",), lambda: _alpha_info("bake_depth.frag", False))


def alpha_batch(plan: BakePlan) -> "gpu.types.GPUBatch":
    """Everything the light views draw (plan.drawn_positions) with each face's alpha: its UVs
    and (constant alpha, image layer) per corner (plan.alpha)."""
    alpha = plan.alpha
    face = np.stack([alpha.constant, alpha.layer.astype(np.float32)], axis=1)
    return util.make_batch('TRIS', {"pos": ('F32', plan.drawn_positions.reshape(-1, 3)),
                                    "alpha_uv": ('F32', alpha.uvs.reshape(-1, 2)),
                                    "alpha_face": ('F32', np.repeat(face, 3, axis=0))})


class AlphaPass:
    """The GPU side of plan.alpha: its images as one array texture, bound with a direction's
    seed to the depth passes."""

    def __init__(self, plan: BakePlan) -> None:
        alpha = plan.alpha
        layers, side = alpha.images.shape[0], alpha.images.shape[1]
        data = gpu.types.Buffer('FLOAT', layers * side * side, np.ascontiguousarray(alpha.images, np.float32).ravel())
        self.texture = gpu.types.GPUTexture((side, side), layers=layers, format='R32F', data=data)
        self.clip = alpha.clip if alpha.mode == "clip" else -1.0

    def bind(self, shader, seed: int) -> None:
        shader.uniform_sampler("alpha_tex", self.texture)
        shader.uniform_float("alpha_seed", float(seed))
        shader.uniform_float("alpha_clip", float(self.clip))

    def free(self) -> None:
        self.texture = None


def positions_batch(positions: np.ndarray) -> "gpu.types.GPUBatch":
    """Triangle-soup batch of positions (F, 3, 3) alone (attribute "pos")."""
    return util.make_batch('TRIS', {"pos": ('F32', positions.reshape(-1, 3))})


def plan_batch(plan: BakePlan, with_occluders: bool, order: np.ndarray | None = None,
               face_bins: np.ndarray | None = None, lift_corners: bool = False) -> "gpu.types.GPUBatch":
    """Triangle-soup batch of the target, optionally followed by the occluders (1/S_f = 0)
    (plan.drawn_positions: the occluders alone in Selected to Active).
    Attributes "face" and "above" are per corner: the shading normal and 1 / S
    (plan.target_corners) and the above-face fraction (plan.target_above).
    order: (F,) face permutation of that list to draw in, or None; face_bins: (F,) target
    face normal bins, added as the float attribute "bin" with the face normal as
    "geometric", each corner's face corners and barycentric unit vector
    (gather_shaders.FACE_ATTRIBUTES; target alone only); lift_corners: with them, each corner also
    carries its face's shading normals (the texel list's terminator lift,
    gather_shaders.LIFT_ATTRIBUTES)."""
    # Selected to Active: the target is not drawn with the occluders (plan.target_drawn).
    ft = len(plan.target_positions) if plan.target_drawn or not with_occluders else 0
    fo = len(plan.occluder_positions) if with_occluders else 0
    pos = np.concatenate([plan.target_positions[:ft], plan.occluder_positions[:fo]])
    uv = np.concatenate([plan.target_uvs[:ft], np.zeros((fo, 3, 2), np.float32)])
    occ_face = np.concatenate([plan.occluder_normals[:fo], np.zeros((fo, 1), np.float32)], axis=1)
    face = np.concatenate([plan.target_corners[:ft], np.repeat(occ_face[:, None, :], 3, axis=1)])
    above = np.concatenate([plan.target_above[:ft], np.zeros((fo, 3), np.float32)])
    assert len(pos) == ft + fo
    if order is not None:
        pos, uv, face, above = pos[order], uv[order], face[order], above[order]
    attrs = {"pos": ('F32', pos.reshape(-1, 3)), "uv": ('F32', uv.reshape(-1, 2)),
             "face": ('F32', face.reshape(-1, 4)), "above": ('F32', above.reshape(-1))}
    if face_bins is not None:
        assert fo == 0 and order is None
        attrs["bin"] = ('F32', np.repeat(np.asarray(face_bins, np.float32), 3))
        attrs["geometric"] = ('F32', np.repeat(plan.target_faces[:, :3], 3, axis=0))
        for k in range(3):
            attrs[f"tri_v{k}"] = ('F32', np.repeat(plan.target_positions[:, k], 3, axis=0))
        attrs["corner_bary"] = ('F32', np.tile(np.eye(3, dtype=np.float32), (len(pos), 1)))
        if lift_corners:
            for k in range(3):
                attrs[f"tri_n{k}"] = ('F32', np.repeat(plan.target_corners[:, k, :3], 3, axis=0))
    return util.make_batch('TRIS', attrs)


def bind_light_view(shader, view: OrthoView, map_size: int, prepass: bool = False) -> None:
    """Bind `shader` and set the light-view push constants of soup_shader_info. Pre-pass
    programs use only view_proj (their compilers drop the others, and setting a dropped
    uniform raises)."""
    shader.bind()
    shader.uniform_float("view_proj", view.matrix.T.ravel())  # column-major for GLSL
    if not prepass:
        shader.uniform_float("omega", (*view.omega, 0.0))
        shader.uniform_float("tex_size", (map_size, map_size))


def drawn_view(view: OrthoView) -> tuple[OrthoView, tuple[int, int, int, int]]:
    """(the view to draw, the window (x, y, width, height) of its pixels to draw) of a light
    view's depth map: a view cropped from a whole one (OrthoView.whole) draws the whole view
    scissored to the crop: the whole bake's rasterization, pixel for pixel (the crop's own
    matrix, or the whole's through an offset viewport, rounded differently on llvmpipe: 10 of
    52k re-baked texels changed by up to 0.01 at 2048^2, 256 directions)."""
    if view.whole is None:
        return view, (0, 0, view.width, view.height)
    return view.whole, (*view.first, view.width, view.height)


def depth_prepass(framebuffer, batch, view: OrthoView, culling: str,
                  averted_runs: list[tuple[int, int]] = (), facing=None, positions_only: bool = False,
                  alpha: tuple[AlphaPass, int] | None = None) -> None:
    """Clear the view's sub-rectangle and draw `batch` depth-only from the light (a
    positions_batch where positions_only, else a plan_batch: its attributes only cost).

    averted_runs: (first face, face count) runs of `batch` whose faces turned away from the
    light are drawn as well, after the whole batch with `culling` (see GatherBaker).
    facing: (positions_batch, (first face, end face) runs) drawn with `culling` instead of the
    whole of `batch`: the same faces in another order, of which only the runs can pass that
    culling (core/bake/normal_bins.FaceBins).
    Colour writes are masked: llvmpipe then runs its depth-only path. (Never mask colour in
    passes with image atomics: llvmpipe then skips their fragment shaders, side effects and
    all.) Call inside util.scoped_state()."""
    view, window = drawn_view(view)
    shader = depth_positions_shader() if positions_only else depth_shader()
    if alpha is not None:  # batch: an alpha_batch (no facing runs); alpha: (its pass, the direction's seed)
        shader = alpha_shader(layered=False)
    with framebuffer.bind():
        fb = gpu.state.active_framebuffer_get()
        gpu.state.viewport_set(0, 0, view.width, view.height)
        gpu.state.scissor_set(*window)  # a crop draws its window alone
        gpu.state.scissor_test_set(True)
        fb.clear(depth=1.0)  # the colour target is never written (masked) nor read
        gpu.state.depth_test_set('LESS')
        gpu.state.depth_mask_set(True)
        gpu.state.face_culling_set(culling)
        gpu.state.color_mask_set(False, False, False, False)
        if facing is None:
            bind_light_view(shader, view, 0, prepass=True)
            if alpha is not None:
                alpha[0].bind(shader, alpha[1])
            batch.draw(shader)
        else:
            positions_shader = depth_positions_shader()
            bind_light_view(positions_shader, view, 0, prepass=True)
            _draw_runs(facing[0], positions_shader, facing[1])
            if averted_runs and shader is not positions_shader:
                bind_light_view(shader, view, 0, prepass=True)
        if averted_runs:
            gpu.state.face_culling_set('FRONT')  # front = counter-clockwise = facing the light
            if hasattr(batch, "draw_range"):
                for first, count in averted_runs:
                    batch.draw_range(shader, elem_start=3 * first, elem_count=3 * count)
            else:  # a Blender without GPUBatch.draw_range: every averted face, still exact
                batch.draw(shader)
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.scissor_test_set(False)


def _draw_runs(batch, shader, runs: list[tuple[int, int]]) -> None:
    """Draw the (first face, end face) runs of batch (all of it on a Blender without draw_range)."""
    if not hasattr(batch, "draw_range"):
        batch.draw(shader)
        return
    for first, end in runs:
        batch.draw_range(shader, elem_start=3 * first, elem_count=3 * (end - first))


VIEW_PREFETCH = 16


class LightViewBaker(util.GPUPass):
    """Base of the bake passes: owns the plan's batches (target alone, target + occluders)
    and checks GPU limits before anything is allocated. Subclasses define bytes_needed and
    _allocate; if allocation fails part-way, what was made is freed before the error leaves."""

    @staticmethod
    def bytes_needed(plan: BakePlan) -> int:
        raise NotImplementedError

    METHOD = ""  # the bake method's name (core/bake/abilities.py declares what it can bake)
    # Whether sample_receivers draws new points each call (the floor check's two replicates).
    FRESH_DRAWS = False

    @classmethod
    def check_limits(cls, plan: BakePlan) -> None:
        """Refuse what the method cannot bake, or what exceeds the GPU's textures or memory."""
        plan.check_method(cls.METHOD)
        util.check_texture_limits(plan.settings.size, plan.max_view_side, cls.bytes_needed(plan))

    def __init__(self, plan: BakePlan) -> None:
        super().__init__()
        self.plan = plan
        self._views: dict[int, OrthoView] = {}
        # Direction of each step (run_direction(step)); subclasses may reorder.
        self.direction_order = np.arange(plan.direction_count)
        self.alpha_pass = None
        try:
            order = self._draw_order()
            if plan.alpha is not None:  # what lets light through: every face, with its alpha (no holes: in order)
                self.alpha_pass = AlphaPass(plan)
                self.all_batch = alpha_batch(plan)
            else:
                self.all_batch = self._light_view_batch(order)
            self.target_batch = self._target_batch()
            self._allocate()
        except BaseException:
            self.free()
            raise

    def _draw_order(self) -> np.ndarray | None:
        """(F,) permutation of target + occluder faces for the light-view batch, or None."""
        return None

    def _light_view_batch(self, order: np.ndarray | None) -> "gpu.types.GPUBatch":
        """What the light views draw (all_batch): target and occluders with their raster
        attributes (plan_batch), in `order`."""
        return plan_batch(self.plan, with_occluders=True, order=order)

    def _alpha(self, index: int) -> tuple[AlphaPass, int] | None:
        """What the depth passes of direction `index` need to leave out what the light passes
        (None where nothing lets light through: the plain passes, counted)."""
        if self.plan.alpha is None:
            self.stats["alpha_passes_skipped"] = self.stats.get("alpha_passes_skipped", 0) + 1
            return None
        self.stats["alpha_passes"] = self.stats.get("alpha_passes", 0) + 1
        return self.alpha_pass, index

    def _target_batch(self) -> "gpu.types.GPUBatch":
        return plan_batch(self.plan, with_occluders=False)

    def view(self, step: int) -> OrthoView:
        """The light view of step `step` (direction direction_order[step]), fitted
        VIEW_PREFETCH steps at a time (plan.views): per view, numpy's call overhead was most
        of the fit's 0.5 ms on the bunny."""
        if step not in self._views:
            steps = list(range(step, min(step + VIEW_PREFETCH, self.plan.direction_count)))
            fitted = self.plan.views([int(self.direction_order[s]) for s in steps])
            self._views = dict(zip(steps, fitted))
            self._views_fitted(steps, fitted)
        return self._views[step]

    def _views_fitted(self, steps: list[int], views: list[OrthoView]) -> None:
        """Hook: per-view work that is cheaper for a batch of views (called from view())."""

    def _allocate(self) -> None:
        raise NotImplementedError

    def _release(self) -> None:
        """Subclasses drop their own textures and framebuffers, then call this."""
        self.all_batch = self.target_batch = None
        if self.alpha_pass is not None:
            self.alpha_pass.free()
            self.alpha_pass = None
