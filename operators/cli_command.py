# SPDX-License-Identifier: GPL-3.0-or-later
"""``blender -c hao bake ...``: the same command line as ``python -m hao_addon``."""
from __future__ import annotations

import bpy

_handle = None


def _cli(argv: list[str]) -> int:
    from ..hao_addon.cli import main
    return main(argv)


def register() -> None:
    global _handle
    if hasattr(bpy.utils, "register_cli_command"):  # Blender 4.2+
        _handle = bpy.utils.register_cli_command("hao", _cli)


def unregister() -> None:
    global _handle
    if _handle is not None:
        bpy.utils.unregister_cli_command(_handle)
        _handle = None
