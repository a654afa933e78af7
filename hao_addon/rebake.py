# SPDX-License-Identifier: GPL-3.0-or-later
"""Re-bake only what an edit changed, with a stated bound on what is kept.

A bake records its scene (core/bake/scene_changes.SceneState: the settings' key, the target's
layout, every soup's faces). The next bake of the same target compares the edited scene's
state with it: the changed faces' spheres, before and after, bound how far each texel's value
can lie from a whole bake of the edited scene (core/bake/change_bound.sampled_change_bound:
the share of the bake's own directions that enter them); cells whose bound stays below
KEEP_SHARE of the map's stated RMSE keep their value, the others are baked again (the plan's
cells: only the bakers that bake a subset spend less, abilities.bakes_all_cells), and the
map's margins grow again from the merged values. A change of any setting that changes pixels,
of the target's UVs or faces, a bake to an error, bent normals, colour attributes, UDIM tiles,
Selected to Active and a baker that bakes every texel re-bake in full (said in the report).
Nothing here touches Blender data.
"""
from __future__ import annotations

import dataclasses
import io
import json
import math
from dataclasses import dataclass, field, replace
from typing import Generator

import numpy as np

from .bake import BakeResult, bake_cells_steps, bake_steps, regrown
from .core.bake.abilities import declaration
from .core.bake.change_bound import cell_bound, face_box_bounds, refined_piece_bounds, sampled_change_bound
from .core.bake.error_estimate import ErrorEstimate, estimate
from .core.bake.plan import make_plan_steps
from .core.bake.scene_changes import SceneState, SoupState, changed_spheres, scene_state
from .core.bake.settings import BakeSettings
from .core.bake.target_kinds import target_kind
from .core.bake.targets import BakeTarget
from .core.bake.udim import udim_layout
from .core.geometry import TriangleSoup
from .core.steps import drain, relay
from .rebake_difference import difference_steps, merged_by_difference

DIFFERENCE = "by difference"  # RebakeReport.how of cells re-baked by rebake_difference.py

# Cells whose bound is below this share of the map's stated RMSE are kept: kept cells then add
# at most half the stated RMSE (in quadrature, the map's RMSE grows by at most 12 %), and the
# report states the largest bound among them.
KEEP_SHARE = 0.5


@dataclass(frozen=True)
class RebakeReport:
    """What a re-bake did: full (and why) or the cells baked again of those covered; the
    largest bound among kept cells (and among the offsets that cells re-baked by difference
    carry from earlier re-bakes) and the threshold they were kept under."""

    full: bool
    why: str
    rebaked: int
    covered: int
    kept_bound: float = 0.0
    threshold: float = 0.0
    # The cells baked again (flat indices into the map), None for a full bake or none.
    cells: np.ndarray | None = field(default=None, compare=False, repr=False)
    # How the cells were baked: 'by difference' (rebake_difference.py) or 'baked whole: why'.
    how: str = ""

    def text(self) -> str:
        if self.full:
            return f"re-baked in full: {self.why}"
        how = f", {self.how}" if self.how else ""
        return (f"re-baked {self.rebaked} of {self.covered} texels ({self.why}{how}); the {self.covered - self.rebaked} "
                f"kept are within {self.kept_bound:.2g} of a whole bake of the edited scene (kept below "
                f"{self.threshold:.2g})")

    def as_dict(self) -> dict:
        return {"full": self.full, "why": self.why, "rebaked": self.rebaked, "covered": self.covered,
                "kept_bound": self.kept_bound, "threshold": self.threshold, "how": self.how}


def settings_key(settings: BakeSettings) -> str:
    """The settings' part of a scene state: every setting that changes pixels (the cache's)."""
    return repr(settings.cache_key())


def record(target: TriangleSoup, occluders: list[TriangleSoup], settings: BakeSettings) -> SceneState:
    """The state a bake of target against occluders records for the next re-bake."""
    return scene_state(target, occluders, settings_key(settings))


