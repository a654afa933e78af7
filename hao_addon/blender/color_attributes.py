# SPDX-License-Identifier: GPL-3.0-or-later
"""Baked AO into a mesh's colour attribute (Cycles' Color Attributes bake target)."""
from __future__ import annotations

import bpy
import numpy as np

from ..core.errors import BakeInputError

AO_ATTRIBUTE = "hao_ao"
DOMAIN_NAMES = {"point": 'POINT', "corner": 'CORNER'}


def store_color_attribute(mesh: bpy.types.Mesh, values: np.ndarray, domain: str,
                          name: str = AO_ATTRIBUTE) -> bpy.types.Attribute:
    """Write accessibility values (n,) (one per vertex for 'point', per face corner for
    'corner') as grey RGB, alpha 1, into the float colour attribute `name` (any attribute of
    that name with another type or domain is replaced) and make it the active colour attribute, so the
    viewport's Attribute colour and the renderers' Color Attribute node show it. AO is data,
    written linear as Cycles writes its float colour attributes."""
    blender_domain = DOMAIN_NAMES[domain]
    # Every attribute of that name, not only colour ones: an INT 'hao_ao', or a colour one on
    # the FACE domain, would otherwise keep the name and push ours to 'hao_ao.001'.
    attribute = mesh.attributes.get(name)
    if attribute is not None and (attribute.domain != blender_domain or attribute.data_type != 'FLOAT_COLOR'):
        mesh.attributes.remove(attribute)
        attribute = None
    if attribute is None:
        attribute = mesh.color_attributes.new(name, 'FLOAT_COLOR', blender_domain)
    if attribute.name != name:  # a built-in or locked attribute held the name
        mesh.attributes.remove(attribute)
        raise BakeInputError(f"'{mesh.name}' keeps an attribute named '{name}' that cannot be replaced: "
                             f"rename it and bake again")
    rgba = np.ones((len(values), 4), np.float32)
    rgba[:, :3] = np.asarray(values, np.float32)[:, None]
    attribute.data.foreach_set("color", rgba.ravel())
    mesh.color_attributes.active_color = attribute
    mesh.update()
    return attribute


def read_color_attribute(mesh: bpy.types.Mesh, name: str = AO_ATTRIBUTE) -> np.ndarray:
    """(n,) the red channel of a float colour attribute (tests and reports)."""
    attribute = mesh.color_attributes[name]
    rgba = np.empty(len(attribute.data) * 4, np.float32)
    attribute.data.foreach_get("color", rgba)
    return rgba.reshape(-1, 4)[:, 0].copy()
