# SPDX-License-Identifier: GPL-3.0-or-later
"""Cycles' shadow-terminator geometry offset, so that bakes of smooth-shaded meshes match
Cycles' own (the per-object *Shadow Terminator > Geometry Offset*, default 0.1).

A smooth-shaded triangle mesh is shaded as a curved surface but traced as flat facets, so
directions that graze a facet, and those above the shading hemisphere but just below the
facet, see the neighbouring facets and darken in bands along the triangles. Cycles
(kernel/light/sample.h, shadow_ray_offset and shadow_ray_smooth_surface_offset) starts
such rays from a point lifted off the facet to the smooth surface its corner normals
describe: P + amount * n * h, n the interpolated (unnormalized) corner normal, h a
parabolic height capped by a local linear envelope, amount a ramp that is 1 for directions
at or below the facet and fades out over `cutoff` of cos(theta). Measured against Cycles'
smooth bakes (256^2, 1024 samples): the ray-traced reference's bias goes from -0.0017 to
+0.0001 on Spot and from -0.0008 to -0.0001 on the rocker arm.

The GLSL twin of both functions is gpu_shaders/bake_terminator.glsl.
"""
from __future__ import annotations

import numpy as np

# A lift (normalized units: the drawn scene's radius is 1) shorter than this leaves a ray start
# on its facet, and a direction below the facet then counts as occluded. One threshold for every
# baker and the bench's truth (bench/truth.py): the reference once lifted above its own ray
# offset and the truth above 10x that, and on smooth fandisk's crease faces (shading 45 degrees
# off the facet) the two read 0.96 and 0.85 at the same points.
MIN_LIFT = 1e-6


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("md,md->m", a, b)


def smooth_surface_lift(triangles: np.ndarray, corner_normals: np.ndarray, bary: np.ndarray,
                        geometric: np.ndarray) -> np.ndarray:
    """(m, 3) n * h: how far Cycles lifts a ray start at full offset amount.

    triangles: (m, 3, 3) the facet's corners; corner_normals: (m, 3, 3) their shading normals
    (unit); bary: (m, 3) the point's barycentric weights of those corners; geometric: (m, 3)
    the facet's normal. Zero on flat facets (all corner normals equal the face's)."""
    v0, v1, v2 = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    n0, n1, n2 = corner_normals[:, 0], corner_normals[:, 1], corner_normals[:, 2]
    u, v, w = bary[:, 0], bary[:, 1], bary[:, 2]
    p = v0 * u[:, None] + v1 * v[:, None] + v2 * w[:, None]
    n = n0 * u[:, None] + n1 * v[:, None] + n2 * w[:, None]
    # Parabolic approximation of the smooth surface's height over the facet.
    a = _dot(n2 - n0, v0 - v2)
    b = _dot(n2 - n1, v1 - v2)
    c = _dot(n1 - n0, v1 - v0)
    h = a * u * (u - 1.0) + (a + b + c) * u * v + b * v * (v - 1.0)

    def envelope(sign: float, at: np.ndarray) -> np.ndarray:
        """Local linear envelope at the points `at` (indices): the lowest of the corners'
        tangent planes over p (sign +1), or of their planes below it (sign -1, flipped
        normals). Each side is evaluated only where it is used (half the work)."""
        heights = []
        for vk, nk, others in ((v0, n0, (v1, v2)), (v1, n1, (v0, v2)), (v2, n2, (v0, v1))):
            vk, nk, o0, o1 = vk[at], nk[at], others[0][at], others[1][at]
            reach = np.maximum(np.maximum(sign * _dot(o0 - vk, nk), sign * _dot(o1 - vk, nk)), 0.0)
            heights.append(np.maximum(sign * _dot(vk - p[at], nk) + reach, 0.0))
        return np.minimum(np.minimum(heights[0], heights[1]), heights[2])

    facing = _dot(n, geometric) > 0.0
    up, down = np.flatnonzero(facing), np.flatnonzero(~facing)
    lifted = np.empty_like(h)
    lifted[up] = np.maximum(envelope(1.0, up), 0.5 * h[up])
    lifted[down] = np.minimum(-envelope(-1.0, down), 0.5 * h[down])
    return n * lifted[:, None]


def lift_amount(cos_shading: np.ndarray, cos_true: np.ndarray, cutoff: float) -> np.ndarray:
    """How much of the lift a direction gets: cos_shading = omega . shading normal (> 0 for
    the directions a receiver weighs), cos_true = omega . facet normal; cutoff: the
    object's geometry offset (0: never lifted)."""
    if cutoff <= 0.0:
        return np.zeros(np.broadcast(cos_shading, cos_true).shape)
    near_terminator = np.clip(2.0 - (cos_true + cos_shading) / cutoff, 0.0, 1.0)
    grazing = np.clip(1.0 - cos_true / cutoff, 0.0, 1.0)
    return np.where(cos_shading < cutoff, near_terminator, grazing)


def lifted_starts(amount: np.ndarray, lift_length: np.ndarray, min_lift: float = MIN_LIFT) -> np.ndarray:
    """Which ray starts are lifted: amount (lift_amount's, any shape) times the full lift's
    length (broadcast against it) above min_lift (MIN_LIFT in the same units as the lift)."""
    return amount * lift_length > min_lift
