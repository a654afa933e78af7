# SPDX-License-Identifier: GPL-3.0-or-later
"""The gather's texel list (gpu/bake_gather.py): one entry per sample point of the target,
each with its position, normals and sums, grouped by normal bin; listed by a UV-space raster
on the GPU or uploaded from CPU receivers, and for a run of some cells (an incremental
re-bake) the raster's entries in those cells alone."""
from __future__ import annotations

from dataclasses import replace

import gpu
import numpy as np

from ..core.bake.entry_blocks import block_boxes, block_order
from ..core.bake.interleave import SIDE
from ..core.bake.normal_bins import BIN_COUNT, bin_cones, normal_bins, octahedral_coords, octahedral_decode
from ..core.bake.plan import BakePlan
from ..core.bake.receivers import Receivers, faces_touching
from ..core.errors import BakeInputError
from . import util
from .gather_shaders import ACCUM_FORMATS, FORMAT_CHANNELS, LIST_WIDTH, texel_list_shader

ENTRY_BYTES = 16 + 16 + 4  # position + 1/S_f, normal, texel (and 4 bytes per estimator channel)
LIFT_BYTES = 16  # an entry's terminator lift, where the plan lifts (plan.lifts_terminator)


def entry_bytes(plan: BakePlan) -> int:
    return ENTRY_BYTES + 4 * plan.estimator.channel_count + (LIFT_BYTES if plan.lifts_terminator else 0)


def faces_reaching_cells(plan: BakePlan) -> BakePlan:
    """plan with the target's faces that reach its cells alone (the plan's window_faces,
    receivers.faces_touching): the texel list of a run of some cells rasterizes only them."""
    faces = plan.window_faces
    if faces is None:  # a run whose cells no face reaches
        faces = faces_touching(plan.target_uvs, plan.settings.size, plan.cells)
    return replace(plan, target_positions=plan.target_positions[faces], target_uvs=plan.target_uvs[faces],
                   target_faces=plan.target_faces[faces], target_corners=plan.target_corners[faces],
                   target_above=plan.target_above[faces])


