# SPDX-License-Identifier: GPL-3.0-or-later
"""The shadow-map gather baseline that McGraw & Sowers compare against (their Table 1, ATI's
GPU MeshMapper): per direction render a depth map from the light, then test every texel
centre of the target against it.

Same interface as ScatterBaker. Differences a user sees: point samples (the texel centre, or
the sub-texel and Selected-to-Active receivers of core/bake/receivers.py; no area average, no
stretch correction needed), shadow-map resolution (the receiver-plane depth test allows half
a light-view pixel of depth and a quarter pixel of the receiver plane's slope, so occluders
thinner than that are missed), Cycles' terminator offset (the scatter ignores it). With a
max distance each view's
depth map becomes per-pixel depth lists (the scatter's, light_view.layers_prepass), and a
receiver's nearest occluder towards the light is the deepest entry in front of it.

The target is rasterized in UV space once per bake, into a compact texel list (surface point,
face, texel of every covered texel centre), or a CPU receiver list is uploaded as that list,
and the directions' tests are compute passes over it. Rasterizing the target in UV space
again for every direction gives the same fragments, but on llvmpipe a draw's per-triangle cost (about 0.25 us, even for triangles
that are clipped away) made it half of each direction's time on a 70k-triangle mesh.
The list is stored by normal bin, and each dispatch tests up to four nearby directions over the
bins that can face them (core/bake/normal_bins.py).
Sums are float32 per entry in a fixed direction order (deterministic), float64 per texel at the end.
"""
from __future__ import annotations

import math

import gpu
import numpy as np

from ..core.bake.entry_blocks import block_runs, intersected_runs
from ..core.bake.interleave import class_pixel_scale
from ..core.bake.face_chunks import (boxes_meeting_windows, face_chunks, hole_chunk_ranges_many,
                                      window_chunk_ranges_many)
from ..core.bake.normal_bins import (BIN_COUNT, FaceBins, bin_cones, bin_runs, bins_facing, cell_cones,
                                     normal_bins, octahedral_decode, proximity_order)
from ..core.directions import probe_order
from ..core.bake.estimators import texel_sums
from ..core.bake.plan import BakePlan
from ..core.bake.probe_snapshot import EntrySnapshot
from ..core.bake.receivers import Receivers
from . import util
from .gather_difference import SceneBefore, runs_within, window_arrays
from .gather_texel_list import TexelList, entry_bytes, faces_reaching_cells
from .light_view import LAYERS, LightViewBaker, layer_lists, depth_prepass, layers_prepass, plan_batch, positions_batch
from .gather_shaders import (ACCUM_FORMATS, ACCUM_NAMES, FORMAT_CHANNELS, GATHER_MAX_VIEWS, GATHER_VIEWS_DTYPE,
                             GROUP_SIZE, LIST_WIDTH, gather_shader)

# Directions tested per compute dispatch: an entry and its sums are loaded once for all of
# them. On the smooth bunny (llvmpipe) an entry's loads, decodes and store cost about twice
# one facing direction's test: one direction per dispatch spent 3.4 ms per direction on texel
# tests, 4 per dispatch ~1.5 ms. At 64 directions 4, 8 and 16 per dispatch invoke 7.5M, 4.2M
# and 2.3M entries (the union of a batch's hemispheres grows slowly: batches are nearby
# directions) and the bake takes 1.56, 1.44 and 1.33 s (medians of 4, one process). Each needs
# its own depth map, so a batch holds at most DEPTH_BATCH_BYTES of them: 16 views up to
# 1024^2 pixels, 4 at 2048^2, 1 beyond. Each is a sampler of the compute shader, and OpenGL
# guarantees 16 of those (GL_MAX_COMPUTE_TEXTURE_IMAGE_UNITS).
VIEWS_PER_DISPATCH = 16
DEPTH_BATCH_BYTES = 64 << 20
# Dispatch only the entries of normal bins that can face a view, and draw into a depth map
# culling one side of the faces only the bins that side can be in (False: every entry and
# face; the results are the same, tests/test_bake_analytic.py).
NORMAL_BINNING = True
# Texel centres of the target's own UVs are listed by a UV-space raster on the GPU (the fast
# path); sub-texel samples and Selected-to-Active receivers are made on the CPU
# (core/bake/receivers.py) and uploaded. False: upload in every case (tests compare the two).
GPU_TEXEL_LIST = True


