# SPDX-License-Identifier: GPL-3.0-or-later
"""What a bake writes into: one BakeTarget type for the three kinds (pure numpy).

- texels: the target mesh's own surface, sampled at the texels of its UV layout (an image);
- corners: its vertices or face corners (a colour attribute, core/bake/vertex_target.py);
- projected: high-poly points found by rays from its texels (Selected to Active,
  core/bake/projection.py); the target itself then does not occlude.

Each kind is a row of TARGET_KINDS (core/bake/target_kinds.py: whether it needs UVs, whether
the target occludes, which baker ability it needs); the plan reads the row instead of
testing which optional inputs are present.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import BakeInputError
from ..geometry import TriangleSoup
from .projection import HighToLow
from .target_kinds import TARGET_KINDS, TargetKind, kind_name
from .vertex_target import VertexTarget


@dataclass(frozen=True)
class BakeTarget:
    """The mesh a bake writes into (soup: world-space triangles, UVs where the kind needs
    them), its kind (a key of TARGET_KINDS) and what the kind adds: corners (VertexTarget)
    of a colour attribute, high_to_low (HighToLow) of Selected to Active. check() refuses
    what cannot be baked."""

    soup: TriangleSoup
    kind_name: str = "texels"
    corners: VertexTarget | None = None
    high_to_low: HighToLow | None = None

    @classmethod
    def of(cls, soup: TriangleSoup, target_setting: str, high_to_low: HighToLow | None = None,
           vertex_target: VertexTarget | None = None) -> "BakeTarget":
        """The target of a bake's inputs as the bake functions take them: the settings'
        Target ('image', or 'color-attribute', which uses vertex_target), Selected to Active
        where high_to_low is given."""
        name = kind_name(target_setting, high_to_low is not None)
        return cls(soup, name, vertex_target if name == "corners" else None, high_to_low)

    @property
    def kind(self) -> TargetKind:
        return TARGET_KINDS[self.kind_name]

    @property
    def name(self) -> str:
        return self.soup.name

    def check(self, bent_normals: bool) -> None:
        """Raise BakeInputError for a target that cannot be baked (before any work)."""
        if self.soup.face_count == 0:
            raise BakeInputError(f"'{self.name}' has no faces to bake")
        if self.kind_name == "corners":
            if self.corners is None or self.corners.cells.shape != (self.soup.face_count, 3):
                raise BakeInputError(f"'{self.name}': a colour-attribute bake needs the mesh's vertices and corners")
            if self.high_to_low is not None or bent_normals:
                raise BakeInputError("a colour attribute holds the AO of the mesh's own surface: Selected to Active "
                                     "and bent normals bake into images (Target: Image Textures)")
        if self.kind.needs_uvs and self.soup.uvs is None:
            raise BakeInputError(f"'{self.name}' has no UV map")


def as_bake_target(target: "TriangleSoup | BakeTarget", target_setting: str, high_to_low: HighToLow | None = None,
                   vertex_target: VertexTarget | None = None) -> BakeTarget:
    """target itself if a BakeTarget, else BakeTarget.of its parts (the bake functions take
    either)."""
    if isinstance(target, BakeTarget):
        return target
    return BakeTarget.of(target, target_setting, high_to_low, vertex_target)
