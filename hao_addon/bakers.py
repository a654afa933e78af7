# SPDX-License-Identifier: GPL-3.0-or-later
"""The one factory of bake passes: a method name -> its baker class. Every baker takes a
BakePlan and offers check_limits(plan), run_direction(i), accumulated() -> (size, size,
channels) the sums of the plan's estimator (core/bake/estimators.py), stats and free(); the
tests run each on the same scenes. And the ray cast of a method's Selected-to-Active
projection: the GPU's for the GPU bakers, mathutils' BVH for the reference (twins, same
signature: core/bake/projection.project_steps)."""
from __future__ import annotations

from .core.bake.abilities import BAKE_METHODS  # the bakers' declarations (what each can bake)


def baker_for(method: str):
    """The bake pass class for 'scatter', 'gather' (GPU) or 'reference' (CPU ray tracing)."""
    if method == "reference":
        import bpy  # noqa: F401 - the bpy module makes mathutils (the reference's BVH) importable
        from .core.bake.reference_baker import ReferenceBaker
        return ReferenceBaker
    if method not in BAKE_METHODS:
        raise ValueError(f"unknown bake method '{method}', expected one of {BAKE_METHODS}")
    from .gpu.context import ensure_gpu_context
    ensure_gpu_context()  # importing the GPU passes needs a GPU context
    if method == "scatter":
        from .gpu.bake_scatter import ScatterBaker
        return ScatterBaker
    from .gpu.bake_gather import GatherBaker
    return GatherBaker


RAY_CASTS = ("cpu", "gpu")


def ray_cast_name(method: str) -> str:
    """'cpu' (mathutils' BVH) for the reference and 'cpu', 'gpu' (the grid walk of
    gpu/bake_ray_cast.py) for the GPU bakers and 'gpu'."""
    if method not in (*BAKE_METHODS, *RAY_CASTS):
        raise ValueError(f"unknown bake method '{method}', expected one of {BAKE_METHODS}")
    return "cpu" if method in ("reference", "cpu") else "gpu"


def ray_caster_for(method: str):
    """The Selected-to-Active ray cast (projection.RayCast) that `method` (a bake method or
    one of RAY_CASTS) plans with."""
    if ray_cast_name(method) == "cpu":
        import bpy  # noqa: F401 - the bpy module makes mathutils (the CPU cast's BVH) importable
        from .core.bake.projection import project_steps
        return project_steps
    from .gpu.context import ensure_gpu_context
    ensure_gpu_context()
    from .gpu.bake_ray_cast import project_steps
    return project_steps


def distance_cast_for(method: str):
    """The batched first-hit cast (core/bake/projection.DistanceCast) that exact rays
    checking or repairing a `method` bake use: the GPU's grid walk (gpu/bake_ray_cast.py) for
    the GPU bakers, None (mathutils' BVH, a ray at a time) for the reference."""
    if ray_cast_name(method) == "cpu":
        return None
    from .gpu.context import ensure_gpu_context
    ensure_gpu_context()
    from .gpu.bake_ray_cast import first_hit_distances
    return first_hit_distances
