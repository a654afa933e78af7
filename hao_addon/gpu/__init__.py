# SPDX-License-Identifier: GPL-3.0-or-later
"""GPU passes. Each pass owns its shaders and resources and frees them deterministically."""


def baker_for(method: str):
    """The GPU bake pass class for a method name ('scatter' or 'gather')."""
    from .context import ensure_gpu_context
    ensure_gpu_context()
    if method == "scatter":
        from .bake_scatter import ScatterBaker
        return ScatterBaker
    if method == "gather":
        from .bake_gather import GatherBaker
        return GatherBaker
    raise ValueError(f"unknown bake method '{method}'")
