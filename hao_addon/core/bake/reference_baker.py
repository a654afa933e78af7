# SPDX-License-Identifier: GPL-3.0-or-later
"""The bakers' CPU twin: the same estimator as the GPU passes, with visibility ray traced
(mathutils' BVH) instead of read from depth maps.

Same interface as ScatterBaker and GatherBaker (check_limits, construction from a plan,
run_direction, accumulated, stats, free) and behind the same factory (hao_addon.bakers), so
every bake test runs it on the scenes the GPU passes bake. Receivers are the texel centres
of the target's UV layout (as the gather's), their sub-texel samples, or the high-poly
points of a Selected-to-Active bake (core/bake/receivers.py); per direction each adds (V w, w) with
w = weight(omega . n_s) / S interpolated like the GPU passes interpolate them, and V the
visibility (the estimator, core/bake/estimators.py, turns (w, V, omega) into its sums): one ray towards the light with the plan's max distance, falloff and back-face
rule, from the receiver or, where Cycles' terminator offset lifts it (core/bake/terminator.py),
from the lifted point; 0 for a direction below the true surface that is not lifted (such a ray
would enter the surface, as it does in Cycles' AO pass). Slow (a Python
call per ray): for tests and for checking a GPU bake, never a silent substitute for one.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mathutils import Vector

from ..errors import BakeInputError
from ..kernels import occlusion_weight
from .estimators import texel_sums, texel_sums_at
from .normalization import hemisphere_weight
from .plan import BakePlan
from .terminator import lift_amount, lifted_starts
from ..reference import build_bvh, first_hits, hits_along, ray_offset
from .alpha import expected_visibility
from .projection import DistanceCast, barycentric
from .receivers import Receivers

# Rays one reference bake may trace (about 4 us each here): beyond this it would run for
# minutes, which nobody asks for by accident.
MAX_REFERENCE_RAYS = 20_000_000


class ReferenceBaker:
    """Ray-traced twin of the GPU bake passes for one plan."""

    METHOD = "reference"

    @staticmethod
    def rays_needed(plan: BakePlan) -> int:
        """Rays of a whole bake at most (one per receiver and direction)."""
        if plan.cells is not None:
            return len(plan.cells) * plan.settings.sample_count * plan.texel_directions
        return plan.layout.receiver_bound() * plan.texel_directions

    @classmethod
    def check_limits(cls, plan: BakePlan) -> None:
        """Refuse what the reference cannot bake (core/bake/abilities.py; nothing today), or
        a bake that would trace more than MAX_REFERENCE_RAYS rays."""
        plan.check_method(cls.METHOD)
        rays = cls.rays_needed(plan)
        if rays > MAX_REFERENCE_RAYS:
            raise BakeInputError(
                f"the reference (CPU ray tracing) bake would trace up to {rays:,} rays "
                f"(size^2 x samples per texel x directions), "
                f"more than its limit of {MAX_REFERENCE_RAYS:,}; use a smaller map, fewer directions or a GPU method")

    def __init__(self, plan: BakePlan, receivers: Receivers | None = None, min_offset: float = 0.0) -> None:
        """receivers: trace from these instead of the plan's (a GPU bake's own sample points,
        hao_addon/floor_check.py); min_offset: rays start at least this far off the surface
        (normalized units; float32 points off their face need more than ray_offset)."""
        self.plan = plan
        receivers = plan.receivers() if receivers is None else receivers  # plan.cells' alone where it names them
        receivers = receivers.subset(receivers.inv_s > 0.0)
        self.texel = receivers.texel
        # Each texel class's receivers (core/bake/interleave.py), or None: every direction serves all.
        self.served = None
        if plan.classes > 1:
            receiver_class = plan.receiver_classes(self.texel)
            self.served = [np.flatnonzero(receiver_class == k) for k in range(plan.classes)]
        self.points, self.shading, self.inv_s = receivers.points, receivers.shading, receivers.inv_s
        self.geometric = receivers.geometric
        scene = plan.drawn_positions.astype(np.float64)
        self.scene = scene
        self.bvh = build_bvh(scene)
        self.face_normals = plan.drawn_normals.astype(np.float64) if plan.settings.ignore_back_faces else None
        flat = scene.reshape(-1, 3)
        radius = float(np.linalg.norm(flat.max(0) - flat.min(0))) / 2.0
        self.offsets = np.array([max(ray_offset(p, radius), min_offset) for p in self.points])
        self.origin_points = self.points + self.geometric * self.offsets[:, None]
        self.lift = receivers.lift
        self.estimator = plan.estimator
        self.sums = np.zeros((len(self.points), self.estimator.channel_count))
        self.stats = dict(receivers=len(self.points), rays_traced=0, rays_lifted=0, rays_below_surface=0,
                          directions_done=0, shading_normals=plan.smooth_shading)

    def run_direction(self, index: int) -> None:
        """Trace direction `index` of the plan from every receiver it serves (with texel
        classes, core/bake/interleave.py, those of its class) and add their terms."""
        rays = self._rays(index)
        self._add(rays, self._cpu_distances(rays))

    def run_directions(self, indices: np.ndarray, cast: DistanceCast | None = None) -> None:
        """run_direction of each of `indices`, their rays cast together by `cast` (origins
        (m, 3), unit directions (m, 3), the scene's triangles (F, 3, 3), reach -> (m,) first-hit
        distances, inf for none: gpu/bake_ray_cast.first_hit_distances) where the bake's rays
        are plain ones (can_cast_together), else one direction after another on the CPU."""
        if cast is None or not self.can_cast_together:
            for index in indices:
                self.run_direction(int(index))
            return
        batches = [self._rays(int(index)) for index in indices]
        origins = np.concatenate([np.zeros((0, 3))] + [b.origins for b in batches])
        aims = np.concatenate([np.zeros((0, 3))] + [np.broadcast_to(b.omega, b.origins.shape) for b in batches])
        distances = cast(origins, aims, self.scene, self._reach())
        ends = np.cumsum([0] + [len(b.origins) for b in batches])
        for batch, first, end in zip(batches, ends[:-1], ends[1:]):
            self._add(batch, distances[first:end])

    @property
    def can_cast_together(self) -> bool:
        """Every ray is one first hit (no surface that lets light through, no back face or
        near occluder to pass by): a batch of them is one cast."""
        settings = self.plan.settings
        return self.plan.alpha is None and self.face_normals is None and settings.min_distance == 0.0

    def _reach(self) -> float:
        return self.plan.max_distance_normalized if self.plan.settings.max_distance > 0.0 else 1e30

    def _rays(self, index: int) -> "_Rays":
        """The rays of direction `index` from the receivers it serves: from each lit receiver
        above its true surface, or from its terminator lift where that lifts it."""
        settings = self.plan.settings
        at = self.served[self.plan.direction_class[index]] if self.served is not None else slice(None)
        omega = self.plan.directions[index]
        cos_shading = self.shading[at] @ omega
        weight = hemisphere_weight(cos_shading, settings.weighting, settings.spread_cos) * self.inv_s[at]
        cos_true = self.geometric[at] @ omega
        above = cos_true > 0.0
        lifted = np.zeros(len(weight), bool)
        if self.lift is not None:
            lift = self.lift[at]
            amount = lift_amount(cos_shading, cos_true, settings.terminator_offset)
            lifted = (weight > 0.0) & lifted_starts(amount, np.linalg.norm(lift, axis=1))
        plain, lifted_at = np.flatnonzero(above & (weight > 0.0) & ~lifted), np.flatnonzero(lifted)
        starts = [self.origin_points[at][plain]]
        if len(lifted_at):
            starts.append(self.points[at][lifted_at] + lift[lifted_at] * amount[lifted_at, None])
        return _Rays(at, omega, weight, above, lifted, np.concatenate([plain, lifted_at]), np.concatenate(starts),
                     self.offsets[at])

    def _cpu_distances(self, rays: "_Rays") -> np.ndarray | None:
        """The rays' first-hit distances by the CPU's BVH; None where surfaces let light through
        (their visibility is computed per ray in _add)."""
        if self.plan.alpha is not None:
            return None
        origins = [Vector(p) for p in rays.origins]
        return first_hits(self.bvh.ray_cast, origins, rays.omega, self._reach(), rays.offsets[rays.traced],
                          self.face_normals, self.plan.min_distance_normalized)

    def _add(self, rays: "_Rays", distances: np.ndarray | None) -> None:
        """Add the terms of rays whose first hits lie at `distances` (None: trace each through
        what lets light through)."""
        settings = self.plan.settings
        d_max = self.plan.max_distance_normalized if settings.max_distance > 0.0 else 0.0
        dists = np.zeros(len(rays.weight))  # below the true surface: occluded
        if distances is not None:
            dists[rays.traced] = distances
            visible = 1.0 - occlusion_weight(dists, d_max, settings.falloff)
        else:  # every surface up to the first opaque one, each kept with its alpha (core/bake/alpha.py)
            visible = 1.0 - occlusion_weight(dists, d_max, settings.falloff)  # 0 below the surface
            for i, origin in zip(rays.traced, rays.origins):
                visible[i] = self._visible_through(Vector(origin), rays.omega, self._reach(), rays.offsets[i], d_max)
        self.sums[rays.at] += self.estimator.terms(rays.weight, visible, rays.omega)
        self.stats["rays_traced"] += len(rays.traced)
        self.stats["rays_lifted"] += int(rays.lifted.sum())
        self.stats["rays_below_surface"] += int(((rays.weight > 0.0) & ~rays.above & ~rays.lifted).sum())
        self.stats["directions_done"] += 1

    def _visible_through(self, origin: Vector, omega: np.ndarray, reach: float, offset: float, d_max: float
                         ) -> float:
        """A ray's expected visibility through surfaces that let light through."""
        alpha, settings = self.plan.alpha, self.plan.settings
        kept_of = {}

        def opaque(face: int, point: np.ndarray) -> bool:
            bary = barycentric(point[None], self.scene[face][None])
            kept_of[face, tuple(point)] = float(alpha.kept_weight(alpha.face_alpha(np.array([face]), bary))[0])
            return kept_of[face, tuple(point)] >= 1.0

        hits = hits_along(self.bvh.ray_cast, origin, omega, reach, offset, self.face_normals, opaque,
                          min_distance=self.plan.min_distance_normalized)
        kept = [kept_of[face, tuple(point)] for _d, face, point in hits]
        occlusion = occlusion_weight(np.array([d for d, _f, _p in hits]), d_max, settings.falloff)
        return expected_visibility(kept, list(occlusion))

    def accumulated(self) -> np.ndarray:
        """(*plan.output_shape, channels) float64: the estimator's sums per texel (or element)."""
        return texel_sums(self.texel, self.sums, self.plan.output_shape)

    def accumulated_at(self, cells: np.ndarray) -> np.ndarray:
        """(k, channels) float64: accumulated() at the sorted flat cells (k,) alone."""
        return texel_sums_at(self.texel, self.sums, np.asarray(cells, np.int64))

    def restart(self) -> None:
        """Zero the sums (after accumulated()): the next directions are summed apart."""
        self.sums[:] = 0.0

    def free(self) -> None:
        """Nothing on the GPU; drops the BVH."""
        self.bvh = None


@dataclass
class _Rays:
    """One direction's rays from the receivers `at` it serves: omega (3,); weight, above,
    lifted (k,) per receiver; traced (t,) which of them cast a ray, from origins (t, 3)
    (normalized); offsets (k,) their self-intersection offsets."""

    at: np.ndarray | slice
    omega: np.ndarray
    weight: np.ndarray
    above: np.ndarray
    lifted: np.ndarray
    traced: np.ndarray
    origins: np.ndarray
    offsets: np.ndarray
