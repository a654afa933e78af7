# SPDX-License-Identifier: GPL-3.0-or-later
"""Hybrid Ambient Occlusion frame: one small sequencer runs a method's passes
(core/hao/methods.py) over the frame's inputs. One code path for the viewport overlay and the
headless render (hao_addon/render_ao.py).

Each pass is a row of PASSES: what it reads (frame inputs and resources other passes wrote),
the settings it depends on, the resource it writes. Its key is made of those; it runs only
when the resource it writes does not already hold that key, so the skips are (counted in
`stats`, shown by tests/test_hao_scene.py and test_hao_cascades.py):
- geometry upload only when an object's key (geometry or transform) or the set of objects
  changed; voxelization only when that happened to an object reaching into the region of
  interest, or the region or the grid resolution changed;
- G-buffer only when the view, the size or the geometry changed;
- AO sampling only when the G-buffer, the grid or a sampling setting changed;
- filtering only when the AO or a filter setting changed;
- inside the AO pass, background pixels, objects with a baked AO map and points outside the
  region of interest are not marched (`sampled_pixels` counts those that are).
The AO map is one resource written in place by a chain of passes (voxel_ao then spheres,
say): a pass that starts it runs again whenever another pass changed it since.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from typing import Any, Callable

import gpu
import numpy as np

from ..core.errors import ViewInputError
from ..core.hao.cascades import Focus, cascade_specs, focus_from_depth
from ..core.hao.methods import MethodPlan, method_plan
from ..core.hao.view_scene import SceneObject, filled_classes, render_anchor, scene_bounds
from ..core.hao.view_settings import ViewAOSettings
from ..core.hao.voxel_grid import GridSpec, dominant_axes, grid_for_bounds
from . import util
from .hao_gbuffer import GBufferPass
from .hao_sampling import AOSamplingPass, BilateralPass, LowGBufferPass
from .hao_voxelize import VoxelPass
from .near_field import run_near_field
from .sphere_far import FarSpheresPass

AO_MAP = "ao_map"  # the low-resolution AO map, written in place by a method's AO passes
# What a frame's passes read besides each other (HaoRenderer._frame_inputs).
FRAME_INPUTS = ("geometry", "region", "grid", "view", "spheres")


@dataclass(frozen=True)
class PassSpec:
    """run: the renderer's runner of the pass (renderer, frame) -> its output key or None;
    reads: FRAME_INPUTS and resources (a pass name, or AO_MAP) whose keys its key includes;
    settings: ViewAOSettings fields it depends on; writes: the resource it leaves (its own
    name, or AO_MAP); stat: its counter in stats."""
    run: Callable[["HaoRenderer", "Frame"], Any]
    reads: tuple[str, ...]
    settings: tuple[str, ...]
    stat: str
    writes: str = ""




# The bilateral filter's position weight reaches 0 at d_max; at unlimited distance at this
# many voxels of the grid.
UNLIMITED_FILTER_VOXELS = 32


def filter_range(settings: ViewAOSettings, spec: GridSpec) -> float:
    """Distance (world units) at which the bilateral filter's position weight reaches 0."""
    return settings.max_distance if settings.max_distance > 0.0 else UNLIMITED_FILTER_VOXELS * spec.voxel