def _full_reason(previous: BakeResult | None, before: SceneState | None, after: SceneState,
                 target: TriangleSoup, settings: BakeSettings) -> str:
    """Why this re-bake cannot keep anything, or ''."""
    if previous is None or before is None:
        return "no earlier bake of this target"
    if previous.tiles is not None or previous.ao.shape != (settings.size, settings.size):
        return "the earlier bake's map is of another layout"
    if before.settings_key != after.settings_key:
        return "a setting that changes pixels changed"
    if before.target_layout != after.target_layout:
        return "the target's UVs or faces changed"
    if settings.error_target > 0.0:
        return "a bake to an error is re-baked in full"
    if settings.bent_normals:
        return "bent normals have no bound on what an edit changes"
    if not target_kind(settings.target).writes_images:
        return "colour attributes are re-baked in full"
    if udim_layout(target.uvs) is not None:
        return "UDIM tiles are re-baked in full"
    if previous.error is None:
        return "the earlier bake states no error to keep texels under"
    return ""


def rebake_steps(previous: BakeResult | None, before: SceneState | None, target: TriangleSoup | BakeTarget,
                 occluders: list[TriangleSoup], settings: BakeSettings
                 ) -> Generator[float, None, tuple[BakeResult, SceneState, RebakeReport]]:
    """The edited scene's bake, from previous (a bake of before's scene with the same settings)
    where the edit cannot have changed a cell by KEEP_SHARE of its stated RMSE; yields progress.
    Returns (the map, the state to record for the next re-bake, what was done); the map's
    stats carry the report ('rebake')."""
    bake_target = target
    target = target.soup if isinstance(target, BakeTarget) else target
    after = record(target, occluders, settings)
    reason = _full_reason(previous, before, after, target, settings)
    if not reason and isinstance(bake_target, BakeTarget) and bake_target.high_to_low is not None:
        reason = "Selected to Active is re-baked in full"
    plan = None
    if not reason:
        plan = yield from relay(make_plan_steps(target, occluders, settings), lambda f: 0.05 * f)
        if declaration(plan.method).bakes_all_cells:
            reason = (f"the {declaration(plan.method).label} bakes every texel (Method: Gather re-bakes part of a "
                      f"map)")
    if reason:
        result = yield from bake_steps(bake_target, occluders, settings, use_cache=False)
        report = RebakeReport(True, reason, int(result.covered.sum()), int(result.covered.sum()))
        return _reported(result, result.stats, report), after, report
    spheres = changed_spheres(before, after)
    covered = int(previous.covered.sum())
    stats = {**plan.stats, "method": plan.method, "covered_texels": covered, "cache_hit": False}
    if len(spheres) == 0:
        yield 1.0
        report = RebakeReport(False, "nothing changed", 0, covered)
        return _reported(previous, stats, report), after, report
    threshold = KEEP_SHARE * previous.error.rmse
    # A cell kept by earlier re-bakes already lies up to their bounds from its scene's bake.
    carried = 0.0 if previous.kept_offset is None else previous.kept_offset.reshape(-1).astype(np.float64)
    grown = _grown(plan, spheres)
    bounds = carried + _cell_bounds(plan, grown, settings, threshold)
    redo = previous.covered.reshape(-1) & (bounds >= threshold)
    kept = previous.covered.reshape(-1) & ~redo
    kept_bound = float(bounds[kept].max()) if kept.any() else 0.0
    offset = np.where(kept, bounds, 0.0).astype(np.float32).reshape(previous.covered.shape)
    why = f"{len(spheres)} changed parts"
    if not redo.any():
        yield 1.0
        report = RebakeReport(False, why, 0, covered, kept_bound, threshold)
        noise = previous.error if previous.twin is None else estimate(previous.twin, previous.covered,
                                                                      previous.error.directions)
        kept = replace(previous, error=_with_bound(noise, previous.error, kept_bound), kept_offset=offset)
        return _reported(kept, stats, report), after, report
    cells = np.flatnonzero(redo)
    part, how = yield from relay(_cells_steps(previous, before, (target, occluders), settings, cells, grown),
                                 lambda f: 0.1 + 0.9 * f)
    if how == DIFFERENCE and previous.kept_offset is not None:
        # A difference adds to the earlier value: a cell keeps what earlier re-bakes let it carry
        # (under the threshold, which it was kept under).
        offset.reshape(-1)[cells] = carried[cells]
        kept_bound = max(kept_bound, float(carried[cells].max()))
    report = RebakeReport(False, why, len(cells), covered, kept_bound, threshold, cells, how)
    merged = replace(_merged(previous, part, redo.reshape(previous.covered.shape), settings, kept_bound),
                     kept_offset=offset)
    return _reported(merged, {**stats, **part.stats, "covered_texels": covered}, report), after, report


