# SPDX-License-Identifier: GPL-3.0-or-later
"""What a bake job takes besides what it computes (BakeSettings): which meshes occlude, and
how its outputs are laid out. Each option is defined once here (default, choices,
description, core/setting_spec.py): the panel's properties, the command line's options, the
job's request (blender/bake_job.BakeRequest) and the README table are made from it.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..setting_spec import Choice, SettingError, setting, validate
from .tangent_space import CONVENTION_CHOICES, SPACE_CHOICES
from .verify import VERIFY_DIRECTIONS

GROUP_OCCLUDER_CHOICES = (
    Choice("group", "Group", "only the group's own meshes occlude its low-poly (an exploded bake without moving "
                             "anything)"),
    Choice("all", "All", "every mesh occludes every group (to ground the parts), except the low-poly meshes "
                         "that stand in for a high-poly"),
)
PNG_BITS_CHOICES = (
    Choice("16", "16-bit", "smooth as baked"),
    Choice("8", "8-bit", "for engines and texture budgets; see Dither"),
)
OCCLUDER_CHOICES = (
    Choice("target", "Self", "only the baked mesh itself (Selected to Active: the high-poly only)"),
    Choice("selected", "Selected", "the baked mesh and the other selected meshes"),
    Choice("visible", "Visible", "every mesh that renders, as in Cycles' bake (Disable in Renders leaves one out, "
                                 "hiding it in the viewport does not), and the meshes the scene shows through "
                                 "instances (collections, geometry nodes, particles)"),
)


@dataclass(frozen=True)
class JobOptions:
    """Which meshes occlude and how the outputs are laid out (see each field's description)."""

    occluders: str = setting(
        "visible", label="Occluders", choices=OCCLUDER_CHOICES,
        description="what casts occlusion onto the baked mesh (by default every visible mesh, as Cycles' bake: "
                    "the panel and the command line alike)")
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

    png_bits: str = setting(
        "16", label="PNG Bits", noun="PNG bit depth", choices=PNG_BITS_CHOICES,
        description="bits per sample of PNG files (EXR files are 32-bit float either way)")
    dither: bool = setting(
        False, label="Dither",
        description="8-bit PNG: add a noise below one step before rounding, so that smooth gradients show no bands "
                    "(the same bytes on every run); levels such as 1.0 stay exact")
    match_names: bool = setting(
        False, label="Match Names",
        description="bake groups matched by name: each low-poly (name ending in the low suffix, or in a collection "
                    "so named; Blender's .001 numbers ignored) from its own group's high-poly meshes (Selected to "
                    "Active), every group in one run; a group without high-poly meshes bakes its own parts; names "
                    "that match nothing are listed")
    low_suffix: str = setting(
        "_low", label="Low Suffix", noun="low-poly suffix", description="what ends a low-poly's name (Match Names)")
    high_suffix: str = setting(
        "_high", label="High Suffix", noun="high-poly suffix", description="what ends a high-poly's name (Match Names)")
    group_occluders: str = setting(
        "group", label="Group Occluders", choices=GROUP_OCCLUDER_CHOICES,
        description="Match Names: which meshes occlude a group (Occluders does not apply)")

    verify: int = setting(
        0, label="Verify Texels", noun="verified texels", minimum=0, maximum=100000,
        description="after the bake, re-estimate this many random covered texels (seeded by Seed) with the CPU "
                    f"reference at {VERIFY_DIRECTIONS} directions, and report the map's RMSE, p99 and bias against it with 95 % "
                    "intervals (what the reference shares with the bake: the same surface points, normals and "
                    "estimator); 0 = off")
    verify_max_error: float = setting(
        0.0, label="Verify Max Error", minimum=0.0, maximum=0.5,
        description="with Verify Texels: the run fails (exit 1) when the verification's 95 % interval puts the "
                    "map's p99 error above this; the maps are written either way; 0 = no bound")

    rebake_changed: bool = setting(
        False, label="Re-bake Changed", ui=False,  # the panel's own button sets it for its run
        description="(in the panel: the Re-bake Changed button beside Bake AO) re-bake only the texels that what changed since the last bake of the same map (recorded "
                    "beside it, <map>.hao-rebake.npz) can have moved by half its stated error or more; the others "
                    "are kept, and the report gives how many were re-baked, why, and the bound on the kept ones. "
                    "A changed setting, UV layout or target face count, a bake to an error, bent normals, UDIM "
                    "tiles, colour attributes, Selected to Active and the histogram scatter re-bake in full "
                    "(and say so)")

    @property
    def png_bit_depth(self) -> int:
        return int(self.png_bits)

    def validated(self) -> "JobOptions":
        """Return self, or raise SettingError naming the option."""
        validate(self)
        if self.verify_max_error > 0.0 and self.verify == 0:
            raise SettingError("verify_max_error", "verify max error checks a verification: add --verify N (texels)")
        if self.rebake_changed and self.verify:
            raise SettingError("rebake_changed", "re-bake changed keeps texels from the last bake: verify it "
                                                 "with a bake of its own (drop --verify)")
        if self.dither and self.png_bits != "8":
            raise SettingError("dither", "dither applies to 8-bit PNG files: add --png-bits 8")
        if self.match_names and (not self.low_suffix or not self.high_suffix
                                 or self.low_suffix.lower() == self.high_suffix.lower()):
            # The option named is the one at fault: the empty one, else the high (the second).
            name = "low_suffix" if not self.low_suffix else "high_suffix"
            raise SettingError(name, f"the low and high suffixes must differ and not be empty, got "
                                     f"'{self.low_suffix}' and '{self.high_suffix}'")
        return self
