# SPDX-License-Identifier: GPL-3.0-or-later
"""The viewport AO methods as data (pure Python): the passes each one runs, in order, and
what its voxels hold. The GPU renderer (hao_addon/gpu/hao_renderer.py) knows how to run each
pass and what each one reads; a method is nothing but this list, so a new method, or a new
way to combine two, is a new row here and at most a new pass there.

Pass names (what each computes is documented with its runner in the renderer):
upload, gbuffer, back_layer, low_gbuffer: scene buffers; cascades, voxelize: where the voxel
grids go (around the G-buffer's focus) and their voxels;
voxel_ao, near_field, open_ao: start the AO map (voxel march, image-space near field, all 1);
spheres: multiply the sphere proxies' occlusion into it; filter: bilateral upsampling (weighing
the AO map's samples by low_gbuffer, the G-buffer pixels they were computed at).
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class MethodPlan:
    """passes: run in this order; spheres: whether the method needs sphere proxies;
    sphere_scope: which of them occlude: 'all', or 'outside' the region of interest (the
    voxels hold everything inside it, so each occluder is counted once)."""
    name: str
    passes: tuple[str, ...]
    spheres: bool = False
    sphere_scope: str = "all"

    @property
    def voxels(self) -> bool:
        """Whether the method voxelizes the scene."""
        return "voxelize" in self.passes


METHOD_PLANS = {plan.name: plan for plan in (
    MethodPlan("hao", ("upload", "gbuffer", "cascades", "voxelize", "voxel_ao", "low_gbuffer", "filter")),
    MethodPlan("far", ("upload", "gbuffer", "open_ao", "low_gbuffer", "spheres", "filter"), spheres=True),
    MethodPlan("hao+far", ("upload", "gbuffer", "cascades", "voxelize", "voxel_ao", "low_gbuffer", "spheres",
                           "filter"), sphere_scope="outside", spheres=True),
    MethodPlan("near", ("upload", "gbuffer", "back_layer", "near_field", "low_gbuffer", "filter")),
    MethodPlan("near+far", ("upload", "gbuffer", "back_layer", "near_field", "low_gbuffer", "spheres", "filter"),
               spheres=True),
)}


def method_plan(name: str) -> MethodPlan:
    """The plan of a method named in view_settings.METHODS."""
    return METHOD_PLANS[name]
