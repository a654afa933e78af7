# SPDX-License-Identifier: GPL-3.0-or-later
"""The maps a bake writes, one row each: what the command line's --X-out options and --maps,
the panel's Save ... To fields, the job's files and checks, the --skip-existing key and the
manual's table are made from. A new map is a new row (and its producer in the bake job)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .curvature import cavity_map, curvature_map
from .target_kinds import TARGET_KINDS


@dataclass(frozen=True)
class MapKind:
    """One map: its names, what an image file of it holds, and what turns it on."""

    name: str  # the word in --maps and in the file names --maps makes (ao.png -> ao_bent_normal.png)
    key: str  # the bake job's key for it (BakeRequest.map_paths, BakeJob.files)
    noun: str  # in messages and reports: "the bent normals"
    channels: int  # an image file's channels
    setting: str  # the BakeSettings flag its output needs on ("" none): the CLI's option turns it on
    skip_key: str  # its entry in the --skip-existing key (cli/skip.py), "" for the AO (always written)
    panel_label: str  # the panel's file field
    help: str  # what it holds, for the CLI's option, the panel's tooltip and the manual
    note: str = ""  # what else its file option does (the CLI's help)
    image_suffix: str = ""  # the Blender image it is stored in: '<object>_<suffix>' ('' none: a file only)
    settings: tuple[str, ...] = ()  # the settings that shape it alone (the panel draws them with it)
    # Made from the target's own surface alone: (soup, size, margin) -> (size, size) map (no AO
    # result needed; the bake job calls it for each target). None: the job's own producer.
    from_surface: Callable[..., np.ndarray] | None = None
    # The target kinds (core/bake/target_kinds.py) that can make it, and the refusal where
    # another is asked for it.
    target_kinds: frozenset[str] = frozenset(TARGET_KINDS)
    refusal: str = ""

    @property
    def option(self) -> str:
        """The argparse dest of its file option ('' for the AO: --out)."""
        return "" if self.key == "ao" else f"{self.name.replace('-', '_')}_out"

    @property
    def flag(self) -> str:
        """Its command-line file option."""
        return "--out" if self.key == "ao" else "--" + self.option.replace("_", "-")

    @property
    def property_name(self) -> str:
        """The panel's file property (HAO_PG_bake_settings)."""
        return "filepath" if self.key == "ao" else f"{self.key}_filepath"

    @property
    def what(self) -> str:
        """How reports and checks name its file: 'the bent normals (--bent-normal-out)'."""
        return f"{self.noun} ({self.flag})"


# The target kinds whose output is images of the UV layout.
IMAGE_KINDS = frozenset(kind.name for kind in TARGET_KINDS.values() if kind.writes_images)

MAP_KINDS = (
    MapKind("ao", "ao", "the AO map", 1, "", "", "Save To",
            "the ambient occlusion, 1 open to 0 occluded", image_suffix="AO"),
    MapKind("bent-normal", "bent", "the bent normals", 4, "bent_normals", "bent_normals_file", "Save Bent Normals To",
            "the bent normals (the cosine-weighted mean unoccluded direction, same pass), RGB 0.5 + 0.5 n",
            image_suffix="BentNormals", settings=("bent_space", "bent_convention"), target_kinds=IMAGE_KINDS,
            refusal="a colour attribute holds the AO of the mesh's own surface: bent normals bake into images "
                    "(Target: Image Textures)"),
    MapKind("thickness", "thickness", "the thickness map", 1, "thickness", "thickness_file", "Save Thickness To",
            "thickness: the occlusion of the inverted hemisphere by the mesh itself within the thickness "
            "distance, 1 thin, 0 nothing within reach (a second pass)", image_suffix="Thickness",
            settings=("thickness_distance",), target_kinds=frozenset({"texels"}),
            refusal="thickness bakes the mesh's own surface into an image (not a colour attribute or Selected to "
                    "Active)"),
    MapKind("orm", "orm", "the ORM texture", 4, "", "orm_file", "Save ORM To",
            "glTF's occlusion-roughness-metallic texture: R the AO, G and B the material's roughness and "
            "metallic (values or image textures) in the baked UV layout (past the islands' margin, each "
            "channel's mean over them)",
            "with --gltf-out the .glb's material uses it for occlusion, roughness and metallic", image_suffix="ORM",
            target_kinds=IMAGE_KINDS, refusal="the ORM texture packs one object's AO with its material (not a colour "
                                              "attribute)"),
    MapKind("error", "error", "the error map", 1, "", "error_file", "Save Error To",
            "each texel's estimated error (the RMS of the bake's own error estimate over its 5 x 5 "
            "neighbourhood: one standard error)", target_kinds=IMAGE_KINDS,
            refusal="an error map is an image of the UV layout: a colour-attribute bake reports its error (--json) "
                    "but has no error map"),
    MapKind("curvature", "curvature", "the curvature map", 1, "", "curvature_file", "Save Curvature To",
            "the surface's mean curvature times its bounding radius, 0.5 flat, brighter convex, darker concave",
            image_suffix="Curvature", from_surface=curvature_map, target_kinds=IMAGE_KINDS,
            refusal="the curvature map is an image of the UV layout, not a colour attribute"),
    MapKind("cavity", "cavity", "the cavity map", 1, "", "cavity_file", "Save Cavity To",
            "cavities: 1 on flat and convex surface, darker in grooves and crevices", image_suffix="Cavity",
            from_surface=cavity_map, target_kinds=IMAGE_KINDS,
            refusal="the cavity map is an image of the UV layout, not a colour attribute"),
)
# The maps besides the AO, each with a file option of its own.
EXTRA_MAPS = MAP_KINDS[1:]
