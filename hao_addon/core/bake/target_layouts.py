# SPDX-License-Identifier: GPL-3.0-or-later
"""What each kind of bake target adds to a plan (pure numpy): where its receivers lie, the
shape of what it bakes into, and how a bake's sums become that output.

One class per row of TARGET_KINDS (core/bake/target_kinds.py), made by the row's own steps
(LAYOUTS[kind].made): the plan, the bakers and the bake read the layout instead of testing
which optional inputs a plan holds.

- TexelLayout: the target's own UV layout, one size x size map (a UDIM layout: one per tile);
- ProjectedLayout: the same maps, their receivers the high-poly points the texels project to
  (Selected to Active, core/bake/projection.py);
- CornerLayout: one value per vertex or face corner (a colour attribute, core/bake/vertex_target.py).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Generator

import numpy as np

from .contacts import contact_faces, contact_pairs, window_samples
from .estimators import BENT_NORMALS, Estimator
from .projection import RayCast, projected_receivers_steps
from .receivers import Receivers, corner_receivers, receivers_at, sub_texel_grid, tiled_sample_points, uv_receivers
from .seams import element_values, estimated, finalize_map, finalize_vectors
from .settings import BakeSettings
from .target_kinds import TARGET_KINDS
from .targets import BakeTarget
from .udim import UdimLayout
from .vertex_target import VertexTarget
from .views import cell_corners

# Selected-to-Active light views are fitted to the corners of grid cells this many light-view
# pixels wide that hold receivers (views.cell_corners): a few thousand points instead of
# millions, for windows at most that much wider.
VIEW_FIT_CELL = 16

# (ao, covered, filled, bent normals or None) of a finished bake.
Finished = tuple[np.ndarray, np.ndarray, np.ndarray, "np.ndarray | None"]


@dataclass(frozen=True)
class TexelLayout:
    """texels: the target's own surface at sample_count points a texel of a size x size map,
    one map per tile of `udim` where the UV layout is tiled."""

    size: int
    sample_count: int
    udim: UdimLayout | None = None
    KIND: ClassVar[str] = "texels"

    @classmethod
    def made(cls, target: BakeTarget, settings: BakeSettings, udim: UdimLayout | None, centre: np.ndarray,
             scale: float, cast: RayCast | None, earlier: tuple | None) -> Generator[float, None, "TexelLayout"]:
        """The layout of `target` (the kind's steps: a projection yields its progress; the
        others take none)."""
        yield from ()
        return cls.of(target, settings, udim)

    @classmethod
    def of(cls, target: BakeTarget, settings: BakeSettings, udim: UdimLayout | None) -> "TexelLayout":
        return cls(settings.size, settings.sample_count, udim)

    @property
    def per_element(self) -> bool:
        """A value per vertex or corner, not a map (its kind's row writes no images): no
        margins, no texels to cover."""
        return not TARGET_KINDS[self.KIND].writes_images

    @property
    def output_shape(self) -> tuple[int, ...]:
        """(size, size) texels, or (tiles, size, size) on a UDIM layout."""
        return (self.size, self.size) if self.udim is None else (self.udim.count, self.size, self.size)

    @property
    def tiles(self) -> tuple[int, ...] | None:
        """The UDIM numbers of the maps, in order, or None for one 0..1 map."""
        return None if self.udim is None else tuple(int(t) for t in self.udim.tiles)

    @property
    def gpu_lists_receivers(self) -> bool:
        """Whether a GPU raster of the UV layout can list the receivers itself (texel centres
        of one tile), instead of the CPU's list being uploaded."""
        return self.udim is None and self.sample_count == 1

    @property
    def extent(self) -> float:
        """The receivers' sphere's radius about the origin, normalized (1: the target's)."""
        return 1.0

    @property
    def counters(self) -> dict:
        """The layout's counters for BakeResult.stats."""
        return {} if self.udim is None else {"udim_tiles": list(self.tiles)}

    @property
    def warnings(self) -> list[str]:
        return []

    @property
    def smooth_receivers(self) -> bool:
        """Whether receivers other than the target's own corners carry smooth shading normals."""
        return False

    def reusable(self) -> tuple | None:
        """What a later run of the same target and settings may reuse (make_plan_steps'
        projection), or None."""
        return None

    def receivers(self, plan) -> Receivers:
        """The receivers of `plan` (a BakePlan of this layout); of its cells alone where it
        names them (only the faces reaching them rasterized)."""
        return uv_receivers(plan.target_positions, plan.target_uvs, plan.target_faces, plan.target_corners,
                            self.size, self.sample_count, plan.lifts_terminator, self.udim, plan.cells)

    def contact_candidates(self, plan, reach: float) -> tuple[Receivers, np.ndarray]:
        """(receivers, faces): receivers of `plan` that may be in contact with a drawn face
        within `reach` (core/bake/contacts.py), and the drawn faces they may be in contact
        with (indices into plan.drawn_positions): those on the target's faces that can be
        (only those faces rasterized: where UV islands overlap, a texel's point may lie on
        another face than in the whole raster)."""
        if self.udim is None:  # only the UV windows of the faces near each partner (contacts.window_samples)
            f, g = contact_pairs(plan.target_positions, plan.drawn_positions, reach)
            drawn = plan.drawn_positions[g]
            texel, face, bary = window_samples(plan.target_positions, plan.target_uvs, f, drawn.min(1) - reach,
                                               drawn.max(1) + reach, self.size, sub_texel_grid(self.sample_count))
            partners = np.unique(g)
        else:  # the tiles know the faces by their index in the whole target: all of them, then those
            faces, partners = contact_faces(plan.target_positions, plan.drawn_positions, reach)
            texel, face, bary = tiled_sample_points(plan.target_uvs, self.size, self.sample_count, self.udim)
            keep = np.isin(face, faces)
            texel, face, bary = texel[keep], face[keep], bary[keep]
        return receivers_at(plan.target_positions, plan.target_faces, plan.target_corners, texel, face, bary), partners

    def receiver_bound(self) -> int:
        """The most receivers a whole bake has (a reference bake's rays per direction)."""
        return self.size ** 2 * self.sample_count * (1 if self.udim is None else self.udim.count)

    def receiver_points(self) -> np.ndarray:
        """(m, 3) normalized points that receive besides the target's own surface."""
        return np.zeros((0, 3))

    def view_points(self, welded_corners: np.ndarray, pixel_size: float) -> np.ndarray:
        """(n, 3) normalized points a light view's window is fitted to: the target's distinct
        corners (welded_corners)."""
        return welded_corners

    def finished(self, estimator: Estimator, sums: np.ndarray, margin: int) -> Finished:
        """The maps from a bake's summed estimator (output_shape plus its channels), each
        tile with its own margins and seams (core/bake/seams.py)."""
        tiles = sums if self.udim is not None else sums[None]
        maps = [finalize_map(*estimator.ratio(tile), margin) for tile in tiles]
        ao, covered, filled = (np.stack(part) for part in zip(*maps))
        bent = None
        if estimator is BENT_NORMALS:
            bent = np.stack([finalize_vectors(BENT_NORMALS.bent(tile), c, f, margin)
                             for tile, c, f in zip(tiles, covered, filled)])
        if self.udim is None:
            return ao[0], covered[0], filled[0], None if bent is None else bent[0]
        return ao, covered, filled, bent

    def finished_cells(self, estimator: Estimator, sums: np.ndarray, cells: np.ndarray) -> Finished:
        """finished() of a run of some cells (flat indices), margin 0, computed at the cells
        alone: the same values at its covered cells (the only ones a merge takes: rebake.py,
        bake._combine_rounds), the rest background and not covered (the whole map's ratio,
        erosion and rim cost 0.5 s of a 1 % re-bake at 2048^2). UDIM tiles and bent normals
        take the whole map's path."""
        if self.udim is not None or estimator is BENT_NORMALS:
            return self.finished(estimator, sums, 0)
        numerator, weight = (part.reshape(-1)[cells] for part in estimator.ratio(sums))
        here = estimated(weight)
        ao = np.ones(self.output_shape, np.float32)
        ao.reshape(-1)[cells] = np.where(here, np.clip(np.divide(numerator, weight, out=np.zeros_like(numerator),
                                                                 where=here), 0.0, 1.0), 1.0)
        covered = np.zeros(self.output_shape, bool)
        covered.reshape(-1)[cells] = here
        return ao, covered, covered.copy(), None

    def estimated(self, weight: np.ndarray) -> np.ndarray:
        """The cells whose value is the bake's own estimate, by their summed weight."""
        return estimated(weight, elements=self.per_element)


@dataclass(frozen=True)
class ProjectedLayout(TexelLayout):
    """projected: the maps of the target's UV layout, their receivers the high-poly points its
    texel samples project to. projection: (receivers, stats, warning) of
    projected_receivers_steps, which no direction or seed changes (a bake to an error's rounds
    pass it on: BakeRun)."""

    projection: tuple = ()
    KIND: ClassVar[str] = "projected"

    @classmethod
    def made(cls, target: BakeTarget, settings: BakeSettings, udim: UdimLayout | None, centre: np.ndarray,
             scale: float, cast: RayCast | None, earlier: tuple | None) -> Generator[float, None, "ProjectedLayout"]:
        """The layout, casting the projection's rays (yielding their fraction done) unless
        `earlier` holds a projection of the same target, sources and settings."""
        projection = earlier
        if projection is None:
            projection = yield from projected_receivers_steps(target.soup, target.high_to_low, settings, centre,
                                                              scale, cast, udim)
        return cls(settings.size, settings.sample_count, udim, projection)

    @property
    def projected(self) -> Receivers:
        return self.projection[0]

    @property
    def gpu_lists_receivers(self) -> bool:
        return False

    @property
    def extent(self) -> float:
        points = self.projected.points
        return max(1.0, float(np.linalg.norm(points, axis=1).max())) if len(points) else 1.0

    @property
    def counters(self) -> dict:
        return {**super().counters, **self.projection[1]}

    @property
    def warnings(self) -> list[str]:
        return [self.projection[2]] if self.projection[2] else []

    @property
    def smooth_receivers(self) -> bool:
        return self.projection[1]["smooth_receivers"] > 0

    def reusable(self) -> tuple:
        return self.projection

    def receivers(self, plan) -> Receivers:
        return self.projected

    def contact_candidates(self, plan, reach: float) -> tuple[Receivers, np.ndarray]:
        # Points of the high-poly sources, not of the target's faces: all of them, every face.
        return self.projected, np.arange(len(plan.drawn_positions))

    def receiver_bound(self) -> int:
        return len(self.projected)

    def receiver_points(self) -> np.ndarray:
        return self.projected.points

    def view_points(self, welded_corners: np.ndarray, pixel_size: float) -> np.ndarray:
        """The corners of the grid cells that hold receivers (VIEW_FIT_CELL light-view pixels)."""
        return cell_corners(self.projected.points, VIEW_FIT_CELL * pixel_size)


@dataclass(frozen=True)
class CornerLayout(TexelLayout):
    """corners: one value per element (vertex or face corner) of `corners`, its receivers the
    target's face corners; no UV layout, map or margins."""

    corners: VertexTarget | None = None
    KIND: ClassVar[str] = "corners"

    @classmethod
    def of(cls, target: BakeTarget, settings: BakeSettings, udim: UdimLayout | None) -> "CornerLayout":
        return cls(settings.size, 1, None, target.corners)

    @property
    def output_shape(self) -> tuple[int, ...]:
        return (self.corners.count,)

    @property
    def gpu_lists_receivers(self) -> bool:
        return False

    @property
    def counters(self) -> dict:
        return dict(vertex_target_corners=int((self.corners.cells >= 0).sum()),
                    vertex_target_elements=self.corners.count)

    def contact_candidates(self, plan, reach: float) -> tuple[Receivers, np.ndarray]:
        return self.receivers(plan), np.arange(len(plan.drawn_positions))  # a few per face: all of them

    def receivers(self, plan) -> Receivers:
        return corner_receivers(plan.target_faces, plan.target_positions, plan.target_corners, self.corners.cells,
                                plan.lifts_terminator)

    def receiver_bound(self) -> int:
        return int((self.corners.cells >= 0).sum())

    def finished(self, estimator: Estimator, sums: np.ndarray, margin: int) -> Finished:
        """One value per element (element_values), no bent normals."""
        return (*element_values(*estimator.ratio(sums)), None)

    def finished_cells(self, estimator: Estimator, sums: np.ndarray, cells: np.ndarray) -> Finished:
        return self.finished(estimator, sums, 0)


LAYOUTS: dict[str, type[TexelLayout]] = {layout.KIND: layout for layout in (TexelLayout, ProjectedLayout, CornerLayout)}
