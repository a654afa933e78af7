# SPDX-License-Identifier: GPL-3.0-or-later
"""Contacts traced exactly: the texels in contact with another surface (core/bake/contacts.py),
where a baker's depth slack hides what touches them (abilities.traces_contacts: the gather),
get the reference's sums along the bake's own directions, replicate by replicate, in place of
the baker's: exact rays, each replicate's cast together by the GPU's grid walk
(bakers.distance_cast_for; a Python call per ray on the CPU was host time no GPU shrinks). No
Blender data: numpy in and out, as hao_addon.bake.

Why exact rays and not a finer depth map: the gap under a prop resting on a floor goes to 0,
so no light-view resolution resolves it, and the texels it concerns are few (a band about
CONTACT_REACH_PIXELS light-view pixels wide along each contact).
"""
from __future__ import annotations

import time
from typing import Generator

import numpy as np

from .core.bake.abilities import declaration
from .core.bake.contacts import contact_points
from .core.bake.plan import BakePlan
from .core.directions import replicate_sizes
from .core.steps import relay
from .floor_check import START_OFFSET_PIXELS

# A receiver is in contact with a face within this many light-view pixels (the gather's depth
# slack, DEPTH_BIAS_PIXELS of depth plus its slope's SLOPE_BIAS_PIXELS, read up to 0.71 pixel
# beside the receiver, hides occluders about a pixel away along a ray).
# Measured on a torus resting on a floor (256^2, 128 directions, against the reference): 0.5
# left contact texels 0.86 too bright, 1.0 and 2.0 left none over 0.06 (the gather's floor elsewhere).
CONTACT_REACH_PIXELS = 1.0


def contact_cells(plan: BakePlan) -> np.ndarray:
    """(k,) sorted flat output cells whose receivers are in contact with a drawn face (of
    plan.cells alone where the run names them)."""
    reach = CONTACT_REACH_PIXELS * plan.pixel_size
    candidates, partners = plan.layout.contact_candidates(plan, reach)
    if len(candidates) == 0 or len(partners) == 0:
        return np.zeros(0, np.int64)
    found = contact_points(candidates.points, candidates.geometric, plan.drawn_positions[partners], reach)
    cells = np.unique(candidates.texel[found])
    return cells if plan.cells is None else np.intersect1d(cells, plan.cells)


def traced_contacts_steps(plan: BakePlan, baker, count: int, sums: tuple, shared: dict
                          ) -> Generator[float, None, dict]:
    """The bake's texels in contact with another surface traced exactly (_traced_steps) from
    the live baker's own sample points, along its directions, where its method declares it
    (abilities.traces_contacts); found once for the rounds of a bake to an error
    (shared["contact_cells"]; a round of some cells traces those among them). Returns the
    counters (texels, rays, seconds; none for another method); yields no progress of its own
    (each step a cancel point)."""
    if not declaration(plan.method).traces_contacts:
        return {}
    t0 = time.perf_counter()
    if "contact_cells" not in shared:
        shared["contact_cells"] = contact_cells(plan.with_cells(None))
    cells = shared["contact_cells"]
    cells = cells if plan.cells is None else np.intersect1d(cells, plan.cells)
    counters = dict(contact_texels=0, contact_rays=0)
    if len(cells):
        order = np.asarray(getattr(baker, "direction_order", np.arange(count)))
        # Where UV islands overlap, a texel has a point on each (the CPU's raster keeps one).
        receivers = baker.sample_receivers(cells) if hasattr(baker, "sample_receivers") else None
        counters = yield from relay(_traced_steps(plan, cells, order, count, sums, receivers), lambda _fraction: 1.0)
    return {**counters, "contact_seconds": time.perf_counter() - t0}


def _traced_steps(plan: BakePlan, cells: np.ndarray, order: np.ndarray, count: int,
                  sums: tuple[np.ndarray | None, np.ndarray], receivers=None) -> Generator[float, None, dict]:
    """Replace each replicate's sums (sums_a or None, sums_b; each (*output_shape, channels),
    in place) at `cells` by the CPU reference's along the same directions (order: the baker's
    direction of each step; the first replicate_sizes(count)[0] steps are the first
    replicate). Yields progress in [0, 1]; returns the counters."""
    from .bakers import distance_cast_for  # deferred: mathutils comes with bpy, the GPU's with a context
    from .core.bake.reference_baker import ReferenceBaker
    split = replicate_sizes(count)[0] if sums[0] is not None else 0
    # Every direction of each replicate: the texel's noise is the map's (the twins state it),
    # and no band of other noise marks the contacts.
    parts = [(sums[0], order[:split]), (sums[1], order[split:count])] if sums[0] is not None else [(sums[1], order[:count])]
    # A GPU's float32 points start off the surface as the floor check's do.
    baker = ReferenceBaker(plan.with_cells(cells), receivers, START_OFFSET_PIXELS * plan.pixel_size)
    cast = distance_cast_for(plan.method)  # a replicate's rays at once: the GPU's grid walk
    channels = plan.estimator.channel_count
    try:
        for k, (part, steps) in enumerate(parts):
            if k:
                baker.restart()
            baker.run_directions(steps, cast)
            yield (k + 1) / len(parts)
            part.reshape(-1, channels)[cells] = baker.accumulated_at(cells)
    finally:
        baker.free()
    return dict(contact_texels=int(len(cells)), contact_rays=int(baker.stats["rays_traced"]))
