# SPDX-License-Identifier: GPL-3.0-or-later
"""An independent truth for bakes: exact ray-traced AO at each texel's sample point, traced by
Embree (embreex), converged with tens of thousands of rays, its own noise measured from two
seeds. It shares nothing with the bakers but the definitions (core/kernels.py's falloff, the
texel centre as a texel's sample point): not their direction sets, not their rasterization,
not the CPU reference's BVH.

A texel's value is the AO at the surface point under its centre (core/bake/uv_raster.py):
accessibility = 1 - E[rho(t)] over cosine-distributed directions about the normal (the face's,
or the interpolated shading normal: then, as in Cycles' AO, a direction below the true face
counts as occluded at distance 0), rays leaving the true surface.

    from truth import texel_truth
    truth = texel_truth(soup, occluders, size=256, rays=32768)   # truth.values (S, S), truth.noise
"""
from __future__ import annotations

import hashlib
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from hao_addon.core.bake.terminator import MIN_LIFT, smooth_surface_lift  # noqa: E402
from hao_addon.core.bake.uv_raster import texel_surface_samples  # noqa: E402
from hao_addon.core.kernels import occlusion_weight  # noqa: E402

# Rays leave p + n * OFFSET * (the baked mesh's radius): past float32 self-hits, far below a
# texel (of the whole scene's radius, a 400-unit ceiling over a 2-unit floor lifted the floor
# by 0.003 and the truth with it).
OFFSET = 1e-5
CHUNK_RAYS = 1 << 21


@dataclass(frozen=True)
class Truth:
    """values: (S, S) accessibility at covered texel centres (0 elsewhere); covered: (S, S)
    bool; noise: RMSE of the values' own Monte Carlo error (from the two seeds' halves)."""

    values: np.ndarray
    covered: np.ndarray
    noise: float


class Samples(NamedTuple):
    """Where a truth is traced: covered (S, S) texels, their points (N, 3) in world units,
    shading and face normals (N, 3), and for a smooth bake with Cycles' terminator offset the
    lift at full amount (N, 3) world units, the offset and the shortest lift that counts
    (terminator.MIN_LIFT in world units: the bakes' own threshold)."""

    covered: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    geometric: np.ndarray
    lift: np.ndarray | None = None
    terminator_offset: float = 0.0
    min_lift: float = 0.0


def texel_samples(soup, size: int, shading: bool, terminator_offset: float = 0.0) -> Samples:
    """The texel centres inside the soup's UV triangles; with shading and a terminator offset,
    their lift as the bakes compute it (normalized by the soup's own bounding sphere, which
    is the bakes' normalization)."""
    face, bary, _hits = texel_surface_samples(soup.uvs, size)
    covered = face >= 0
    faces, weights = face[covered], bary[covered]
    corners = soup.positions[faces]
    points = np.einsum("nk,nkj->nj", weights, corners)
    geometric = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    geometric /= np.maximum(np.linalg.norm(geometric, axis=1, keepdims=True), 1e-300)
    normals = geometric
    if not (shading and soup.normals is not None):
        return Samples(covered, points, normals, geometric)
    normals = np.einsum("nk,nkj->nj", weights, soup.normals[faces])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    if terminator_offset <= 0.0:
        return Samples(covered, points, normals, geometric)
    lift = smooth_surface_lift(corners, soup.normals[faces], weights, geometric)
    return Samples(covered, points, normals, geometric, lift, terminator_offset, MIN_LIFT * _plan_scale(soup))


def _plan_scale(soup) -> float:
    """World units per normalized unit of a bake of `soup` (core/bake/plan.py: the target's
    bounding sphere)."""
    from hao_addon.core.geometry import bounding_sphere
    return bounding_sphere(soup.positions.reshape(-1, 3))[1]


