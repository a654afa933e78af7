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

import numpy as np
from mathutils import Vector

from ..errors import BakeInputError
from ..kernels import occlusion_weight
from .estimators import texel_sums
from .normalization import hemisphere_weight
from .plan import BakePlan
from .terminator import lift_amount, lifted_starts
from ..reference import build_bvh, first_hits, hits_along, ray_offset
from .alpha import expected_visibility
from .projection import barycentric
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
            return len(plan.cells) * plan.settings.sample_count * plan.direction_count
        return plan.layout.receiver_bound() * plan.direction_count

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
        self.points, self.shading, self.inv_s = receivers.points, receivers.shading, receivers.inv_s
        self.geometric = receivers.geometric
        scene = plan.drawn_positions.astype(np.float64)
        self.scene = scene
        self.bvh = build_bvh(scene)
        self.face_normals = plan.drawn_normals.astype(np.float64) if plan.settings.ignore_back_faces else None
        flat = scene.reshape(-1, 3)
        radius = float(np.linalg.norm(flat.max(0) - flat.min(0))) / 2.0
        self.offsets = np.array([max(ray_offset(p, radius), min_offset) for p in self.points])
        self.origins = [Vector(p) for p in self.points + self.geometric * self.offsets[:, None]]
        self.lift = receivers.lift
        self.estimator = plan.estimator
        self.sums = np.zeros((len(self.points), self.estimator.channel_count))
        self.stats = dict(receivers=len(self.points), rays_traced=0, rays_lifted=0, rays_below_surface=0,
                          directions_done=0, shading_normals=plan.smooth_shading)

    def run_direction(self, index: int) -> None:
        """Trace direction `index` of the plan from every receiver and add its terms."""
        settings = self.plan.settings
        omega = self.plan.directions[index]
        cos_shading = self.shading @ omega
        weight = hemisphere_weight(cos_shading, settings.weighting, settings.spread_cos) * self.inv_s
        cos_true = self.geometric @ omega
        above = cos_true > 0.0
        reach = self.plan.max_distance_normalized if settings.max_distance > 0.0 else 1e30
        dists = np.zeros(len(self.points))  # below the true surface: occluded
        ray_cast = self.bvh.ray_cast
        amount = None
        if self.lift is not None:
            amount = lift_amount(cos_shading, cos_true, settings.terminator_offset)
            lifted = (weight > 0.0) & lifted_starts(amount, np.linalg.norm(self.lift, axis=1))
        else:
            lifted = np.zeros(len(self.points), bool)
        d_max = self.plan.max_distance_normalized if settings.max_distance > 0.0 else 0.0
        plain, lifted_at = np.flatnonzero(above & (weight > 0.0) & ~lifted), np.flatnonzero(lifted)
        starts = [(i, self.origins[i]) for i in plain]
        starts += [(i, Vector(self.points[i] + self.lift[i] * amount[i])) for i in lifted_at]
        if self.plan.alpha is None:
            rays = np.concatenate([plain, lifted_at])
            dists[rays] = first_hits(ray_cast, [origin for _i, origin in starts], omega, reach, self.offsets[rays],
                                     self.face_normals, self.plan.min_distance_normalized)
            visible = 1.0 - occlusion_weight(dists, d_max, settings.falloff)
        else:  # every surface up to the first opaque one, each kept with its alpha (core/bake/alpha.py)
            visible = 1.0 - occlusion_weight(dists, d_max, settings.falloff)  # 0 below the surface
            for i, origin in starts:
                visible[i] = self._visible_through(origin, omega, reach, self.offsets[i], d_max)
        self.sums += self.estimator.terms(weight, visible, omega)
        traced = (above & (weight > 0.0)) | lifted
        self.stats["rays_traced"] += int(traced.sum())
        self.stats["rays_lifted"] += int(lifted.sum())
        self.stats["rays_below_surface"] += int(((weight > 0.0) & ~above & ~lifted).sum())
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

    def restart(self) -> None:
        """Zero the sums (after accumulated()): the next directions are summed apart."""
        self.sums[:] = 0.0

    def free(self) -> None:
        """Nothing on the GPU; drops the BVH."""
        self.bvh = None
