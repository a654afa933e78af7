# SPDX-License-Identifier: GPL-3.0-or-later
"""What a bake job takes besides what it computes (BakeSettings): which meshes occlude, and
how its outputs are laid out. Each option is defined once here (default, choices,
description, core/setting_spec.py): the panel's properties, the command line's options, the
job's request (blender/bake_job.BakeRequest) and the README table are made from it.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..setting_spec import Choice, setting, validate
from .tangent_space import CONVENTION_CHOICES, SPACE_CHOICES

OCCLUDER_CHOICES = (
    Choice("target", "Self", "only the baked mesh itself (Selected to Active: the high-poly only)"),
    Choice("selected", "Selected", "the baked mesh and the other selected meshes"),
    Choice("visible", "Visible", "every visible mesh in the view layer"),
)


@dataclass(frozen=True)
class JobOptions:
    """Which meshes occlude and how the outputs are laid out (see each field's description)."""

    occluders: str = setting(
        "selected", label="Occluders", choices=OCCLUDER_CHOICES, cli_default="visible",
        description="what casts occlusion onto the baked mesh (the command line's default is visible: what "
                    "a loaded file happens to have selected is no choice made for the bake)")
    texture_set: bool = setting(
        False, label="Texture Set",
        description="bake the meshes together into one shared image 'TextureSet_AO', each on its own UVs "
                    "(islands must not overlap across objects), each occluding the others; {object} in file "
                    "names becomes 'TextureSet'")
    bent_space: str = setting(
        "tangent", label="Space", noun="bent-normal space", choices=SPACE_CHOICES,
        description="the space the bent normals are written in")
    bent_convention: str = setting(
        "opengl", label="Convention", noun="bent-normal convention", choices=CONVENTION_CHOICES,
        description="which way the bent normals' green channel points")

    def validated(self) -> "JobOptions":
        """Return self, or raise SettingError naming the option."""
        validate(self)
        return self
