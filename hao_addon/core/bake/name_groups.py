# SPDX-License-Identifier: GPL-3.0-or-later
"""Bake groups matched by name (Substance's *By Mesh Name*, Marmoset's bake groups), pure data.

A mesh belongs to group X as its low-poly when its name is X + the low suffix ('crate_low'),
as its high-poly when X + the high suffix ('crate_high'). Blender's duplicate numbers
('crate_high.001') are ignored, case is ignored, and a mesh whose own name matches nothing
takes its collection's name ('crate_high' collection holding 'bolt', 'screw'). Names that
match nothing are listed, never guessed.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

_DUPLICATE = re.compile(r"\.\d{3,}$")  # Blender's '.001' of a copied object


@dataclass(frozen=True)
class NameGroup:
    """name: the shared base ('crate'); lows, highs: the object names, in the input's order."""

    name: str
    lows: tuple[str, ...]
    highs: tuple[str, ...]


@dataclass(frozen=True)
class GroupMatch:
    """groups: those with a low-poly, by name; unmatched: object names in no group; orphans:
    the high-poly names of groups without a low-poly (nothing to bake them onto)."""

    groups: tuple[NameGroup, ...]
    unmatched: tuple[str, ...]
    orphans: tuple[str, ...]


def role_of(name: str, low_suffix: str, high_suffix: str) -> tuple[str, str] | None:
    """('low' | 'high', the base name) of a name ending in a suffix (before Blender's
    duplicate number; case ignored), or None."""
    stem = _DUPLICATE.sub("", name)
    for role, suffix in (("low", low_suffix), ("high", high_suffix)):
        if suffix and stem.lower().endswith(suffix.lower()) and len(stem) > len(suffix):
            return role, stem[: len(stem) - len(suffix)].lower()
    return None


def match_groups(meshes: list[tuple[str, str]], low_suffix: str = "_low", high_suffix: str = "_high") -> GroupMatch:
    """Group meshes given as (object name, its collection's name or '') by their names."""
    if not low_suffix or not high_suffix or low_suffix.lower() == high_suffix.lower():
        raise ValueError(f"the low and high suffixes must differ and not be empty: '{low_suffix}', '{high_suffix}'")
    found: dict[str, dict[str, list[str]]] = {}
    unmatched = []
    for name, collection in meshes:
        role = role_of(name, low_suffix, high_suffix) or (role_of(collection, low_suffix, high_suffix)
                                                          if collection else None)
        if role is None:
            unmatched.append(name)
            continue
        found.setdefault(role[1], {"low": [], "high": []})[role[0]].append(name)
    groups = tuple(NameGroup(base, tuple(parts["low"]), tuple(parts["high"]))
                   for base, parts in found.items() if parts["low"])
    orphans = tuple(name for parts in found.values() if not parts["low"] for name in parts["high"])
    return GroupMatch(groups, tuple(unmatched), orphans)
