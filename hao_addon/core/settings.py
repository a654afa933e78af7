# SPDX-License-Identifier: GPL-3.0-or-later
"""Bake settings shared by the operator, the CLI and the tests (plain data, validated)."""
from __future__ import annotations

from dataclasses import asdict, dataclass

from .kernels import FALLOFFS
from .normalization import WEIGHTINGS

METHODS = ("auto", "scatter", "gather")
MAX_DIRECTIONS = 65536


@dataclass(frozen=True)
class BakeSettings:
    """What a bake computes.

    size: the AO map is size x size texels. directions: number D of light directions.
    max_distance: occluders farther than this (world units) do not occlude; 0 = unlimited.
    falloff: 'none' or 'wendland' (used only with a max distance). weighting: 'cosine'
    (Lambertian AO) or 'uniform' (fraction of the hemisphere). ignore_back_faces: faces seen
    from behind do not occlude. margin: texels grown past every UV island. method: 'scatter'
    (McGraw & Sowers) or 'gather' (the shadow-map baseline). view_samples: light-view pixels
    per texel (the scatter's sampling density). seed: direction-set rotation.
    """

    size: int = 1024
    directions: int = 256
    max_distance: float = 0.0
    falloff: str = "none"
    weighting: str = "cosine"
    ignore_back_faces: bool = False
    margin: int = 16
    method: str = "auto"
    view_samples: float = 4.0
    seed: int = 0

    def validated(self) -> "BakeSettings":
        """Return self, or raise ValueError with a message a user can act on."""
        if not 1 <= self.size <= 16384:
            raise ValueError(f"map size must be between 1 and 16384 texels, got {self.size}")
        if not 1 <= self.directions <= MAX_DIRECTIONS:
            raise ValueError(f"directions must be between 1 and {MAX_DIRECTIONS}, got {self.directions}")
        if not self.max_distance >= 0.0 or self.max_distance == float("inf"):
            raise ValueError(f"max distance must be a finite number >= 0 (0 = unlimited), got {self.max_distance}")
        if self.falloff not in FALLOFFS:
            raise ValueError(f"falloff must be one of {FALLOFFS}, got '{self.falloff}'")
        if self.weighting not in WEIGHTINGS:
            raise ValueError(f"weighting must be one of {WEIGHTINGS}, got '{self.weighting}'")
        if self.method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got '{self.method}'")
        if not 0 <= self.margin <= 1024:
            raise ValueError(f"margin must be between 0 and 1024 texels, got {self.margin}")
        if not 0.25 <= self.view_samples <= 64.0:
            raise ValueError(f"view samples per texel must be in [0.25, 64], got {self.view_samples}")
        if self.method == "gather" and self.max_distance > 0.0:
            raise ValueError("the gather (shadow-map) baseline supports only unlimited distance: "
                             "a depth map keeps the occluder nearest the light, not the one nearest the texel")
        return self

    @property
    def resolved_method(self) -> str:
        """The bake variant that runs: 'auto' picks by the max distance."""
        if self.method != "auto":
            return self.method
        return "scatter" if self.max_distance > 0.0 else "gather"

    def cache_key(self) -> tuple:
        return tuple(sorted(asdict(self).items()))
