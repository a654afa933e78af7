# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender glue: properties, operators, panels and the command-line hook.

Registration never touches the GPU (background mode has none until a bake asks for it).
"""
from . import (auto_rebake, bake_operator, cli_command, panels, preferences, properties, render_operator,
               sphere_operators, view_properties, viewport_overlay)

_modules = (properties, view_properties, bake_operator, auto_rebake, render_operator, sphere_operators, viewport_overlay,
            panels, preferences, cli_command)


def register() -> None:
    for mod in _modules:
        mod.register()


def unregister() -> None:
    for mod in reversed(_modules):
        mod.unregister()