class TexelList:
    """The texel-list part of GatherBaker (its plan, target_batch, receivers, lifted and
    the list textures are the baker's). The list is stored bin by bin: the normal bins
    (core/bake/normal_bins.py) of texel class 0, then those of class 1 and on
    (core/bake/interleave.py)."""

    @property
    def list_bins(self) -> int:
        """The list's bins: BIN_COUNT per texel class."""
        return BIN_COUNT * self.plan.classes

    def _allocate_list(self, count: int, uploaded: tuple[np.ndarray, ...] | None = None) -> None:
        """The list textures for `count` entries (LIST_WIDTH per row) and zeroed sums;
        uploaded: (position (count, 4), normal (count, 4)[, lift (count, 4)]) float32 to fill
        them with (the texel of each entry then stays on the CPU: only accumulated() reads it)."""
        size = self.plan.settings.size
        self.entry_count = count
        self.entry_cells = None  # read back once, at the first readback of sums
        self.listed = None  # the entries as receivers (entry_state), read back once
        rows = util.list_rows(count)
        if rows > gpu.capabilities.max_texture_size_get():
            raise BakeInputError(f"{count} covered texels exceed this GPU's texture limit; use a smaller map")
        if count > size * size:  # overlapping UV islands or sub-texel samples: more entries than texels
            util.check_texture_limits(size, self.plan.max_view_side,
                                      count * entry_bytes(self.plan) + self.plan.max_view_side**2 * 8)
        shape = (LIST_WIDTH, rows)
        self.entry_lift = None
        if uploaded is None:
            self.entry_position = gpu.types.GPUTexture(shape, format='RGBA32F')
            self.entry_normal = gpu.types.GPUTexture(shape, format='RGBA32F')
            self.entry_texel = gpu.types.GPUTexture(shape, format='R32UI')
            if self.lifted:
                self.entry_lift = gpu.types.GPUTexture(shape, format='RGBA32F')
        else:
            self.entry_position, self.entry_normal = (util.list_texture(v, 'RGBA32F') for v in uploaded[:2])
            if len(uploaded) > 2:
                self.entry_lift = util.list_texture(uploaded[2], 'RGBA32F')
        channels = self.plan.estimator.channel_count
        self.accums = [gpu.types.GPUTexture(shape, format=fmt) for fmt in ACCUM_FORMATS[channels]]
        for accum, fmt in zip(self.accums, ACCUM_FORMATS[channels]):
            accum.clear(format='FLOAT', value=(0.0,) * FORMAT_CHANNELS[fmt])

    def _upload_texel_list(self, receivers: Receivers) -> None:
        """The list from CPU receivers: sorted by the normal bin of their shading normal (the
        one their weight is about), both normals octahedral-encoded (the SHADING_NORMALS layout)."""
        receivers = receivers.subset(receivers.inv_s > 0.0)
        normal_bin = normal_bins(receivers.shading)
        bins = normal_bin + BIN_COUNT * self.plan.receiver_classes(receivers.texel)  # each class's bins apart
        order = np.argsort(bins, kind="stable")
        bins = bins[order]
        self.bin_axis, self.bin_threshold = bin_cones(receivers.shading[order], normal_bin[order],
                                                      np.ones(len(bins), bool))
        self.bin_first = np.concatenate([[0], np.cumsum(np.bincount(bins, minlength=self.list_bins))]).astype(np.int64)
        position = np.concatenate([receivers.points[order], receivers.inv_s[order, None]], axis=1)
        normal = np.concatenate([octahedral_coords(receivers.shading[order]),
                                 octahedral_coords(receivers.geometric[order])], axis=1)
        self.entry_texels = receivers.texel[order]
        uploaded = [position.astype(np.float32), normal.astype(np.float32)]
        if self.lifted:
            lift = np.zeros((len(order), 4), np.float32)
            lift[:, :3] = receivers.lift[order]
            uploaded.append(lift)
        self._allocate_list(len(order), tuple(uploaded))

    def _build_texel_list(self) -> None:
        """Count the target's UV-space fragments per normal bin, allocate the list at that
        size with each bin's entries together, fill it (or upload cpu_receivers)."""
        if self.receivers is not None:
            self._upload_texel_list(self.receivers)
            return
        size, bins = self.plan.settings.size, self.list_bins
        counter = gpu.types.GPUTexture((bins, 1), format='R32UI')
        uv_target = gpu.types.GPUTexture((size, size), format='R8')
        uv_fb = gpu.types.GPUFrameBuffer(color_slots=uv_target)

        def draw(shader) -> None:
            counter.clear(format='UINT', value=(0,))
            with util.scoped_state(), uv_fb.bind():
                util.set_overlay_pass_state(size, size)
                shader.bind()
                shader.image("bin_count", counter)
                if shader is fill:
                    shader.uniform_int("capacity", count)
                    shader.image("entry_position", self.entry_position)
                    shader.image("entry_normal", self.entry_normal)
                    shader.image("entry_texel", self.entry_texel)
                    shader.image("bin_start", bin_start)
                    if self.lifted:
                        shader.image("entry_lift", self.entry_lift)
                self.target_batch.draw(shader)
            util.image_barrier()

        side = SIDE if self.plan.classes > 1 else 1
        fill = texel_list_shader(True, self.plan.smooth_shading, self.lifted, side)
        draw(texel_list_shader(False, self.plan.smooth_shading, self.lifted, side))
        per_bin = util.texture_to_numpy(counter, np.uint32).ravel()[:bins].astype(np.int64)
        count = int(per_bin.sum())
        self.bin_first = np.concatenate([[0], np.cumsum(per_bin)])  # (BIN_COUNT + 1,) range bounds
        self._allocate_list(count)
        # Only FLOAT buffers upload: the uint32 starts travel as float bits (floatBitsToUint).
        starts = self.bin_first[:-1].astype(np.uint32).view(np.float32)
        bin_start = gpu.types.GPUTexture((bins, 1), format='R32F', data=gpu.types.Buffer('FLOAT', bins, starts))
        draw(fill)
        # Both passes bin each fragment by the same arithmetic on the same inputs; a GPU whose
        # two variants rounded a shading normal differently would have filled a neighbour's range.
        filled = util.texture_to_numpy(counter, np.uint32).ravel()[:bins].astype(np.int64)
        if not np.array_equal(filled, per_bin):
            raise RuntimeError(f"the texel list's fill pass binned {int(np.abs(filled - per_bin).sum())} entries "
                               f"differently from its count pass")
        if self.plan.cells is not None:
            self._keep_cells_entries(self.plan.cells)

    def _keep_cells_entries(self, cells: np.ndarray) -> None:
        """Keep the listed entries of `cells` alone (a run of some cells lists the faces that
        reach them), in their bins' order, uploaded again; their texels stay on the CPU."""
        n = self.entry_count
        flat = self._entry_cells()
        wanted = np.zeros(int(np.prod(self.plan.output_shape)), bool)
        wanted[cells] = True
        keep = np.flatnonzero(wanted[flat])
        bins = np.searchsorted(self.bin_first, keep, side="right") - 1
        textures = [self.entry_position, self.entry_normal] + ([self.entry_lift] if self.lifted else [])
        uploaded = tuple(util.texture_to_numpy(t, np.float32).reshape(-1, 4)[:n][keep] for t in textures)
        if self.plan.window_spheres is not None:  # views cropped to spheres: entries in blocks
            order = block_order(uploaded[0][:, :3].astype(np.float64), bins, flat[keep])
            keep, bins, uploaded = keep[order], bins[order], tuple(u[order] for u in uploaded)
            ends = uploaded[0][:, :3] + (uploaded[2][:, :3] if self.lifted else 0.0)  # a test's point: up to the lift
            self.entry_blocks = block_boxes(np.minimum(uploaded[0][:, :3], ends).astype(np.float64),
                                            np.maximum(uploaded[0][:, :3], ends).astype(np.float64))
        self.bin_first = np.concatenate([[0], np.cumsum(np.bincount(bins, minlength=self.list_bins))]).astype(np.int64)
        self._allocate_list(len(keep), uploaded)
        self.entry_cells = flat[keep]

    def entry_state(self) -> tuple[Receivers, np.ndarray] | None:
        """(the listed receivers in list order, (n, channels) float32 their sums so far) of a
        list the GPU raster made (None for uploaded receivers, which the list keeps in another
        order): a re-bake by difference compares two bakes entry by entry."""
        if self.receivers is not None:
            return None
        self._test_pending_views()
        if self.listed is None:  # every entry is in the cells: no filter (np.isin cost 0.4 s at 1.2M)
            n = self.entry_count
            position = util.texture_to_numpy(self.entry_position, np.float32).reshape(-1, 4)[:n].astype(np.float64)
            normal = util.texture_to_numpy(self.entry_normal, np.float32).reshape(-1, 4)[:n].astype(np.float64)
            shading = octahedral_decode(normal[:, :2]) if self.shading_layout else normal[:, :3]
            self.listed = Receivers(position[:, :3], shading, shading, position[:, 3], self._entry_cells())
        return self.listed, self._entry_sums()

    def _entry_cells(self) -> np.ndarray:
        """(entry_count,) int each entry's flat texel index, read back once."""
        if self.receivers is not None:
            return self.entry_texels
        if self.entry_cells is None:
            size = self.plan.settings.size
            texel = util.texture_to_numpy(self.entry_texel, np.uint32).ravel()[:self.entry_count]
            # int32 where it fits: 64 MB at 4096^2 (16M entries), kept for the bake
            kind = np.int32 if np.prod(self.plan.output_shape) < 2 ** 31 else np.int64
            self.entry_cells = (texel >> 16).astype(kind) * kind(size) + (texel & 0xFFFF).astype(kind)
        return self.entry_cells
