# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's preferences: where its manual is (shipped inside the extension, site/)."""
from __future__ import annotations

from pathlib import Path

import bpy

# The manual as tools/docs.sh builds it and tools/build_extension.py ships it.
MANUAL = Path(__file__).resolve().parent.parent / "site" / "index.html"


class HAO_AP_preferences(bpy.types.AddonPreferences):
    bl_idname = __package__.rpartition(".")[0]  # the extension's package (the repository root)

    def draw(self, context) -> None:
        layout = self.layout
        if MANUAL.is_file():
            op = layout.operator("wm.path_open", text="Open the Manual", icon='HELP')
            op.filepath = str(MANUAL)
        else:
            layout.label(text="The manual is not built here: run tools/docs.sh", icon='INFO')


def register() -> None:
    bpy.utils.register_class(HAO_AP_preferences)


def unregister() -> None:
    bpy.utils.unregister_class(HAO_AP_preferences)
