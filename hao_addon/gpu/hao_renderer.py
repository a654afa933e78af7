# SPDX-License-Identifier: GPL-3.0-or-later
"""Hybrid Ambient Occlusion frame: voxelize -> G-buffer -> AO sampling -> bilateral upsample.
One code path for the viewport overlay and the headless render (hao_addon/render_ao.py).

Skips (counted in `stats`, shown by tests/test_hao_skip.py):
- geometry upload only when an object's key (geometry or transform) or the set of objects
  changed; voxelization only when that happened to an object reaching into the region of
  interest, or the region or the grid resolution changed;
- G-buffer only when the view, the size or the geometry changed;
- AO sampling only when the G-buffer, the grid or a sampling setting changed;
- filtering only when the AO or a filter setting changed;
- inside the AO pass, background pixels, objects with a baked AO map and points outside the
  region of interest are not marched (`sampled_pixels` counts those that are).
"""
from __future__ import annotations

from collections import Counter

import gpu
import numpy as np

from ..core.errors import BakeInputError
from ..core.hao.view_scene import SceneObject, render_anchor, scene_bounds
from ..core.hao.view_settings import ViewAOSettings
from ..core.hao.voxel_grid import GridSpec, dominant_axes, grid_for_bounds
from . import util
from .hao_gbuffer import GBufferPass
from .hao_sampling import AOSamplingPass, BilateralPass, LowGBufferPass
from .hao_voxelize import VoxelPass
from .near_field import run_near_field
from .sphere_far import FarSpheresPass


