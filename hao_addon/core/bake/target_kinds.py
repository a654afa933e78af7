# SPDX-License-Identifier: GPL-3.0-or-later
"""The kinds of bake target as rows of data (no imports: the settings, the abilities and the
plan all read them). See core/bake/targets.py for the target type itself."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class TargetKind:
    """name: the key. needs_uvs: the target's UV layout is sampled (texels, or ray starts).
    target_occludes: the target mesh itself is drawn as an occluder. ability: what a baker
    must be able to bake for it (core/bake/abilities.py; None: every baker can). target: the
    Target setting's value that asks for it. writes_images: its output is images of the UV
    layout (files, image datablocks); otherwise one value per mesh element, stored in the
    mesh (a colour attribute). settings: the settings that belong to it alone (the panel
    draws them under Target). phrase: how a refusal names it."""

    name: str
    needs_uvs: bool
    target_occludes: bool
    ability: str | None
    target: str
    writes_images: bool
    phrase: str
    settings: tuple[str, ...] = ()


TARGET_KINDS = {k.name: k for k in (
    TargetKind("texels", needs_uvs=True, target_occludes=True, ability=None, target="image", writes_images=True,
               phrase="image textures"),
    TargetKind("corners", needs_uvs=False, target_occludes=True, ability="color-attribute", target="color-attribute",
               writes_images=False, phrase="a colour attribute", settings=("color_domain",)),
    TargetKind("projected", needs_uvs=True, target_occludes=False, ability="selected-to-active", target="image",
               writes_images=True, phrase="Selected to Active"),
)}


def kind_name(target_setting: str, high_to_low: bool) -> str:
    """The kind of a bake with the settings' Target ('image' or 'color-attribute') and,
    where high_to_low, Selected to Active: the Target's kind whose target occludes unless
    high_to_low (Cycles' definition); a colour attribute has only its own (with high_to_low
    it is refused by BakeTarget.check)."""
    kinds = [k for k in TARGET_KINDS.values() if k.target == target_setting]
    if not kinds:
        raise ValueError(f"unknown Target '{target_setting}'")
    return next((k for k in kinds if k.target_occludes != high_to_low), kinds[0]).name


def target_kind(target_setting: str, high_to_low: bool = False) -> TargetKind:
    """The row of kind_name."""
    return TARGET_KINDS[kind_name(target_setting, high_to_low)]


# The Target setting's value that bakes images of the mesh's own surface (a thickness map's inner bake).
IMAGE_TARGET = TARGET_KINDS["texels"].target