def _boxes_overlap(lo_a: np.ndarray, hi_a: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Whether the boxes [lo_a, hi_a] and [lo, hi] overlap."""
    return bool((lo_a <= hi).all() and (hi_a >= lo).all())


@dataclass
class Frame:
    """One render call's inputs, anchor-relative (see render_anchor)."""
    objects: list[SceneObject]
    view_proj: np.ndarray  # (4, 4) anchor-relative -> clip
    width: int
    height: int
    settings: ViewAOSettings
    spheres: tuple[np.ndarray, np.ndarray] | None
    inputs: dict | None = None


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
        self._state: dict[str, object] = {}  # resource -> key of what it holds now
        self._outputs: dict[str, object] = {}  # resource -> the key later passes see of it
        self._boxes_key: object = None
        self._boxes: list = []
        self.spec: GridSpec | None = None  # the region's grid (the coarsest cascade)
        self.cascade_specs: tuple[GridSpec, ...] = ()  # finest first
        self.anchor = np.zeros(3)  # world point the GPU passes' positions are relative to

    def render(self, objects: list[SceneObject], view_proj: np.ndarray, width: int, height: int,
               settings: ViewAOSettings, region: tuple[np.ndarray, np.ndarray] | None = None,
               spheres: tuple[np.ndarray, np.ndarray] | None = None) -> None:
        """Run what changed since the last call. view_proj: (4, 4) world -> clip;
        region: world box (lo, hi) of the region of interest, default the objects' bounds;
        spheres: (centres (K, 3), radii (K,)) sphere proxies for the methods that use them.
        On an error no compute shader stays bound (draw passes restore their own state)."""
        try:
            self._render(objects, view_proj, width, height, settings.validated(), region, spheres)
        except BaseException:
            gpu.shader.unbind()
            self._state.clear()  # a pass may have stopped half way: redo everything next time
            raise

    def invalidate(self, keep: tuple[str, ...] = ()) -> None:
        """Forget what the resources hold, except those named in keep (pass names): the next
        render runs every other pass of its method (benchmarks time whole frames so)."""
        self._state = {k: v for k, v in self._state.items() if k in keep}

    def _render(self, objects, view_proj, width, height, settings, region, spheres) -> None:
        if width < 1 or height < 1:
            raise ViewInputError(f"image size must be positive, got {width}x{height}")
        plan = method_plan(settings.method)
        if plan.spheres and spheres is None:
            raise ViewInputError(f"method '{settings.method}' needs sphere proxies: sync them first")
        self.stats["frames"] += 1
        inputs, frame = self._frame_inputs(plan, objects, view_proj, width, height, settings, region, spheres)
        self._sequence(plan, inputs, frame)

    def _frame_inputs(self, plan: MethodPlan, objects, view_proj, width, height, settings, region, spheres):
        """(the frame inputs' keys, the Frame): geometry, grid, view and spheres."""
        geometry_key = tuple((o.name, o.key, o.receiver, o.fill, len(o.positions)) for o in objects)
        if self._boxes_key != geometry_key:  # object boxes are a pass over every triangle
            self._boxes = [o.world_bounds() if len(o.positions) else None for o in objects]
            self._boxes_key = geometry_key
        world_bounds = scene_bounds(objects, self._boxes)
        bounds = region if region is not None else world_bounds
        if bounds is None:
            raise ViewInputError("nothing to render: no visible mesh objects")
        # Everything on the GPU is measured from the anchor (float32 precision far from the
        # origin); G-buffer positions read back are relative to it (self.anchor).
        anchor = render_anchor(*(world_bounds if world_bounds is not None else bounds))
        self.anchor = anchor
        self.region = (np.asarray(bounds[0]) - anchor, np.asarray(bounds[1]) - anchor)
        self.spec = grid_for_bounds(*self.region, settings.grid)
        voxel_boxes = [(k, box) for k, box in zip(geometry_key, self._boxes) if box is not None]

        def grid_key():
            """Per cascade, the objects reaching into it (read once the cascades are placed):
            one moving outside every cascade re-renders the G-buffer but is not voxelized."""
            per_cascade = []
            for spec in self.cascade_specs:
                lo = np.asarray(spec.origin) + anchor
                hi = lo + np.asarray(spec.dims) * spec.voxel
                per_cascade.append(tuple(k for k, box in voxel_boxes if _boxes_overlap(*box, lo, hi)))
            return tuple(per_cascade), settings.march

        shift = np.identity(4)
        shift[:3, 3] = anchor
        view_proj = np.asarray(view_proj, np.float64) @ shift  # anchor-relative -> clip
        if spheres is not None:
            spheres = (np.asarray(spheres[0], np.float64) - anchor, np.asarray(spheres[1], np.float64))
            if plan.sphere_scope == "outside":  # the voxels hold what is inside the region
                lo, hi = self.region
                outside = ~np.all((spheres[0] >= lo) & (spheres[0] <= hi), axis=1)
                spheres = (spheres[0][outside], spheres[1][outside])
        inputs = {
            "geometry": (geometry_key, anchor.tobytes()),
            "region": (self.spec, anchor.tobytes()),
            "grid": grid_key,
            "view": (geometry_key, np.asarray(view_proj, np.float32).tobytes(), width, height),
            "spheres": ((np.asarray(spheres[0], np.float32).tobytes(), np.asarray(spheres[1], np.float32).tobytes())
                        if spheres is not None else None),
        }
        return inputs, Frame(objects, view_proj, width, height, settings, spheres)

    def _sequence(self, plan: MethodPlan, inputs: dict, frame: Frame) -> None:
        """Run the plan's passes whose resource does not hold their key yet. An input may be
        a function, read when a pass first needs it (after the passes before it ran); a
        runner may return the key the passes after it see of its resource (else its key)."""
        keys = dict(inputs)
        frame.inputs = keys  # runners read the inputs their keys were made of

        def read(name):
            if callable(keys.get(name)):
                keys[name] = keys[name]()
            return keys.get(name)

        for name in plan.passes:
            spec = PASSES[name]
            key = (name, tuple(read(r) for r in spec.reads), tuple(getattr(frame.settings, f) for f in spec.settings))
            resource = spec.writes or name
            if self._state.get(resource) != key:
                output = spec.run(self, frame)
                self._state[resource] = key
                self._outputs[resource] = key if output is None else output
                self.stats[spec.stat] += 1
            keys[resource] = self._outputs.get(resource, key)

    # The passes' runners (rows of PASSES, below): each runs unconditionally; the sequencer
    # decides when.

    def _run_upload(self, frame: Frame) -> None:
        anchor = self.anchor

        def relative(objs):
            if not objs:
                return np.zeros((0, 3, 3), np.float32)
            return np.concatenate([(o.positions + (o.offset - anchor)).astype(np.float32) for o in objs])

        objects = frame.objects
        pos = relative(objects)
        nrm = np.concatenate([o.normals for o in objects]) if objects else np.zeros((0, 3, 3), np.float32)
        flags = (np.concatenate([np.full(len(o.positions), o.receiver, np.float32) for o in objects])
                 if objects else np.zeros(0, np.float32))
        fill = (np.concatenate([np.full(len(o.positions), o.fill, np.int8) for o in objects]) if objects
                else np.zeros(0, np.int8))
        self.voxels.set_geometry(pos, dominant_axes(pos), fill, [len(o.positions) for o in objects])
        self.gbuffer.set_geometry(pos, nrm, flags)
        self.back.set_geometry(pos, nrm, flags)

    def _run_cascades(self, frame: Frame):
        """Place the cascades around the focus of the G-buffer (the paper's fixed march
        keeps one grid); returns the placement."""
        settings = frame.settings
        count = settings.cascades if settings.march == "hierarchical" else 1
        focus = self._focus(frame) if count > 1 else None
        self.cascade_specs = cascade_specs(*self.region, settings.grid, count, focus, settings.max_distance)
        return self.cascade_specs

    def _focus(self, frame: Frame) -> Focus | None:
        """The focus from the G-buffer's depth in the central half of the image (a readback,
        only when the view changed: this pass runs after the G-buffer's)."""
        w, h = frame.width, frame.height
        depth = self.gbuffer.read_depth(w // 4, h // 4, max(w // 2, 1), max(h // 2, 1))
        return focus_from_depth(depth, np.linalg.inv(frame.view_proj), (w, h))

    def _run_voxelize(self, frame: Frame) -> None:
        per_cascade, march = frame.inputs["grid"]
        self.stats["cascades_voxelized"] += self.voxels.voxelize(self.cascade_specs, fill=filled_classes(march),
                                                                 keys=per_cascade)

    def _run_gbuffer(self, frame: Frame) -> None:
        self.gbuffer.render(frame.view_proj, frame.width, frame.height)

    def _run_back_layer(self, frame: Frame) -> None:
        self.back.render(frame.view_proj, frame.width, frame.height)

    def _run_low_gbuffer(self, frame: Frame) -> None:
        self.low_gbuffer.run(self.gbuffer, frame.settings.scale)

    def _run_voxel_ao(self, frame: Frame) -> None:  # noqa: D102 - the cascades' march
        self.sampling.run(self.gbuffer, self.voxels, frame.settings)

    def _run_near_field(self, frame: Frame) -> None:
        settings = frame.settings
        self.sampling.clear(self.gbuffer, settings.scale)
        run_near_field(self.gbuffer, self.back, self.sampling.ao_low, settings.scale, frame.view_proj,
                       settings.near_field_radius(), settings.rays, settings.max_distance, settings.falloff)

    def _run_open_ao(self, frame: Frame) -> None:
        self.sampling.clear(self.gbuffer, frame.settings.scale)

    def _run_spheres(self, frame: Frame) -> None:
        centres, radii = frame.spheres
        settings = frame.settings
        near_radius = settings.near_field_radius() if "near_field" in method_plan(settings.method).passes else 0.0
        self.far.run(self.low_gbuffer, self.sampling.ao_low, centres, radii, settings.epsilon, frame.view_proj,
                     settings.max_distance, settings.falloff, near_radius)

    def _run_filter(self, frame: Frame) -> None:
        self.filter.run(self.gbuffer, self.low_gbuffer, self.sampling.ao_low, frame.settings,
                        filter_range(frame.settings, self.spec))

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
        self._state.clear()


# The passes, one row each (PassSpec): its runner, what it reads, the settings it depends on,
# its counter and what it writes. A method (core/hao/methods.py) is a list of these names.
PASSES = {
    "upload": PassSpec(HaoRenderer._run_upload, ("geometry",), (), "upload"),
    # Where the cascades go (core/hao/cascades.py): its key for the passes after it is the
    # placement it chose, which a small camera move leaves unchanged.
    "cascades": PassSpec(HaoRenderer._run_cascades, ("gbuffer", "region"),
                         ("grid", "cascades", "march", "max_distance"), "cascades"),
    # Not the upload: the grid's key names the cascades and the objects reaching into each
    # (one changing outside a user region, or outside a cascade, is not voxelized again).
    "voxelize": PassSpec(HaoRenderer._run_voxelize, ("cascades", "grid"), (), "voxelize"),
    "gbuffer": PassSpec(HaoRenderer._run_gbuffer, ("upload", "view"), (), "gbuffer"),
    "back_layer": PassSpec(HaoRenderer._run_back_layer, ("upload", "view"), (), "back_layer"),
    "low_gbuffer": PassSpec(HaoRenderer._run_low_gbuffer, ("gbuffer",), ("scale",), "low_gbuffer"),
    "voxel_ao": PassSpec(HaoRenderer._run_voxel_ao, ("gbuffer", "voxelize"),
                         ("scale", "rays", "steps", "march", "spread", "max_distance", "falloff"), "ao", AO_MAP),
    "near_field": PassSpec(HaoRenderer._run_near_field, ("gbuffer", "back_layer"),
                           ("scale", "rays", "max_distance", "falloff", "near_radius", "method"), "near", AO_MAP),
    "open_ao": PassSpec(HaoRenderer._run_open_ao, ("gbuffer",), ("scale",), "open_ao", AO_MAP),
    "spheres": PassSpec(HaoRenderer._run_spheres, (AO_MAP, "low_gbuffer", "spheres", "region"),
                        ("epsilon", "max_distance", "falloff", "near_radius", "method"), "far", AO_MAP),
    "filter": PassSpec(HaoRenderer._run_filter, (AO_MAP, "low_gbuffer", "region"), ("filter_size", "max_distance"),
                       "filter"),
}