def _boxes_overlap(lo_a: np.ndarray, hi_a: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Whether the boxes [lo_a, hi_a] and [lo, hi] overlap."""
    return bool((lo_a <= hi).all() and (hi_a >= lo).all())


class HaoRenderer(util.GPUPass):
    def __init__(self) -> None:
        super().__init__()
        self.voxels = VoxelPass()
        self.gbuffer = GBufferPass()
        self.sampling = AOSamplingPass()
        self.filter = BilateralPass()
        self.far = FarSpheresPass()
        self.back = GBufferPass(back_layer=True)  # second layer of the near-field pass
        self.low_gbuffer = LowGBufferPass()  # G-buffer at the AO-map resolution, for the spheres
        self.stats: Counter = Counter()
        self._keys: dict[str, object] = {}
        self.spec: GridSpec | None = None
        self.anchor = np.zeros(3)  # world point the GPU passes' positions are relative to
        self._boxes: list = []

    def _changed(self, name: str, key: object) -> bool:
        if self._keys.get(name) == key:
            return False
        self._keys[name] = key
        return True

    def render(self, objects: list[SceneObject], view_proj: np.ndarray, width: int, height: int,
               settings: ViewAOSettings, region: tuple[np.ndarray, np.ndarray] | None = None,
               spheres: tuple[np.ndarray, np.ndarray] | None = None) -> None:
        """Run what changed since the last call. view_proj: (4, 4) world -> clip;
        region: world box (lo, hi) of the region of interest, default the objects' bounds;
        spheres: (centres (K, 3), radii (K,)) sphere proxies for the 'far' methods.
        On an error no compute shader stays bound (draw passes restore their own state)."""
        try:
            self._render(objects, view_proj, width, height, settings, region, spheres)
        except BaseException:
            gpu.shader.unbind()
            self._keys.clear()  # a pass may have stopped half way: redo everything next time
            raise

    def _render(self, objects, view_proj, width, height, settings, region, spheres) -> None:
        settings = settings.validated()
        if width < 1 or height < 1:
            raise BakeInputError(f"image size must be positive, got {width}x{height}")
        self.stats["frames"] += 1
        # With 'hao+far' the spheres stand in for the objects that have them: those are drawn
        # and receive AO but are not voxelized, so no occluder is counted twice.
        voxelized = [o for o in objects if not (settings.method == "hao+far" and o.proxied)]
        geometry_key = tuple((o.name, o.key, o.receiver, o.solid, len(o.positions)) for o in objects)
        # Object boxes are a pass over every triangle: only when an object changed.
        if self._changed("boxes", geometry_key):
            self._boxes = [o.world_bounds() if len(o.positions) else None for o in objects]
        boxes = self._boxes
        world_bounds = scene_bounds(objects, boxes)
        bounds = region if region is not None else world_bounds
        if bounds is None:
            raise BakeInputError("nothing to render: no visible mesh objects")
        # Everything on the GPU is measured from the anchor (float32 precision far from the
        # origin); G-buffer positions read back are relative to it (self.anchor).
        anchor = render_anchor(*(world_bounds if world_bounds is not None else bounds))
        self.anchor = anchor

        def relative(objs):
            if not objs:
                return np.zeros((0, 3, 3), np.float32)
            return np.concatenate([(o.positions + (o.offset - anchor)).astype(np.float32) for o in objs])

        if self._changed("geometry", (geometry_key, tuple(o.name for o in voxelized), anchor.tobytes())):
            pos = relative(objects)
            nrm = (np.concatenate([o.normals for o in objects]) if objects else np.zeros((0, 3, 3), np.float32))
            flags = np.concatenate([np.full(len(o.positions), o.receiver, np.float32) for o in objects]) \
                if objects else np.zeros(0, np.float32)
            vpos = relative(voxelized)
            solid = (np.concatenate([np.full(len(o.positions), o.solid) for o in voxelized]) if voxelized
                     else np.zeros(0, bool))
            self.voxels.set_geometry(vpos, dominant_axes(vpos), solid)
            self.gbuffer.set_geometry(pos, nrm, flags)
            self.back.set_geometry(pos, nrm, flags)
            self.stats["upload"] += 1
        self.spec = grid_for_bounds(np.asarray(bounds[0]) - anchor, np.asarray(bounds[1]) - anchor, settings.grid)
        # Only objects reaching into the region can change the grid: one moving outside a
        # user region re-renders the G-buffer but is not re-voxelized.
        lo = np.asarray(self.spec.origin) + anchor
        hi = lo + np.asarray(self.spec.dims) * self.spec.voxel
        inside = tuple(k for o, k, box in zip(objects, geometry_key, boxes)
                       if box is not None and o in voxelized and _boxes_overlap(*box, lo, hi))
        grid_key = (inside, self.spec, anchor.tobytes())
        use_voxels = settings.method in ("hao", "hao+far")
        if use_voxels and self._changed("grid", grid_key):
            self.voxels.voxelize(self.spec)
            self.stats["voxelize"] += 1
        shift = np.identity(4)
        shift[:3, 3] = anchor
        view_proj = np.asarray(view_proj, np.float64) @ shift  # anchor-relative -> clip
        if spheres is not None:
            spheres = (np.asarray(spheres[0], np.float64) - anchor, spheres[1])
        view_key = (geometry_key, np.asarray(view_proj, np.float32).tobytes(), width, height)
        if self._changed("view", view_key):
            self.gbuffer.render(view_proj, width, height)
            self.stats["gbuffer"] += 1
        use_near = settings.method in ("near", "near+far")
        if use_near and self._changed("back", view_key):
            self.back.render(view_proj, width, height)
            self.stats["back_layer"] += 1
        use_spheres = settings.method in ("far", "hao+far", "near+far")
        if use_spheres and spheres is None:
            raise BakeInputError(f"method '{settings.method}' needs sphere proxies: sync them first")
        sphere_key = ((np.asarray(spheres[0], np.float32).tobytes(), np.asarray(spheres[1], np.float32).tobytes(),
                       settings.epsilon) if use_spheres else None)
        ao_key = (settings.method, grid_key if use_voxels else None, view_key, sphere_key, settings.scale,
                  (settings.rays, settings.steps, settings.spread, settings.max_distance) if use_voxels or use_near
                  else None)
        if self._changed("ao", ao_key):
            if use_voxels:
                self.sampling.run(self.gbuffer, self.voxels, settings)
                self.stats["ao"] += 1
            elif use_near:
                self.sampling.clear(self.gbuffer, settings.scale)
                run_near_field(self.gbuffer, self.back, self.sampling.ao_low, settings.scale, view_proj,
                               settings.max_distance, settings.rays)
                self.stats["near"] += 1
            else:
                self.sampling.clear(self.gbuffer, settings.scale)
            if use_spheres:
                if self._changed("low_gbuffer", (view_key, settings.scale)):
                    self.low_gbuffer.run(self.gbuffer, settings.scale)
                self.far.run(self.low_gbuffer, self.sampling.ao_low, spheres[0], spheres[1], settings.epsilon,
                             view_proj)
                self.stats["far"] += 1
        if self._changed("filter", (ao_key, settings.filter_size)):
            self.filter.run(self.gbuffer, self.sampling.ao_low, settings)
            self.stats["filter"] += 1

    @property
    def ao_texture(self) -> "gpu.types.GPUTexture":
        return self.filter.ao

    def read_ao(self) -> np.ndarray:
        """(H, W) float32 accessibility, row 0 bottom; 1 on background."""
        return self.filter.read()

    def sampled_pixels(self) -> int:
        """AO-map pixels the last AO pass marched (the rest were skipped)."""
        return self.sampling.sampled_pixels()

    def _release(self) -> None:
        for p in (self.voxels, self.gbuffer, self.sampling, self.filter, self.far, self.back, self.low_gbuffer):
            p.free()
        self._keys.clear()
