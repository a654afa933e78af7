# SPDX-License-Identifier: GPL-3.0-or-later
"""Settings of the viewport / render-time Hybrid Ambient Occlusion (pure Python).

Defaults follow the HAO paper's Table 1 (32 rays, 256^3 grid, AO map at half the screen
resolution per axis, bilateral filter of 16 pixels), except the march: the paper's 8 fixed
steps step over thin walls and objects far inside d_max, so rays walk every voxel with a
budget of DEFAULT_STEPS traversal steps (march 'fixed', steps 8 is the paper's). Each field is the one definition
of its setting; the panel's properties, render-ao's options and the README table come from it.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

from .cascades import MAX_CASCADES, MIN_REACH_VOXELS
from .methods import method_plan
from ..kernels import FALLOFF_CHOICES
from ..setting_spec import Choice, setting, validate

GRID_MIN, GRID_MAX = 64, 512
MAX_RENDER_SIDE = 65536

METHOD_CHOICES = (
    Choice("hao", "HAO Voxels", "voxel ray-marching against everything (static and deforming)"),
    Choice("far", "Sphere Proxies", "only the sphere proxies of characters (fast, coarse)"),
    Choice("hao+far", "Voxels + Spheres", "voxels for everything in the region of interest, sphere proxies "
                                          "for characters outside it (each occluder counted once)"),
    Choice("near", "Near Field", "image-space AO from the two depth layers within the distance "
                                 "(rays = samples per pixel); misses what is off screen"),
    Choice("near+far", "Near Field + Spheres", "the paper's combination: near field within Near Radius, sphere "
                                               "proxies beyond it (each occluder counted once)"),
)
METHODS = tuple(c.value for c in METHOD_CHOICES)
MARCH_CHOICES = (
    Choice("hierarchical", "Hierarchical", "every voxel on a ray is visited (exact 3D-DDA; coarse levels of an "
                                           "occupancy pyramid skip empty space), so no thin wall is stepped over"),
    Choice("fixed", "Fixed Steps", "the paper's march: Steps samples spaced d_max / Steps apart, which can step "
                                   "over walls thinner than that"),
)
DEFAULT_STEPS = 128
DEFAULT_CASCADES = 4


@dataclass(frozen=True)
class ViewAOSettings:
    rays: int = setting(32, label="Rays", minimum=1, maximum=1024, soft_max=128,
                        description="rays per AO-map pixel; the main cost (paper default 32)")
    steps: int = setting(DEFAULT_STEPS, label="Steps", minimum=1, maximum=1024, soft_max=256,
                         description="traversal steps per ray: the hierarchical march's budget (a ray that spends "
                                     "it counts as open; rarely reached at the default), or the fixed march's "
                                     "samples (paper default 8)")
    march: str = setting("hierarchical", label="March", choices=MARCH_CHOICES, description="how rays walk the voxels")
    spread: float = setting(1.0, label="Spread", minimum=0.05, maximum=1.0,
                            description="cone of the rays: 1 = the whole hemisphere (the AO definition); "
                                        "smaller gives sharper, more contrasted AO")
    max_distance: float = setting(1.0, label="Distance", noun="max distance", minimum=0.0,
                                  soft_max=100.0, unit="scene units", subtype='DISTANCE',
                                  description="the maximum distance d_max: occluders farther than this do not darken; "
                                              "0 = unlimited (what Cycles' AO and the bake compute)")
    falloff: str = setting("wendland", label="Falloff", choices=FALLOFF_CHOICES,
                           description="how occlusion fades with distance (only with a max distance)")
    grid: int = setting(256, label="Grid", minimum=GRID_MIN, maximum=GRID_MAX, unit="voxels",
                        description="voxels along the longest side of the region of interest (and of each cascade)")
    cascades: int = setting(DEFAULT_CASCADES, label="Cascades", minimum=1, maximum=MAX_CASCADES,
                            description="nested grids, each with half the voxel size of the one around it, placed "
                                        "around what the view looks at while they cover it, or while the max "
                                        f"distance spans fewer than {MIN_REACH_VOXELS:g} voxels (1 = one grid over "
                                        "the region; the fixed march uses one)")
    scale: int = setting(2, label="AO Scale", noun="scale", minimum=1, maximum=8,
                         description="AO is sampled at 1/scale of the image resolution per axis, then "
                                     "upsampled by the bilateral filter")
    filter_size: int = setting(16, label="Filter", noun="filter size", minimum=0, maximum=64, unit="pixels",
                               cli="--filter", description="bilateral filter window (0 = off)")
    strength: float = setting(1.0, label="Strength", minimum=0.0, maximum=1.0, subtype='FACTOR', cli=None,
                              description="how much the viewport is darkened (1 = the computed AO)")
    method: str = setting("hao", label="Method", choices=METHOD_CHOICES, description="what casts the AO")
    near_radius: float = setting(0.075, label="Near Radius", minimum=0.0, above_minimum=True, soft_max=10.0,
                                 unit="scene units", subtype='DISTANCE',
                                 description="near field + spheres: the near field covers occluders within this "
                                             "distance, the sphere proxies those beyond it, so none is counted "
                                             "twice; the near field alone covers d_max (this at unlimited distance)")
    epsilon: float = setting(0.05, label="Sphere Cut-off", noun="epsilon", minimum=0.0, above_minimum=True,
                             maximum=0.99, description="occlusion below which a sphere proxy stops influencing "
                                                       "(the paper's epsilon): smaller reaches farther")

    def validated(self) -> "ViewAOSettings":
        """Self, or SettingError naming the first bad value."""
        validate(self)
        return self

    def with_(self, **changes) -> "ViewAOSettings":
        return replace(self, **changes)

    def near_field_radius(self) -> float:
        """The distance the near field samples within: its share with the spheres (near+far),
        else d_max, or near_radius at unlimited distance."""
        if self.method == "near+far":
            return min(self.near_radius, self.max_distance) if self.max_distance > 0.0 else self.near_radius
        return self.max_distance if self.max_distance > 0.0 else self.near_radius


# GPU bytes per full-resolution pixel: a G-buffer layer (RGBA32F position and normal, 32-bit
# depth: 36 B; the near field adds a back layer) and the filter's two R32F images (8 B); per
# AO-map pixel the low-resolution G-buffer (36 B) and AO (4 B).
GBUFFER_LAYER_BYTES, FILTER_BYTES, BYTES_PER_AO_PIXEL = 36, 8, 40


def render_gpu_bytes(width: int, height: int, settings: ViewAOSettings) -> int:
    """Estimate of the GPU memory a width x height frame takes (images and voxel grids: one
    bit per voxel in each cascade, and its occupancy pyramid, at most 8/7 of that)."""
    low = -(-width // settings.scale) * -(-height // settings.scale)
    layers = 2 if "back_layer" in method_plan(settings.method).passes else 1
    full = width * height * (layers * GBUFFER_LAYER_BYTES + FILTER_BYTES)
    grids = settings.cascades * settings.grid ** 3 // 8 * 8 // 7 if method_plan(settings.method).voxels else 0
    return full + low * BYTES_PER_AO_PIXEL + grids


@dataclass(frozen=True)
class RenderSize:
    """Image size of a camera render (render-ao; the operator takes the scene's resolution)."""

    width: int = setting(800, label="Width", minimum=1, maximum=MAX_RENDER_SIDE, unit="pixels", ui=False,
                         description="image width (also limited by the GPU's texture size and memory budget)")
    height: int = setting(600, label="Height", minimum=1, maximum=MAX_RENDER_SIDE, unit="pixels", ui=False,
                          description="image height")

    def validated(self) -> "RenderSize":
        validate(self)
        return self
