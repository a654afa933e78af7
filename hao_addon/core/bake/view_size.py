# SPDX-License-Identifier: GPL-3.0-or-later
"""How fine a bake's light views are: a light-view pixel sized from the target's texel
density (a UV map's), from its UDIM tiles' finest, or from Size pixels across its bounding
sphere where it has no UV layout; and whether the scatter needs its footprint-splitting
variant."""
from __future__ import annotations

import numpy as np

from .settings import BakeSettings
from .udim import UdimLayout

# The light view never exceeds this many pixels per side (GPU limit is checked separately);
# at 8192^2 one RGBA32F view buffer takes 1 GiB.
MAX_VIEW_SIDE = 8192
# Light-view pixels are sized so that this fraction of the surface area (the part with the
# densest UVs) may get fewer than `view_samples` pixels per texel; the footprint-aware splat
# keeps those texels hole-free, only their visibility is sampled more coarsely.
DENSITY_PERCENTILE = 0.10
# Texels smaller than a light-view pixel by this factor (per side) leave holes between the
# tent splats of neighbouring pixels; when more than DENSE_AREA_LIMIT of the texels are like
# that, the bake uses the footprint-splitting shader variant (slower, so only then).
FOOTPRINT_SPLIT = 1.5
DENSE_AREA_LIMIT = 0.005


def light_pixel_size(settings: BakeSettings, kind, udim: UdimLayout | None, areas: np.ndarray,
                      uv_area: np.ndarray | None, scale: float, method: str, extent: float) -> tuple[float, float]:
    """(a light view's pixel, normalized; the scatter's dense UV-area fraction) for the bake
    method that runs (the plan's choice)."""
    if udim is not None:  # each tile as fine as its own bake would be: the finest of them
        tiles = [faces for faces in map(udim.faces, range(udim.count))
                 if ((areas[faces] > 0.0) & (uv_area[faces] > 0.0)).any()]  # a tile of zero-area faces asks nothing
        pixel_size = min(uv_pixel_size(settings, areas[faces], uv_area[faces], scale, "gather")[0] for faces in tiles)
        dense_fraction = 0.0  # the scatter's split, and it bakes no tiles
    elif kind.needs_uvs:
        pixel_size, dense_fraction = uv_pixel_size(settings, areas, uv_area, scale, method)
    else:  # Size pixels across the bounding sphere's diameter (2), times sqrt(view samples)
        pixel_size, dense_fraction = 2.0 / (settings.size * float(np.sqrt(settings.view_samples))), 0.0
    # The receivers' sphere has diameter 2 (the target's), or 2 extent in Selected to Active.
    return max(pixel_size, 2.0 * extent / (MAX_VIEW_SIDE - 4)), dense_fraction


def uv_pixel_size(settings: BakeSettings, areas: np.ndarray, uv_area: np.ndarray, scale: float,
                   method: str) -> tuple[float, float]:
    """(light-view pixel side, normalized; the fraction of the UV area whose texels are
    FOOTPRINT_SPLIT times smaller than a pixel per side) from the texel density: the world
    area per texel on each face. method: the bake variant that runs (the scatter samples
    finer where it anti-aliases)."""
    size = settings.size
    useful = (areas > 0.0) & (uv_area > 0.0)
    texel_world_area = (areas[useful] / scale**2) / (uv_area[useful] * size * size)
    order = np.argsort(texel_world_area)
    cum = np.cumsum(areas[useful][order])
    # The 10th area-percentile face density: 90 % of the surface gets at least
    # view_samples pixels per texel; finer texels elsewhere are averaged by the tent splat.
    density = texel_world_area[order][np.searchsorted(cum, DENSITY_PERCENTILE * cum[-1])]
    # The scatter's anti-aliasing: that many times more light-view pixels per texel.
    scatter = method == "scatter"
    scatter_samples = settings.view_samples * (settings.sample_count if scatter else 1)
    pixel_size = float(np.sqrt(density / scatter_samples))
    # UV area, not surface area: a small dense region can hold many texels.
    texel_side = np.sqrt(texel_world_area)
    uv_used = uv_area[useful]
    return pixel_size, float(uv_used[texel_side * FOOTPRINT_SPLIT < pixel_size].sum() / uv_used.sum())
