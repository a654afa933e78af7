# SPDX-License-Identifier: GPL-3.0-or-later
"""HAO for Blender: GPU ambient occlusion (viewport and baking).

The repository root is the extension. ``hao_addon/`` is the core (numpy math, CPU references,
GPU passes, Blender data glue); ``operators/`` is the Blender UI glue; ``gpu_shaders/`` holds
the GLSL bodies. Registration only sequences the operator modules.
"""


def register() -> None:
    from . import operators
    operators.register()


def unregister() -> None:
    from . import operators
    from .hao_addon.gpu.shaders import free_shaders
    operators.unregister()
    free_shaders()
