# SPDX-License-Identifier: GPL-3.0-or-later
"""Re-bake only what an edit changed, with a stated bound on what is kept.

A bake records its scene (core/bake/scene_changes.SceneState: the settings' key, the target's
layout, every soup's chunks). The next bake of the same target compares the edited scene's
state with it: the changed chunks' spheres, before and after, bound how much each receiver's
AO can have moved (core/bake/change_bound.py, (r / D)^2 for cosine weighting); cells whose
bound stays below KEEP_SHARE of the map's stated RMSE keep their value, the others are baked
again (the plan's cells: only the bakers that bake a subset spend less), and the map's margins
grow again from the merged values. A change of any setting that changes pixels, of the
target's UVs or faces, a bake to an error, bent normals, colour attributes and UDIM tiles re-bake
in full (said in the report).
Nothing here touches Blender data.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Generator

import numpy as np

from .bake import BakeResult, bake_cells_steps, bake_steps, regrown
from .core.bake.abilities import declaration
from .core.bake.change_bound import cell_bound, change_bound, face_box_bounds, refined_piece_bounds, \
    sampled_change_bound
from .core.bake.error_estimate import ErrorEstimate, estimate
from .core.bake.plan import make_plan_steps
from .core.bake.scene_changes import SceneState, changed_spheres, scene_state
from .core.bake.settings import BakeSettings
from .core.bake.target_kinds import target_kind
from .core.bake.udim import udim_layout
from .core.geometry import TriangleSoup
from .core.steps import drain, relay

# Cells whose bound is below this share of the map's stated RMSE are kept: kept cells then add
# at most half the stated RMSE (in quadrature, the map's RMSE grows by at most 12 %), and the
# report states the largest bound among them.
KEEP_SHARE = 0.5


@dataclass(frozen=True)
class RebakeReport:
    """What a re-bake did: full (and why) or the cells baked again of those covered; the
    largest bound among kept cells and the threshold they were kept under."""

    full: bool
    why: str
    rebaked: int
    covered: int
    kept_bound: float = 0.0
    threshold: float = 0.0
    # The cells baked again (flat indices into the map), None for a full bake or none.
    cells: np.ndarray | None = field(default=None, compare=False, repr=False)

    def text(self) -> str:
        if self.full:
            return f"re-baked in full: {self.why}"
        return (f"re-baked {self.rebaked} of {self.covered} texels ({self.why}); the {self.covered - self.rebaked} "
                f"kept are within {self.kept_bound:.2g} of the edited scene's AO (kept below {self.threshold:.2g})")

    def as_dict(self) -> dict:
        return {"full": self.full, "why": self.why, "rebaked": self.rebaked, "covered": self.covered,
                "kept_bound": self.kept_bound, "threshold": self.threshold}


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


def rebake_steps(previous: BakeResult | None, before: SceneState | None, target: TriangleSoup,
                 occluders: list[TriangleSoup], settings: BakeSettings
                 ) -> Generator[float, None, tuple[BakeResult, SceneState, RebakeReport]]:
    """The edited scene's bake, from previous (a bake of before's scene with the same settings)
    where the edit cannot have changed a cell by KEEP_SHARE of its stated RMSE; yields progress.
    Returns (the map, the state to record for the next re-bake, what was done)."""
    after = record(target, occluders, settings)
    reason = _full_reason(previous, before, after, target, settings)
    if reason:
        result = yield from bake_steps(target, occluders, settings, use_cache=False)
        return result, after, RebakeReport(True, reason, int(result.covered.sum()), int(result.covered.sum()))
    spheres = changed_spheres(before, after)
    covered = int(previous.covered.sum())
    if len(spheres) == 0:
        yield 1.0
        return previous, after, RebakeReport(False, "nothing changed", 0, covered)
    threshold = KEEP_SHARE * previous.error.rmse
    bounds = yield from relay(_cell_bounds(target, occluders, settings, spheres, threshold), lambda f: 0.1 * f)
    redo = previous.covered.reshape(-1) & (bounds >= threshold)
    kept = previous.covered.reshape(-1) & ~redo
    kept_bound = float(bounds[kept].max()) if kept.any() else 0.0
    why = f"{len(spheres)} changed parts"
    if not redo.any():
        yield 1.0
        kept = replace(previous, error=_with_bound(previous.error, previous.error, kept_bound))
        return kept, after, RebakeReport(False, why, 0, covered, kept_bound, threshold)
    cells = np.flatnonzero(redo)
    part = yield from relay(bake_cells_steps(target, occluders, settings, cells), lambda f: 0.1 + 0.9 * f)
    merged = _merged(previous, part, redo.reshape(previous.covered.shape), settings, kept_bound)
    return merged, after, RebakeReport(False, why, len(cells), covered, kept_bound, threshold, cells)


def rebake(previous: BakeResult | None, before: SceneState | None, target: TriangleSoup, occluders: list[TriangleSoup],
           settings: BakeSettings) -> tuple[BakeResult, SceneState, RebakeReport]:
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


def _cell_bounds(target: TriangleSoup, occluders: list[TriangleSoup], settings: BakeSettings, spheres: np.ndarray,
                 threshold: float) -> Generator[float, None, np.ndarray]:
    """(cells,) a bound on each output cell's receivers in the edited scene: the larger of what
    the AO can change by (change_bound) and what the bake's own directions can
    (sampled_change_bound), at the receivers themselves or, for maps above
    RECEIVER_BOUND_SIZE, at pieces of the target's faces painted over their UV boxes (cut
    finer where they reach threshold)."""
    plan = yield from make_plan_steps(target, occluders, settings)
    slack = SLACK_PIXELS * plan.pixel_size * plan.scale if declaration(plan.method).gpu else 0.0
    grown = spheres + np.array([0.0, 0.0, 0.0, slack])
    if settings.size <= RECEIVER_BOUND_SIZE:
        return _receiver_bounds(plan, grown, settings)
    return _piece_bounds(plan, grown, settings, threshold)


def _receiver_bounds(plan, spheres: np.ndarray, settings: BakeSettings) -> np.ndarray:
    """(cells,) the largest bound of each cell's receivers."""
    receivers = plan.receivers()
    world = receivers.points * plan.scale + plan.centre
    args = (settings.weighting, settings.spread_angle, settings.max_distance)
    bound = np.maximum(change_bound(world, spheres, *args),
                       sampled_change_bound(world, receivers.shading, spheres, plan.directions, *args))
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
        return np.maximum(change_bound(pieces[:, :3], spheres, *args, reach=pieces[:, 3]),
                          sampled_change_bound(pieces[:, :3], unit, spheres, plan.directions, *args,
                                               reach=pieces[:, 3]))

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
    stats = {**previous.stats, "cache_hit": False, "rebaked_texels": int(redo.sum()),
             "error": None if error is None else error.as_dict()}
    return replace(previous, ao=ao, twin=twin, error=error, stats=stats)
