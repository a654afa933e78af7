# SPDX-License-Identifier: GPL-3.0-or-later
"""A re-bake by difference: the cells an edit reaches take the earlier bake's value plus what
the edit changed of it, measured only where the edit can have changed anything.

A gather's value at a cell is N / W per replicate: N the weight of the directions whose light
view shows the receiver lit, W the weight of all of them (no occluder changes W). An edit
changes a light view's depth map only in the pixels its changed faces cover, inside the
projection of the changed spheres (grown by the depth maps' slack, rebake.SLACK_PIXELS). So
one bake at the cells draws each direction's depth map twice, the scene before the edit and
the scene after, cropped to those spheres (BakeRun.window_spheres), and the same dispatch
tests both, the view before subtracting (gpu_shaders/bake_gather.comp, DIFFERENCE): a
receiver whose pixel lies outside reads lit in both, and the sum is what the edit changed of
the earlier N, up to float rounding. Each view costs its window's pixels, a ball's, not the
re-baked cells' (which spread over the map wherever a ball's shadow falls from some
direction), and only the entries in blocks the window reaches are tested (entry_blocks.py).

It needs the scene before the edit (kept with its state, SceneState.scene), the same light
views in both scenes (the same target, the same sphere around everything drawn: the pixel
grids and depth ranges), a baker that crops its views (abilities: crops_views), the AO's
sums alone and nothing that lets light through (the alpha taps read neighbouring pixels).
Elsewhere the cells are baked whole (rebake.py).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Generator

import numpy as np

from .core.bake.abilities import declaration
from .core.bake.bake_run import BakeRun
from .core.bake.plan import BakePlan, make_plan_steps
from .core.bake.scene_changes import SceneState
from .core.bake.normalization import hemisphere_weight
from .core.bake.settings import BakeSettings
from .core.directions import replicate_sizes
from .contact_repair import contact_cells
from .core.steps import relay


@dataclass(frozen=True)
class Difference:
    """What an edit changed of the cells' sums: changed (c,) the indices into the cells of
    those it changed, and at them, replicates a and b (a None with one replicate), the change
    of N and W (the same before and after), in texel_sums' units (each lit receiver weighs 1
    in its texel). traced: (t,) the cells in contact with another surface before or after the
    edit, whose values a whole bake traces exactly (hao_addon/contact_repair.py): a GPU
    difference added to them would not be that value, so they are baked whole."""

    changed: np.ndarray
    change_a: np.ndarray | None
    change_b: np.ndarray
    weight_a: np.ndarray | None
    weight_b: np.ndarray
    stats: dict
    traced: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))


def _same_views(a: BakePlan, b: BakePlan) -> bool:
    """Both plans fit the same light views: the same pixel grids and depth ranges."""
    return (a.scale == b.scale and np.array_equal(a.centre, b.centre) and a.pixel_size == b.pixel_size
            and a.max_view_side == b.max_view_side and np.array_equal(a.drawn_sphere[0], b.drawn_sphere[0])
            and a.drawn_sphere[1] == b.drawn_sphere[1] and np.array_equal(a.target_points, b.target_points)
            and np.array_equal(a.directions, b.directions))


def _why_not(plans: tuple[BakePlan, BakePlan]) -> str:
    """Why the cells cannot be re-baked by difference, or ''."""
    old, new = plans
    if not declaration(new.method).crops_views or old.method != new.method:
        return f"the {declaration(new.method).label} bakes the cells whole"
    if new.alpha is not None or old.alpha is not None:
        return "occluders that let light through"
    if new.layered:
        return "a max distance's depth lists"
    if not new.layout.gpu_lists_receivers:
        return "its receivers are sampled on the CPU (sub-texel samples)"
    if not _same_views(old, new):
        return "the edit moved the bounds of what is drawn (other light views)"
    return ""


def difference_steps(before: SceneState, settings: BakeSettings, after_scene: tuple, cells: np.ndarray,
                     spheres: np.ndarray) -> Generator[float, None, Difference | str]:
    """What the edit from before's scene to after_scene ((target, occluders)) changed of the
    sums of `cells` (k,) flat indices, read in views cropped to `spheres` (s, 4) world (the
    changed spheres, grown by the slack); or why it cannot be measured so (a str)."""
    if before.scene is None:
        return "the scene before the edit is not kept"
    run = BakeRun.of(settings).with_cells(np.asarray(cells, np.int64)).with_windows(np.asarray(spheres, np.float64))
    plans = []
    for k, (target, occluders) in enumerate((before.scene, after_scene)):
        plan = yield from relay(make_plan_steps(target, occluders, settings, run=run), lambda f, k=k: 0.05 * (k + f))
        plans.append(plan)
    why = _why_not(tuple(plans))
    if why:
        return why
    plan = replace(plans[1], before_drawn=(plans[0].drawn_positions, plans[0].holes))
    found = yield from relay(_entry_sums_steps(plan), lambda f: 0.1 + 0.9 * f)
    if found is None:
        return "its receivers are uploaded (sub-texel samples)"
    traced = np.zeros(0, np.int64)
    if declaration(plan.method).traces_contacts:
        traced = np.intersect1d(np.union1d(*(contact_cells(p.with_cells(None)) for p in plans)), cells)
    return replace(_texel_difference(*found, plan, cells), traced=traced)


@dataclass(frozen=True)
class _EntrySums:
    """A bake by difference's texel list: its receivers (n) in list order, their sums (n, 2)
    per replicate (a None with one: the change of N, and W of the directions tested), and the
    directions (m, 3) of each replicate."""

    receivers: object
    sums_a: np.ndarray | None
    sums_b: np.ndarray
    directions_a: np.ndarray
    directions_b: np.ndarray
    # (m,) the texel class each of those directions serves (core/bake/interleave.py)
    classes_a: np.ndarray
    classes_b: np.ndarray


def _entry_sums_steps(plan: BakePlan) -> Generator[float, None, tuple[_EntrySums, dict] | None]:
    """Run plan's bake by difference (at its cells, views cropped, the scene before drawn
    too) keeping each entry's sums per replicate; None where its list is not the GPU raster's
    (entry_state)."""
    from .bakers import baker_for  # deferred: needs a GPU context
    baker_cls = baker_for(plan.method)
    baker_cls.check_limits(plan)
    baker = baker_cls(plan)
    try:
        count = plan.direction_count
        split = replicate_sizes(count)[0]
        state_a = None
        for i in range(count):
            if i == split:
                state_a = baker.entry_state()
                baker.restart()
            baker.run_direction(i)
            yield (i + 1) / count
        state_b = baker.entry_state()
        stats = dict(baker.stats)
        order = plan.directions[baker.direction_order]
        served = baker.served_classes(baker.direction_order)
    finally:
        baker.free()
    if state_b is None:
        return None
    sums_a = None if state_a is None else state_a[1].astype(np.float64)
    return _EntrySums(state_b[0], sums_a, state_b[1].astype(np.float64), order[:split], order[split:],
                       served[:split], served[split:]), stats


def _entry_weights(receivers, directions: np.ndarray, settings: BakeSettings, receiver_class: np.ndarray,
                   direction_class: np.ndarray) -> np.ndarray:
    """(n,) each receiver's W over directions (m, 3) of its texel class (receiver_class (n,),
    direction_class (m,)): the weight the bake gives each direction whatever it sees (the
    gather's VIEW_WEIGHT times the receiver's scale), which the skipped blocks of a cropped
    view never add (entry_blocks.py)."""
    total = np.zeros(len(receivers.points))
    for texel_class in np.unique(receiver_class):
        at, own = np.flatnonzero(receiver_class == texel_class), directions[direction_class == texel_class]
        rows = max(1, (1 << 20) // max(1, len(own)))
        for first in range(0, len(at), rows):
            cos = receivers.shading[at[first:first + rows]] @ own.T
            total[at[first:first + rows]] = hemisphere_weight(cos, settings.weighting, settings.spread_cos).sum(axis=1)
    return total * receivers.inv_s


def _texel_difference(entries: _EntrySums, stats: dict, plan: BakePlan, cells: np.ndarray) -> Difference:
    """The Difference at cells of a bake by difference's entry sums: per replicate, each
    entry's change of N over its whole W (texel_sums' normalization: each lit receiver weighs
    1 in its texel), summed per texel, and the texel's count of lit receivers; at the texels
    some entry of which changed alone (W, a sum over every direction, is computed for their
    entries only)."""
    texel = np.searchsorted(cells, entries.receivers.texel)
    replicates = [(sums, d, c) for sums, d, c in ((entries.sums_a, entries.directions_a, entries.classes_a),
                                                  (entries.sums_b, entries.directions_b, entries.classes_b))
                  if sums is not None]
    moved = np.zeros(len(texel), bool)
    for sums, _d, _c in replicates:
        moved |= sums[:, 0] != 0.0
    changed = np.unique(texel[moved])
    marked = np.zeros(len(cells), bool)
    marked[changed] = True
    involved = marked[texel]
    receivers, at = entries.receivers.subset(involved), np.searchsorted(changed, texel[involved])
    parts = []
    receiver_class = plan.receiver_classes(receivers.texel)
    for sums, directions, direction_class in replicates:
        weight = _entry_weights(receivers, directions, plan.settings, receiver_class, direction_class)
        lit = weight > 0.0
        change = np.divide(sums[involved, 0], weight, out=np.zeros(len(weight)), where=lit)
        parts.append((np.bincount(at, weights=change, minlength=len(changed)),
                      np.bincount(at, weights=lit.astype(np.float64), minlength=len(changed))))
    first = parts[0] if len(parts) == 2 else (None, None)
    return Difference(changed, first[0], parts[-1][0], first[1], parts[-1][1], stats)


def merged_by_difference(ao: np.ndarray, twin: np.ndarray | None, difference: Difference
                         ) -> tuple[np.ndarray, np.ndarray | None]:
    """((k,) the cells' values, (k,) their twins or None) of an earlier bake's ao and twin at
    the cells (k,) with the difference added where it changed them (elsewhere they stay, bit
    for bit). The earlier replicates' own values follow from ao = (N_a + N_b) / W and
    twin = (x_a - x_b) / 2 with x = N / W_rep: x_a = ao + 2 twin W_b / W, x_b = ao - 2 twin W_a / W."""
    d = difference
    values = ao.astype(np.float32).copy()
    twins = None if twin is None or d.change_a is None else twin.astype(np.float32).copy()
    base = ao[d.changed].astype(np.float64)
    if d.change_a is None:  # one replicate: no twin
        values[d.changed] = np.clip(base + d.change_b / d.weight_b, 0.0, 1.0)
        return values, None
    weight = d.weight_a + d.weight_b
    values[d.changed] = np.clip(base + (d.change_a + d.change_b) / weight, 0.0, 1.0)
    if twins is None:
        return values, None
    pair = twin[d.changed].astype(np.float64)
    both = (d.weight_a > 0.0) & (d.weight_b > 0.0)
    safe_a, safe_b = np.where(both, d.weight_a, 1.0), np.where(both, d.weight_b, 1.0)
    x_a = base + 2.0 * pair * d.weight_b / weight + d.change_a / safe_a
    x_b = base - 2.0 * pair * d.weight_a / weight + d.change_b / safe_b
    twins[d.changed] = np.where(both, 0.5 * (np.clip(x_a, 0.0, 1.0) - np.clip(x_b, 0.0, 1.0)), 0.0)
    return values, twins
