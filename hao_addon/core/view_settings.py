# SPDX-License-Identifier: GPL-3.0-or-later
"""Settings of the viewport / render-time Hybrid Ambient Occlusion (pure Python).

Defaults follow the HAO paper's Table 1 (32 rays, 8 steps, 256^3 grid, AO map at half the
screen resolution per axis, bilateral filter of 16 pixels)."""
from __future__ import annotations

from dataclasses import dataclass, replace

from .plan import BakeInputError

GRID_MIN, GRID_MAX = 64, 512
# 'hao': voxel AO (everything); 'far': sphere proxies only; 'hao+far': voxels for the objects
# without proxies and spheres for those with them (each occluder counted once); 'near':
# image-space near field within max_distance (rays = samples per pixel); 'near+far': both.
METHODS = ("hao", "far", "hao+far", "near", "near+far")


@dataclass(frozen=True)
class ViewAOSettings:
    rays: int = 32             # rays per AO-map pixel (regular pattern, jittered in object space)
    steps: int = 8             # fixed occupancy tests per ray
    spread: float = 1.0        # cone of the rays: 1 = whole hemisphere (the AO definition)
    max_distance: float = 1.0  # d_max, world units: Wendland support of the hit distance
    grid: int = 256            # voxels along the longest side of the region of interest
    scale: int = 2             # AO map is 1/scale of the screen per axis (k)
    filter_size: int = 16      # bilateral window m (full-resolution pixels)
    strength: float = 1.0      # viewport only: 0 = no darkening, 1 = the computed AO
    method: str = "hao"
    epsilon: float = 0.05      # sphere influence cut-off (A_psi units, paper eq. 5): d_far ~ 7.9 r

    def validated(self) -> "ViewAOSettings":
        """Self, or BakeInputError naming the first bad value."""
        checks = [
            (1 <= self.rays <= 1024, f"rays must be 1..1024, got {self.rays}"),
            (1 <= self.steps <= 256, f"steps must be 1..256, got {self.steps}"),
            (0.05 <= self.spread <= 1.0, f"spread must be 0.05..1, got {self.spread}"),
            (self.max_distance > 0.0 and self.max_distance < float("inf"),
             f"max distance must be a positive number, got {self.max_distance}"),
            (GRID_MIN <= self.grid <= GRID_MAX, f"grid must be {GRID_MIN}..{GRID_MAX}, got {self.grid}"),
            (1 <= self.scale <= 8, f"scale must be 1..8, got {self.scale}"),
            (0 <= self.filter_size <= 64, f"filter size must be 0..64, got {self.filter_size}"),
            (0.0 <= self.strength <= 1.0, f"strength must be 0..1, got {self.strength}"),
            (self.method in METHODS, f"method must be one of {', '.join(METHODS)}, got '{self.method}'"),
            (0.0 < self.epsilon < 1.0, f"epsilon must be in (0, 1), got {self.epsilon}"),
        ]
        for ok, message in checks:
            if not ok:
                raise BakeInputError(message)
        return self

    def with_(self, **changes) -> "ViewAOSettings":
        return replace(self, **changes)