def cpu_receivers(plan: BakePlan) -> Receivers | None:
    """The receivers the gather uploads, or None where its GPU raster lists them (a run of
    some cells keeps the raster's entries in them: a cell's sample points are then the whole
    bake's, where a CPU raster may put a point on a shared UV edge into the other face)."""
    if plan.layout.gpu_lists_receivers and GPU_TEXEL_LIST:
        return None
    return plan.receivers()


def views_per_dispatch(plan: BakePlan) -> int:
    """Directions tested per dispatch: as many depth maps as DEPTH_BATCH_BYTES holds, at most
    VIEWS_PER_DISPATCH, and the bake's directions in batches of equal size (a short last
    batch is padded, and on llvmpipe a padded slot costs about half a direction's test).
    Max-distance bakes test one direction per dispatch (each needs its per-pixel depth
    lists, LAYERS deep, which are too large to keep several of)."""
    assert VIEWS_PER_DISPATCH <= GATHER_MAX_VIEWS
    if plan.layered:
        return 1
    # With texel classes (core/bake/interleave.py) as many as the views would be without them:
    # their coarser views would fit more, but a class's directions lie further apart, and a
    # batch of them faces more bins (the floor under a ball, 1024^2: 3 a dispatch 4.6 s, 15
    # 5.1 s; Spot: 8 5.4 s, 16 6.2 s, as without classes).
    side = plan.max_view_side * class_pixel_scale(plan.classes)
    most = int(np.clip(DEPTH_BATCH_BYTES // (4 * side**2), 1, VIEWS_PER_DISPATCH))
    if plan.before_drawn is not None:  # a re-bake by difference: each direction's maps before and after
        return 2 * max(1, most // 2)
    directions = max(1, plan.direction_count // plan.classes)  # a dispatch's views serve one texel class
    batches = math.ceil(directions / most)
    return math.ceil(directions / batches)


class GatherBaker(TexelList, SceneBefore, LightViewBaker):
    """Owns the depth map, the texel list and its accumulators for one bake."""

    METHOD = "gather"

    @staticmethod
    def bytes_needed(plan: BakePlan) -> int:
        """Texel list at one entry per texel (re-checked once the exact count is known),
        the UV-space target of the list pass, and the view depth."""
        side = plan.max_view_side
        entries = plan.settings.size**2 * plan.settings.sample_count
        per_pixel = 1 + (4 + 4 * LAYERS if plan.layered else 4 * views_per_dispatch(plan))
        return entries * (entry_bytes(plan) + 1) + side * side * per_pixel

    def _allocate(self) -> None:
        plan = self.plan
        side = plan.max_view_side
        self.dummy = gpu.types.GPUTexture((side, side), format='R8')
        self.layered = plan.layered
        self.slots = views_per_dispatch(plan)
        if self.layered:
            # Max distance: the occluder nearest to each receiver, from per-pixel depth lists.
            self.layer_count = gpu.types.GPUTexture((side, side), format='R32UI')
            self.layer_depth = layer_lists(side)
            self.overflow = gpu.types.GPUTexture((1, 1), format='R32UI')
            self.overflow.clear(format='UINT', value=(0,))
            self.layers_fb = gpu.types.GPUFrameBuffer(color_slots=self.dummy)
            self.depths, self.depth_fbs = [], []
        else:
            # One depth map per direction of a dispatch; they share the (never written) colour target.
            self.layer_count = self.layer_depth = self.overflow = self.layers_fb = None
            # Depth maps culling one side of the faces draw only the bins that side can be in.
            self.face_bins = FaceBins.of(plan.drawn_normals)
            self.facing_batch = positions_batch(plan.drawn_positions[self.face_bins.order])
            self.depths = [gpu.types.GPUTexture((side, side), format='DEPTH_COMPONENT32F')
                           for _ in range(self.slots)]
            self.depth_fbs = [gpu.types.GPUFrameBuffer(depth_slot=depth, color_slots=self.dummy)
                              for depth in self.depths]
        self.pending: list = []  # views rendered into depths[:len(pending)], not yet tested
        self.pending_signs: list[float] = []  # each pending view's: -1 the scene before an edit
        self.pending_class = 0  # the texel class the pending views serve (core/bake/interleave.py)
        # GatherViews: one buffer per bake, rewritten before each dispatch.
        self.views_data = np.zeros(1, GATHER_VIEWS_DTYPE)
        self.views_block = gpu.types.GPUUniformBuf(self.views_data.view(np.float32))
        # Batches of nearby directions face nearly the same normal bins (core/bake/normal_bins.py),
        # each replicate in its own order, one after the other (they are accumulated apart), its
        # floor probe's directions first (core/directions.probe_order).
        # With texel classes (core/bake/interleave.py) a part's directions go class by class:
        # a dispatch tests one class's entries against its views.
        self.direction_order = np.concatenate([part[np.lexsort((np.argsort(proximity_order(plan.directions[part])),
                                                                self.served_classes(part)))]
                                               for part in probe_order(len(plan.directions))])
        # Uploaded entries always hold both normals (_upload_texel_list).
        self.shading_layout = self.plan.smooth_shading or self.receivers is not None
        self.lifted = self.plan.lifts_terminator and (self.receivers is None or self.receivers.lift is not None)
        self.entry_blocks = None  # (B, 2, 3) boxes of the entries' blocks (views cropped to spheres)
        self._build_texel_list()
        self.stats = dict(cpu_receivers=self.receivers is not None, view_pixels=0, directions_done=0,
                          texel_list_entries=self.entry_count, depth_faces_drawn=0, depth_faces_skipped=0,
                          averted_faces_drawn=0, averted_faces_skipped=0,
                          window_faces_drawn=0, window_faces_skipped=0,
                          views_per_dispatch=self.slots, texel_tests=0, texel_tests_skipped=0,
                          layered=self.layered, layer_overflow_pixels=0,
                          shading_normals=self.plan.smooth_shading, terminator_lift=self.lifted)

    def _draw_order(self) -> np.ndarray | None:
        """Light views draw light-facing faces, plus averted ones only near holes: in Morton
        order, so that those are a few runs (core/bake/face_chunks.py)."""
        plan = self.plan
        self.chunks = self.window_chunks = None
        self.hole_runs: dict[int, list[tuple[int, int]]] = {}
        self.window_runs: dict[int, list[tuple[int, int]]] = {}
        self._before_setup()
        if plan.holes is None:
            if plan.cells is None or plan.layered or plan.alpha is not None:
                return None
            # A run of some cells draws each view in its window alone: the chunks there.
            self.window_chunks = face_chunks(plan.drawn_positions)
            return self.window_chunks.order
        self.chunks = face_chunks(plan.drawn_positions)
        if plan.cells is not None and not plan.layered:  # a window's faces: the same chunks
            self.window_chunks = self.chunks
        return self.chunks.order

    def _light_view_batch(self, order: np.ndarray | None) -> "gpu.types.GPUBatch":
        """Depth maps need the positions alone (a plan_batch's other attributes made llvmpipe
        set up their interpolation for every averted face drawn); depth lists (max distance)
        the plan_batch."""
        if self.plan.layered:
            return super()._light_view_batch(order)
        positions = self.plan.drawn_positions
        return positions_batch(positions if order is None else positions[order])

    def _target_batch(self) -> "gpu.types.GPUBatch | None":
        """The target with each face's normal bin, and the cones of the bins' normals (None
        when the receivers are uploaded: cpu_receivers)."""
        self.receivers = cpu_receivers(self.plan)
        if self.receivers is not None:
            return None
        plan = self.plan if self.plan.cells is None else faces_reaching_cells(self.plan)
        faces = plan.target_faces
        bins = normal_bins(faces[:, :3])
        if self.plan.smooth_shading:
            # An entry weighs in wherever its shading normal faces the light: the texel list
            # bins each entry by that normal, so its bin's cone is the octahedral cell's.
            self.bin_axis, self.bin_threshold = cell_cones()
        else:
            self.bin_axis, self.bin_threshold = bin_cones(faces[:, :3], bins, faces[:, 3] > 0.0)
        return plan_batch(plan, with_occluders=False, face_bins=bins, lift_corners=plan.lifts_terminator)

    def _views_fitted(self, indices: list[int], views: list) -> None:
        """Hole runs (core/bake/face_chunks.py) of a batch of views, found together."""
        self.hole_runs = {}
        if self.chunks is not None and not self.plan.settings.ignore_back_faces:
            runs = hole_chunk_ranges_many(self.chunks, self.plan.holes, np.stack([v.matrix for v in views]),
                                          len(self.chunks.order))
            self.hole_runs = dict(zip(indices, runs))
        self.window_runs = {}
        cropped = [(index, view) for index, view in zip(indices, views) if view.whole is not None]
        if self.window_chunks is not None and cropped:
            runs = window_chunk_ranges_many(self.window_chunks, *window_arrays([v for _, v in cropped]),
                                            len(self.window_chunks.order))
            self.window_runs = {index: [(first, first + count) for first, count in run]
                                for (index, _), run in zip(cropped, runs)}
            self._before_fitted([index for index, _ in cropped], [v for _, v in cropped])

    def served_classes(self, directions: np.ndarray) -> np.ndarray:
        """(k,) the texel class that directions (k,) (indices into plan.directions) serve."""
        return self.plan.direction_class[directions]

    def _entry_runs(self, omegas: np.ndarray, texel_class: int = 0) -> list[tuple[int, int]]:
        """(first entry, end entry) runs of the bins of `texel_class` that can face one of
        omegas (k, 3)."""
        if NORMAL_BINNING:
            needed = bins_facing(self.bin_axis, self.bin_threshold, omegas)
        else:
            needed = np.ones(BIN_COUNT, bool)
        first = BIN_COUNT * texel_class
        return bin_runs(needed, self.bin_first[first:first + BIN_COUNT + 1])

    def _tested_runs(self, views: list) -> list[tuple[int, int]]:
        """(first entry, end entry) runs a dispatch of views tests: of the bins that can face
        one of them, and of views cropped to spheres only the blocks their windows reach."""
        runs = self._entry_runs(np.array([view.omega for view in views]), self.pending_class)
        if self.entry_blocks is None:
            return runs
        meets = boxes_meeting_windows(self.entry_blocks, *window_arrays(views))
        return intersected_runs(runs, block_runs(meets.any(axis=0), self.entry_count))

    def sample_receivers(self, cells: np.ndarray, draw: int = 0) -> Receivers:
        """The list's receivers at `cells` (flat texel indices): this bake's own sample points,
        where its rasterizer put them (on a UV edge shared by two faces it may pick the other
        face than the CPU's raster, core/bake/uv_raster.py; both are points of the surface).
        The same for every draw: its texels are these points."""
        if self.receivers is not None:
            receivers = self.receivers.subset(self.receivers.inv_s > 0.0)
            return receivers.subset(np.isin(receivers.texel, cells))
        n = self.entry_count
        flat = self._entry_cells()
        wanted = np.zeros(int(np.prod(self.plan.output_shape)), bool)
        wanted[cells] = True
        keep = wanted[flat]
        position = util.texture_to_numpy(self.entry_position, np.float32).reshape(-1, 4)[:n][keep].astype(np.float64)
        normal = util.texture_to_numpy(self.entry_normal, np.float32).reshape(-1, 4)[:n][keep].astype(np.float64)
        if self.shading_layout:
            shading, geometric = octahedral_decode(normal[:, :2]), octahedral_decode(normal[:, 2:])
        else:
            shading = geometric = normal[:, :3]
        lift = None
        if self.lifted:
            lift = util.texture_to_numpy(self.entry_lift, np.float32).reshape(-1, 4)[:n][keep, :3].astype(np.float64)
        return Receivers(position[:, :3], geometric, shading, position[:, 3], flat[keep].astype(np.int64), lift)

    def at_risk_cells(self) -> np.ndarray:
        """(k,) sorted flat texel indices with an entry whose shading normal points against its
        face (most of its hemisphere below the surface, each such direction tested from a
        terminator lift or counted occluded): rare, and there the depth maps can miss what an
        exact ray finds (the bunny at 128^2, smooth: its one such texel read 0.92 where the
        exact AO is 0). The floor check checks each of them (floor_check.floor_sample)."""
        if self.receivers is not None:
            r = self.receivers
            inverted = np.einsum("ij,ij->i", r.shading, r.geometric) < 0.0
            return np.unique(r.texel[inverted & (r.inv_s > 0.0)])
        corners, faces = self.plan.target_corners[..., :3], self.plan.target_faces[:, None, :3]
        # A texel's normal is a convex blend of its face's corners': none at risk unless a corner
        # is (the readback of every entry costs 2.6 s at 4096^2).
        if not self.shading_layout or not (np.einsum("fcj,fcj->fc", corners, faces) < 0.0).any():
            return np.zeros(0, np.int64)
        normal = util.texture_to_numpy(self.entry_normal, np.float32).reshape(-1, 4)[:self.entry_count]
        inverted = np.einsum("ij,ij->i", octahedral_decode(normal[:, :2]), octahedral_decode(normal[:, 2:])) < 0.0
        return np.unique(self._entry_cells()[inverted]).astype(np.int64)

    def restart(self) -> None:
        """Zero the sums (after accumulated()): the next directions are summed apart."""
        self._test_pending_views()
        for accum, fmt in zip(self.accums, ACCUM_FORMATS[self.plan.estimator.channel_count]):
            accum.clear(format='FLOAT', value=(0.0,) * FORMAT_CHANNELS[fmt])

    def _release(self) -> None:
        self.depths = self.depth_fbs = self.dummy = self.views_block = self.facing_batch = self.face_bins = None
        self.layer_count = self.layer_depth = self.overflow = self.layers_fb = None
        self.pending, self.pending_signs = [], []
        self.chunks = self.window_chunks = None
        self._before_release()
        self.entry_position = self.entry_normal = self.entry_texel = self.entry_lift = None
        self.accums = []
        self.receivers = self.entry_texels = self.entry_cells = self.entry_blocks = None
        super()._release()

    def run_direction(self, index: int) -> None:
        plan = self.plan
        texel_class = int(self.served_classes(self.direction_order[index:index + 1])[0])
        if self.pending and texel_class != self.pending_class:  # a dispatch tests one class's entries
            self._test_pending_views()
        self.pending_class = texel_class
        view = self.view(index)
        with util.scoped_state():
            gpu.state.blend_set('NONE')
            alpha = self._alpha(index)
            if self.layered:  # every surface on the way counts: all faces into the lists
                layers_prepass(self.layers_fb, self.all_batch, view, 'FRONT' if plan.settings.ignore_back_faces
                               else 'NONE', self.layer_count, self.layer_depth, self.overflow, alpha)
            else:
                culling, runs = self._depth_map_faces(index)
                # A cropped view draws its window's faces (with any culling: it is per face).
                facing = self._window_faces(index) if alpha is None else None
                if facing is not None:
                    runs = runs_within(runs, facing[1])
                    if self.before_batch is not None:
                        self._draw_before(index, view)
                if facing is None and culling != 'NONE' and NORMAL_BINNING and alpha is None:  # faces turned towards ('BACK') or away from the light
                    toward = view.omega if culling == 'BACK' else -view.omega
                    facing = (self.facing_batch, self.face_bins.runs(toward))
                    drawn = sum(end - first for first, end in facing[1])
                    self.stats["depth_faces_drawn"] += drawn
                    self.stats["depth_faces_skipped"] += len(self.face_bins.order) - drawn
                depth_prepass(self.depth_fbs[len(self.pending)], self.all_batch, view, culling, runs, facing,
                              positions_only=True, alpha=alpha)
        self.pending.append(view)
        self.pending_signs.append(1.0)
        if len(self.pending) == self.slots or index == plan.direction_count - 1:
            self._test_pending_views()
        self.stats["view_pixels"] += view.width * view.height
        self.stats["directions_done"] += 1

    def _window_faces(self, index: int) -> tuple | None:
        """(all_batch, its (first face, end face) runs in the window) of a cropped view, counted,
        or None: a view drawn whole, or faces drawn by culling."""
        if index not in self.window_runs:
            return None
        runs = self.window_runs[index]
        drawn = sum(end - first for first, end in runs)
        self.stats["window_faces_drawn"] += drawn
        self.stats["window_faces_skipped"] += len(self.window_chunks.order) - drawn
        return self.all_batch, runs

    def _depth_map_faces(self, index: int) -> tuple[str, list[tuple[int, int]]]:
        """(culling, averted face runs) of direction `index`'s depth map. The map must hold the
        nearest surface along each pixel's ray. Where everything drawn bounds solids
        (plan.holes is not None), that is a light-facing face except where the light looks
        into a hole: averted faces are drawn only in the chunks there, and the map is the same
        as from every face. Ignoring back faces: a ray from a texel meets the back of exactly
        the faces that look towards the light, so those are left out."""
        if self.plan.settings.ignore_back_faces:
            return 'FRONT', []
        if self.chunks is None:
            return 'NONE', []
        runs = self.hole_runs[index]
        drawn = sum(count for _, count in runs)
        self.stats["averted_faces_drawn"] += drawn
        self.stats["averted_faces_skipped"] += len(self.chunks.order) - drawn
        return 'BACK', runs

    def _test_pending_views(self) -> None:
        """One compute pass tests every texel-list entry against the pending views' depth maps."""
        views, signs, self.pending, self.pending_signs = self.pending, self.pending_signs, [], []
        if not views or not self.entry_count:
            return
        block = self.views_data[0]
        self.views_data.view(np.float32)[:] = 0.0
        for k, view in enumerate(views):
            grid = view.whole or view  # a cropped view is read on its whole view's pixel grid
            block["view_proj"][k] = grid.matrix.T  # column-major for GLSL
            # With view_proj's entries, which the texel test loads anyway, this gives a receiver
            # plane's depth slope: a second (inverse-transpose) matrix's nine loads per view made
            # the smooth bunny's texel tests 17 % slower on llvmpipe (96 directions: 0.85 s
            # against 0.71 s, medians of 8 interleaved).
            block["plane_slope"][k][:2] = grid.plane_slope()
            block["omega"][k] = (*view.omega, signs[k])  # w < 0: the scene before an edit (DIFFERENCE)
            span = grid.depth_far - grid.depth_near
            block["view_info"][k] = (grid.width, grid.height, grid.pixel_size / span, span)
            block["window"][k] = (*view.first, view.width, view.height)
        self.views_block.update(self.views_data.view(np.float32))
        settings = self.plan.settings
        # One variant per bake: a last, short batch fills the other slots with padding (omega 0).
        shader = gather_shader(settings.weighting == "uniform", self.slots, self.shading_layout,
                               self.plan.layered_falloff if self.layered else None, self.lifted, self.plan.estimator,
                               settings.spread_cos, self.plan.alpha is not None and self.plan.alpha.mode == "blend",
                               self.before_batch is not None)
        shader.bind()
        shader.uniform_block("views", self.views_block)
        if self.layered:
            shader.image("layer_count", self.layer_count)
            shader.image("layer_depth", self.layer_depth)
            shader.uniform_float("max_distance", self.plan.layered_reach)
            shader.uniform_float("min_distance", self.plan.min_distance_normalized)
        else:
            for k in range(self.slots):
                shader.uniform_sampler(f"depth_tex{k}", self.depths[k])
        shader.image("entry_position", self.entry_position)
        shader.image("entry_normal", self.entry_normal)
        for name, accum in zip(ACCUM_NAMES, self.accums):
            shader.image(name, accum)
        if self.lifted:
            shader.image("entry_lift", self.entry_lift)
            shader.uniform_float("terminator_offset", settings.terminator_offset)
        # On llvmpipe an invocation costs its whole shader whether or not its entry faces a
        # view, so entries of bins that face none of these views are not dispatched at all.
        tested = 0
        for first, end in self._tested_runs(views):
            shader.uniform_int("first_entry", first)
            shader.uniform_int("entry_end", end)
            count = end - first
            groups_x = -(-min(count, LIST_WIDTH) // GROUP_SIZE)
            gpu.compute.dispatch(shader, groups_x, -(-count // LIST_WIDTH), 1)
            tested += count
        gpu.shader.unbind()
        first = BIN_COUNT * self.pending_class  # the entries of the views' texel class
        entries = int(self.bin_first[first + BIN_COUNT] - self.bin_first[first])
        self.stats["texel_tests"] += tested * len(views)
        self.stats["texel_tests_skipped"] += (entries - tested) * len(views)

    def accumulated(self) -> np.ndarray:
        """(*plan.output_shape, channels) float64: the estimator's sums, the entries summed per
        texel (or colour-attribute element)."""
        self._test_pending_views()  # directions of a bake stopped short of its last one
        if self.layered:  # pixels whose depth list overflowed, counted over the whole bake
            self.stats["layer_overflow_pixels"] = int(util.texture_to_numpy(self.overflow, np.uint32).ravel()[0])
        if self.entry_count == 0:
            return np.zeros((*self.plan.output_shape, self.plan.estimator.channel_count))
        return texel_sums(self._entry_cells(), self._entry_sums().astype(np.float64), self.plan.output_shape)

    def probe_snapshot(self) -> EntrySnapshot:
        """The partial map as the floor check keeps it: each entry's own value, summed per texel
        only at the checked texels (at 4096^2, 16M entries, accumulated() and a whole-map value
        took 1.7-2.1 s a snapshot)."""
        self._test_pending_views()
        return EntrySnapshot.of(self.plan.estimator, self._entry_sums(), self._entry_cells(),
                                int(np.prod(self.plan.output_shape)))

    def _entry_sums(self) -> np.ndarray:
        """(entry_count, channels) float32: each entry's sums as the GPU holds them."""
        n, channels = self.entry_count, self.plan.estimator.channel_count
        parts = [util.texture_to_numpy(accum, np.float32).reshape(-1, FORMAT_CHANNELS[fmt])[:n]
                 for accum, fmt in zip(self.accums, ACCUM_FORMATS[channels])]
        return parts[0] if len(parts) == 1 else np.concatenate(parts, axis=1)
