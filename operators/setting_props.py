# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender properties made from the core's setting definitions (``core/setting_spec.py``), so
the panel's defaults, ranges and tooltips are the CLI's and the core's."""
from __future__ import annotations

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from ..hao_addon.core.setting_spec import specs

# Blender has no exclusive minimum: a property whose core range excludes its minimum starts
# this far above it (the core accepts it; nobody needs a d_max of less than a micrometre).
EXCLUSIVE_MIN_STEP = 1e-6


def _float32_inside(bound: float | None, inward: int) -> float | None:
    """The float32 nearest to bound on the range's side: FloatProperty stores float32, and
    0.99 rounds up to 0.99000001, which the core (float64) would refuse."""
    if bound is None:
        return None
    f = np.float32(bound)
    if (inward > 0 and float(f) < bound) or (inward < 0 and float(f) > bound):  # compared in float64
        f = np.nextafter(f, np.float32(np.inf if inward > 0 else -np.inf))
    return float(f)


def tooltip(text: str) -> str:
    return text[:1].upper() + text[1:]


def enum_items(choices) -> tuple:
    """EnumProperty items of core Choice definitions (their order is the number a .blend file
    stores, unchanged since the first release)."""
    return tuple((c.identifier, c.label, tooltip(c.description)) for c in choices)


def enum_aliases(settings_cls) -> dict[str, dict[str, str]]:
    """{property: {earlier identifier: identifier}} of every enum setting: the core's words
    ('visible', 'color-attribute'), which the previous releases' panel used, still set it."""
    return {f.name: {str(c.value): c.identifier for c in spec.choices if str(c.value) != c.identifier}
            for f, spec in specs(settings_cls) if spec.ui and spec.choices}


class EnumAliases:
    """A property group mixin: its enum properties also take their earlier identifiers
    (_enum_aliases: {property: {earlier: identifier}}, enum_aliases), so scripts, presets
    and farm submitters written against an earlier release keep working."""

    _enum_aliases: dict = {}

    def __setattr__(self, name: str, value) -> None:
        aliases = type(self)._enum_aliases.get(name)
        if aliases and isinstance(value, str):
            value = aliases.get(value, value)
        super().__setattr__(name, value)


def blender_property(field, spec, update=None):
    """The bpy.props definition of one setting."""
    kw = {"name": spec.label, "description": spec.sentence,
          "default": next(c.identifier for c in spec.choices if c.value == field.default) if spec.choices
          else field.default}
    if update is not None:
        kw["update"] = update
    if spec.choices:
        return EnumProperty(items=enum_items(spec.choices), **kw)
    if isinstance(field.default, bool):
        return BoolProperty(**kw)
    if isinstance(field.default, str):
        return StringProperty(**kw)
    low, high = spec.minimum, spec.maximum
    if low is not None and spec.above_minimum:
        low = low + EXCLUSIVE_MIN_STEP
    if not isinstance(field.default, int):
        low, high = _float32_inside(low, +1), _float32_inside(high, -1)
    for key, value in (("min", low), ("max", high), ("soft_max", spec.soft_max)):
        if value is not None:
            kw[key] = value
    if spec.subtype:
        kw["subtype"] = spec.subtype
    if isinstance(field.default, int):
        return IntProperty(**kw)
    if spec.subtype == 'DISTANCE':
        kw["unit"] = 'LENGTH'
    return FloatProperty(**kw)


def setting_annotations(settings_cls, update=None) -> dict:
    """{field name: property} for every setting of the dataclass that has a UI."""
    return {f.name: blender_property(f, spec, update) for f, spec in specs(settings_cls) if spec.ui}


def settings_from(group: bpy.types.PropertyGroup, settings_cls):
    """The settings dataclass filled from a property group made by setting_annotations."""
    return settings_cls(**{f.name: from_property(f, spec, getattr(group, f.name))
                           for f, spec in specs(settings_cls) if spec.ui})


def from_property(field, spec, value):
    """A property's value as the setting holds it: an enum identifier back to its Choice's value."""
    if spec.choices:
        return next(c.value for c in spec.choices if c.identifier == value)
    return value