def _reported(result: BakeResult, stats: dict, report: RebakeReport) -> BakeResult:
    """result with stats, its error and the re-bake's report among them."""
    error = None if result.error is None else result.error.as_dict()
    return replace(result, stats={**stats, "error": error, "rebake": report.as_dict()}, method=stats["method"])


def rebake(previous: BakeResult | None, before: SceneState | None, target: TriangleSoup | BakeTarget,
           occluders: list[TriangleSoup], settings: BakeSettings) -> tuple[BakeResult, SceneState, RebakeReport]:
    """rebake_steps, drained."""
    return drain(rebake_steps(previous, before, target, occluders, settings))


# Changed spheres grow by this many light-view pixels for a GPU baker's bound: it reads
# visibility from depth maps, where an edit reaches the texels whose rays pass within a pixel
# (and its filter) of it. The reference traces exact rays: no slack.
SLACK_PIXELS = 2.0


# The cells' bound is laid out on a grid at most this fine (each fine cell takes its coarse
# cell's): faces' UV boxes paint it, so its cost does not grow with the map's size.
BOUND_GRID = 512


# Maps up to this size bound each cell by its own receivers (exact, and cheap there); larger
# ones by pieces of the target's faces (each piece's sphere standing for its receivers),
# whose cost does not grow with the map.
RECEIVER_BOUND_SIZE = 512
PIECE_SHARE = 0.25


def _grown(plan, spheres: np.ndarray) -> np.ndarray:
    """(k, 4) the changed spheres grown by a GPU baker's slack (SLACK_PIXELS)."""
    slack = SLACK_PIXELS * plan.pixel_size * plan.scale if declaration(plan.method).gpu else 0.0
    return spheres + np.array([0.0, 0.0, 0.0, slack])


def _cells_steps(previous: BakeResult, before: SceneState, after_scene: tuple, settings: BakeSettings,
                 cells: np.ndarray, grown: np.ndarray) -> Generator[float, None, tuple[BakeResult, str]]:
    """(the cells baked again, as a BakeResult of which only they count; how): by difference
    where it can be measured (rebake_difference.py), else whole."""
    found = yield from relay(difference_steps(before, settings, after_scene, cells, grown), lambda f: 0.5 * f)
    if isinstance(found, str):
        part = yield from relay(bake_cells_steps(*after_scene, settings, cells), lambda f: 0.5 + 0.5 * f)
        return part, f"baked whole: {found}"
    twin = None if previous.twin is None else previous.twin.reshape(-1)[cells]
    values, twins = merged_by_difference(previous.ao.reshape(-1)[cells], twin, found)
    if len(found.traced):  # contacts: baked whole, traced exactly as a whole bake traces them
        whole = yield from relay(bake_cells_steps(*after_scene, settings, found.traced), lambda f: 0.5 + 0.5 * f)
        at = np.searchsorted(cells, found.traced)
        values[at] = whole.ao.reshape(-1)[found.traced]
        if twins is not None and whole.twin is not None:
            twins[at] = whole.twin.reshape(-1)[found.traced]
    ao, covered = np.ones(previous.ao.shape, np.float32), np.zeros(previous.covered.shape, bool)
    ao.reshape(-1)[cells], covered.reshape(-1)[cells] = values, True
    part_twin = None
    if twins is not None:
        part_twin = np.zeros(previous.ao.shape, np.float32)
        part_twin.reshape(-1)[cells] = twins
    return BakeResult(ao, covered, covered, found.stats, twin=part_twin, method=previous.method), DIFFERENCE


