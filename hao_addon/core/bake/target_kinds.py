# SPDX-License-Identifier: GPL-3.0-or-later
"""The kinds of bake target as rows of data (no imports: the settings, the abilities and the
plan all read them). See core/bake/targets.py for the target type itself."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class TargetKind:
    """name: the key. needs_uvs: the target's UV layout is sampled (texels, or ray starts). target_occludes: the target
    mesh itself is drawn as an occluder. ability: what a baker must be able to bake for
    it (core/bake/abilities.py; None: every baker can)."""

    name: str
    needs_uvs: bool
    target_occludes: bool
    ability: str | None


TARGET_KINDS = {k.name: k for k in (
    TargetKind("texels", needs_uvs=True, target_occludes=True, ability=None),
    TargetKind("corners", needs_uvs=False, target_occludes=True, ability="color-attribute"),
    TargetKind("projected", needs_uvs=True, target_occludes=False, ability="selected-to-active"),
)}


def kind_name(target_setting: str, high_to_low: bool) -> str:
    """The kind of a bake with the settings' Target ('image' or 'color-attribute') and,
    where high_to_low, Selected to Active (a colour attribute with it is refused by
    BakeTarget.check)."""
    if target_setting == "color-attribute":
        return "corners"
    return "projected" if high_to_low else "texels"