def cosine_directions(normals: np.ndarray, rays: int, rng: np.random.Generator) -> np.ndarray:
    """(N, R, 3): per point, R stratified cosine-weighted directions about its normal, the
    strata rotated at random per point (independent between points)."""
    side = int(np.sqrt(rays))
    gy, gx = np.meshgrid(np.arange(side), np.arange(side), indexing="ij")
    n = len(normals)
    u = (gx.ravel()[None] + rng.random((n, side * side))) / side
    v = (gy.ravel()[None] + rng.random((n, side * side))) / side
    r, phi = np.sqrt(u), 2.0 * np.pi * v
    helper = np.where(np.abs(normals[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    t = np.cross(normals, helper)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    b = np.cross(normals, t)
    return ((r * np.cos(phi))[..., None] * t[:, None] + (r * np.sin(phi))[..., None] * b[:, None]
            + np.sqrt(1.0 - u)[..., None] * normals[:, None])


def embree_scene(triangles: np.ndarray):
    """An Embree scene of (F, 3, 3) triangles."""
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, np.ascontiguousarray(triangles, np.float32))
    return scene


def accessibility(scene, points: np.ndarray, normals: np.ndarray, geometric: np.ndarray, rays: int, seed: int,
                  radius: float, max_distance: float = 0.0, falloff: str = "none", lift: np.ndarray | None = None,
                  terminator_offset: float = 0.0, min_lift: float = 0.0) -> np.ndarray:
    """(N,) AO at the points: 1 - the mean occlusion weight of `rays` cosine rays each.
    lift: (N, 3) Cycles' terminator lift of each point at full amount (world units), with
    terminator_offset its cut-off: a ray starts lifted by lift_amount (core/bake/terminator.py,
    the definition the bakes share) where that lift is longer than min_lift (world units), and a
    ray below the face that is lifted is traced instead of counted occluded."""
    from hao_addon.core.bake.terminator import lift_amount, lifted_starts
    rng = np.random.default_rng(seed)
    out = np.empty(len(points))
    per = max(1, CHUNK_RAYS // rays)
    for start in range(0, len(points), per):
        sl = slice(start, start + per)
        d = cosine_directions(normals[sl], rays, rng)
        cos_true = np.einsum("nrj,nj->nr", d, geometric[sl])
        below = cos_true <= 0.0  # into the true surface: occluded
        origins = np.broadcast_to((points[sl] + geometric[sl] * (OFFSET * radius))[:, None], d.shape)
        if lift is not None and terminator_offset > 0.0:
            amount = lift_amount(np.einsum("nrj,nj->nr", d, normals[sl]), cos_true, terminator_offset)
            lifted = lifted_starts(amount, np.linalg.norm(lift[sl], axis=1)[:, None], min_lift)
            origins = np.where(lifted[..., None], points[sl][:, None] + lift[sl][:, None] * amount[..., None], origins)
            below &= ~lifted
        origins = origins.reshape(-1, 3)
        hit = scene.run(np.ascontiguousarray(origins, np.float32), np.ascontiguousarray(d.reshape(-1, 3), np.float32),
                        query="DISTANCE").reshape(d.shape[:2]).astype(np.float64)
        hit = np.where(np.isfinite(hit) & (hit < 1e30), hit, np.inf)
        weight = occlusion_weight(hit, max_distance, falloff)
        weight = np.where(below, 1.0, weight)
        out[sl] = 1.0 - weight.mean(axis=1)
    return out


def texel_truth(soup, occluders: list, size: int, rays: int = 32768, shading: bool = False,
                max_distance: float = 0.0, falloff: str = "none", seed: int = 0) -> Truth:
    """The truth of a bake of `soup` (with UVs) among `occluders` at size x size: `rays` rays
    per texel centre, as two halves of independent seeds whose difference gives its noise."""
    return truth_at(soup, occluders, texel_samples(soup, size, shading), rays, max_distance, falloff, seed)


def reference_sample_points(soup, settings) -> Samples:
    """bake_sample_points' Samples for the reference bake of `soup` with `settings`: its
    receivers are the CPU raster's texel centres (plan.receivers(), as texel_samples)."""
    from dataclasses import replace
    from hao_addon.core.bake.plan import make_plan_steps
    from hao_addon.core.bake.targets import as_bake_target
    from hao_addon.core.steps import drain
    plan = drain(make_plan_steps(as_bake_target(soup, "image", None, None), [],
                                 replace(settings, method="reference", directions=4)))
    return _samples_of(plan.receivers(), plan, settings)


def _samples_of(receivers, plan, settings) -> tuple:
    """Samples of one receiver per texel (overlapping UV islands: one entry's), in texel order."""
    receivers = receivers.subset(receivers.inv_s > 0.0)
    _unique, first = np.unique(receivers.texel, return_index=True)
    receivers = receivers.subset(first)
    covered = np.zeros(settings.size ** 2, bool)
    covered[receivers.texel] = True
    lift = None if receivers.lift is None else receivers.lift * plan.scale
    return Samples(covered.reshape(settings.size, settings.size), receivers.points * plan.scale + plan.centre,
                   receivers.shading, receivers.geometric, lift, settings.terminator_offset if lift is not None else 0.0,
                   MIN_LIFT * plan.scale)


def bake_sample_points(soup, settings) -> Samples:
    """The points where a gather bake of `soup` with `settings` samples each texel: its GPU texel
    list read back (the texel centre on the face its rasterizer picked; on a UV edge shared by
    two faces that may be the other face than texel_samples' CPU raster picks, and with flat
    normals the two give other values: both are the AO at a point of the surface). The matching
    truth of a gather map is traced at these. Needs a GPU context."""
    from dataclasses import replace
    from hao_addon.core.bake.plan import make_plan_steps
    from hao_addon.core.bake.targets import as_bake_target
    from hao_addon.core.steps import drain
    from hao_addon.gpu.bake_gather import GatherBaker
    plan = drain(make_plan_steps(as_bake_target(soup, "image", None, None), [], replace(settings, directions=4)))
    baker = GatherBaker(plan)
    try:
        receivers = baker.sample_receivers(np.arange(settings.size ** 2))
    finally:
        baker.free()
    return _samples_of(receivers, plan, settings)


def truth_at(soup, occluders: list, samples: Samples, rays: int = 32768, max_distance: float = 0.0,
             falloff: str = "none", seed: int = 0) -> Truth:
    """texel_truth at given samples, such as bake_sample_points'. With HAO_TRUTH_CACHE set to
    a folder, a truth traced before from the same inputs is read back from it (a benchmark
    rerun after a change to a baker keeps its truths: they do not depend on the bakers)."""
    folder = os.environ.get("HAO_TRUTH_CACHE")
    if folder:
        parts = [soup.positions, *(o.positions for o in occluders), *(a for a in samples if isinstance(a, np.ndarray)),
                 np.asarray([rays, max_distance, seed, samples.terminator_offset, samples.min_lift], np.float64)]
        digest = hashlib.sha256(falloff.encode())
        for part in parts:
            digest.update(np.ascontiguousarray(part).tobytes())
            digest.update(str(part.shape).encode())
        path = Path(folder) / f"{digest.hexdigest()[:32]}.npz"
        if path.exists():
            with np.load(path) as held:
                return Truth(held["values"], held["covered"], float(held["noise"]))
        truth = _truth_at(soup, occluders, samples, rays, max_distance, falloff, seed)
        path.parent.mkdir(parents=True, exist_ok=True)
        np.savez(path, values=truth.values, covered=truth.covered, noise=truth.noise)
        return truth
    return _truth_at(soup, occluders, samples, rays, max_distance, falloff, seed)


def _truth_at(soup, occluders: list, samples: Samples, rays: int, max_distance: float, falloff: str,
              seed: int) -> Truth:
    covered, points, normals, geometric, lift, terminator_offset, min_lift = samples
    scene = embree_scene(np.concatenate([soup.positions] + [o.positions for o in occluders]))
    corners = soup.positions.reshape(-1, 3)
    radius = float(np.linalg.norm(corners - corners.mean(axis=0), axis=1).max())
    halves = [accessibility(scene, points, normals, geometric, rays // 2, seed * 2 + k, radius, max_distance,
                            falloff, lift, terminator_offset, min_lift) for k in range(2)]
    values = np.zeros(covered.shape)
    values[covered] = (halves[0] + halves[1]) / 2.0
    noise = float(np.sqrt(np.mean(((halves[0] - halves[1]) / 2.0) ** 2))) if len(points) else 0.0
    return Truth(values, covered, noise)