def _cell_bounds(plan, grown: np.ndarray, settings: BakeSettings, threshold: float) -> np.ndarray:
    """(cells,) a bound on how far each output cell's value can lie from a whole bake of the
    edited scene (plan: that bake's): the weight share of the bake's own directions that
    enter a changed sphere (sampled_change_bound; the same directions, so a direction that
    meets no change reads the same visibility), at the receivers themselves or, for maps
    above RECEIVER_BOUND_SIZE, at pieces of the target's faces painted over their UV boxes
    (cut finer where they reach threshold). The hemisphere's own bound (change_bound, (r /
    D)^2) is what this tends to at many directions; at few it is no bound on an estimate
    (one direction into a small cone moves it by about 1 / D), and at 128 directions on an
    8-unit floor it would re-bake every texel for a ball of 0.4 moved by 0.1. grown: the
    changed spheres grown by the slack (_grown)."""
    if settings.size <= RECEIVER_BOUND_SIZE:
        return _receiver_bounds(plan, grown, settings)
    return _piece_bounds(plan, grown, settings, threshold)


def _receiver_bounds(plan, spheres: np.ndarray, settings: BakeSettings) -> np.ndarray:
    """(cells,) the largest bound of each cell's receivers."""
    receivers = plan.receivers()
    world = receivers.points * plan.scale + plan.centre
    args = (settings.weighting, settings.spread_angle, settings.max_distance)
    bound = sampled_change_bound(world, receivers.shading, spheres, plan.directions, *args,
                                 direction_class=plan.direction_class)
    return cell_bound(bound, receivers.texel, int(np.prod(plan.layout.output_shape)))


def _piece_bounds(plan, spheres: np.ndarray, settings: BakeSettings, threshold: float) -> np.ndarray:
    """(cells,) each cell's bound from pieces of the target's faces that reach it, cut finer
    where the bound reaches threshold (change_bound.refined_piece_bounds)."""
    lit = plan.target_faces[:, 3] > 0.0
    world = plan.target_positions[lit].astype(np.float64) * plan.scale + plan.centre
    normals = plan.target_corners[lit, :, :3].astype(np.float64)
    # Pieces down to about a quarter of the smallest changed sphere, or half a texel, wide.
    texel = np.sqrt(_world_per_uv(world, plan.target_uvs[lit])) / settings.size
    args = (settings.weighting, settings.spread_angle, settings.max_distance)

    def bound_of(pieces: np.ndarray, corner_normals: np.ndarray) -> np.ndarray:
        unit = corner_normals / np.maximum(np.linalg.norm(corner_normals, axis=2, keepdims=True), 1e-30)
        return sampled_change_bound(pieces[:, :3], unit, spheres, plan.directions, *args, reach=pieces[:, 3],
                                    direction_class=plan.direction_class)

    uvs, bound = refined_piece_bounds(world, plan.target_uvs[lit].astype(np.float64), normals, bound_of, threshold,
                                      max(PIECE_SHARE * float(spheres[:, 3].min()), 0.5 * texel))
    return face_box_bounds(uvs, bound, settings.size, BOUND_GRID).reshape(-1)


def _world_per_uv(world: np.ndarray, uvs: np.ndarray) -> float:
    """World area per unit of UV area over the target (its texels' world size squared, times
    size^2)."""
    world_area = 0.5 * np.linalg.norm(np.cross(world[:, 1] - world[:, 0], world[:, 2] - world[:, 0]), axis=1).sum()
    e1, e2 = uvs[:, 1] - uvs[:, 0], uvs[:, 2] - uvs[:, 0]
    uv_area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()
    return float(world_area / max(uv_area, 1e-300))


def _with_bound(noise: ErrorEstimate, previous: ErrorEstimate, kept_bound: float) -> ErrorEstimate:
    """noise's estimate with the kept cells' bound added (RMSE in quadrature, p99 plainly) and
    previous's visibility floor."""
    return ErrorEstimate(math.hypot(noise.rmse, kept_bound), noise.p99 + kept_bound, noise.directions,
                         floor_rmse=previous.floor_rmse, floor_p99=previous.floor_p99,
                         floor_texels=previous.floor_texels, floor_unmeasured=previous.floor_unmeasured)


def _merged(previous: BakeResult, part: BakeResult, redo: np.ndarray, settings: BakeSettings,
            kept_bound: float) -> BakeResult:
    """previous with the re-baked cells' values (and twins) from part, margins grown again;
    its error the merged twins' with the kept cells' bound added."""
    fresh = redo & part.covered
    values = np.where(fresh, part.ao, previous.ao)
    ao = regrown(values, previous.covered, previous, settings.margin)
    twin = None
    error = previous.error
    if previous.twin is not None and part.twin is not None:
        twin = np.where(fresh, part.twin, previous.twin).astype(np.float32)
        error = _with_bound(estimate(twin, previous.covered, previous.error.directions), previous.error, kept_bound)
    return replace(previous, ao=ao, twin=twin, error=error)


# What a bake keeps beside its map for the next re-bake (the command line's sidecar file,
# record_path): the scene's state and the float map with its masks and twins.
RECORD_SUFFIX = ".hao-rebake.npz"
RECORD_VERSION = 1


def record_path(map_path: str) -> str:
    """The record kept beside a map file."""
    return map_path + RECORD_SUFFIX


def record_bytes(state: SceneState, result: BakeResult) -> bytes:
    """state and result (an image bake's: ao, covered, filled, twin, error, method) as an
    .npz file's bytes."""
    meta = {"version": RECORD_VERSION, "settings_key": state.settings_key, "target_layout": state.target_layout,
            "soups": list(state.soups), "method": result.method,
            "error": None if result.error is None else dataclasses.asdict(result.error)}
    arrays = {"ao": result.ao, "covered": result.covered, "filled": result.filled}
    for name in ("twin", "kept_offset"):
        if getattr(result, name) is not None:
            arrays[name] = getattr(result, name)
    for k, soup in enumerate(state.soups.values()):
        arrays[f"prints{k}"], arrays[f"spheres{k}"] = soup.fingerprints, soup.spheres
    scene = _scene_arrays(state.scene)
    if scene is not None:
        meta["scene"], kept = scene
        arrays.update(kept)
    out = io.BytesIO()
    np.savez_compressed(out, meta=np.frombuffer(json.dumps(meta).encode(), np.uint8), **arrays)
    return out.getvalue()


def read_record(data: bytes) -> tuple[BakeResult, SceneState] | None:
    """(the earlier bake, its scene's state) of record_bytes' bytes; None for a record this
    version cannot read (a re-bake is then full, and says so)."""
    try:
        with np.load(io.BytesIO(data), allow_pickle=False) as npz:
            meta = json.loads(bytes(npz["meta"]).decode())
            if meta.get("version") != RECORD_VERSION:
                return None
            soups = {name: SoupState(npz[f"prints{k}"], npz[f"spheres{k}"]) for k, name in enumerate(meta["soups"])}
            error = None if meta["error"] is None else ErrorEstimate(**meta["error"])
            optional = {name: npz[name] if name in npz.files else None for name in ("twin", "kept_offset")}
            result = BakeResult(npz["ao"], npz["covered"], npz["filled"], {"method": meta["method"]}, error=error,
                                method=meta["method"], **optional)
            scene = _scene_of(meta.get("scene"), npz)
    except (OSError, ValueError, KeyError, TypeError, json.JSONDecodeError):
        return None
    return result, SceneState(meta["settings_key"], meta["target_layout"], soups, scene)


def _scene_arrays(scene: tuple | None) -> tuple[list[str], dict] | None:
    """(the soups' names, their arrays) of a state's scene for the record, the target first
    (positions exact, and the target's UVs: what a re-bake by difference draws of the scene
    before, rebake_difference.py); None without one, or where a soup lets light through
    (which a difference cannot measure)."""
    if scene is None or any(soup.alpha is not None for soup in [scene[0], *scene[1]]):
        return None
    target, occluders = scene
    arrays = {"scene_uvs": target.uvs, **{f"scene{k}": soup.positions for k, soup in enumerate([target, *occluders])}}
    return [soup.name for soup in [target, *occluders]], arrays


def _scene_of(names: list[str] | None, npz) -> tuple | None:
    """The (target, occluders) _scene_arrays kept, or None."""
    if names is None:
        return None
    soups = [TriangleSoup(npz[f"scene{k}"], npz["scene_uvs"] if k == 0 else None, name) for k, name in enumerate(names)]
    return soups[0], soups[1:]

