# SPDX-License-Identifier: GPL-3.0-or-later
"""Create Blender's GPU context in background mode (``blender -b``, ``import bpy``).

In background mode every ``gpu`` call raises ``SystemError`` until the window manager has
initialised the GPU backend. Blender 4.2 to 5.0 have no ``gpu.init()``; rendering once with a
throw-away ``RenderEngine`` whose ``bl_use_gpu_context`` is set makes Blender create the
context (0.05 s, no shader compiled), and it stays alive for the rest of the process.
In the GUI the context already exists and nothing is done.
"""
from __future__ import annotations

import glob
import os

import bpy
import gpu

from ..core.errors import GPUUnavailableError  # raised here; the operators name it from here


def gpu_is_ready() -> bool:
    """True when ``gpu`` objects can be created in this process."""
    try:
        gpu.types.GPUOffScreen(1, 1).free()
    except SystemError:
        return False
    return True


class _HaoGPUInitEngine(bpy.types.RenderEngine):
    bl_idname = "HAO_GPU_INIT_ENGINE"
    bl_label = "HAO GPU init"
    bl_use_gpu_context = True

    def render(self, depsgraph):  # noqa: D401 - nothing to draw; the context is the point
        pass


def _let_mesa_software_grant_gl46() -> None:
    """Blender's headless context creation asks EGL for OpenGL 4.6 first, then 4.5, ...
    Mesa's software rasterizer (llvmpipe, used where no GPU render node exists) offers 4.5,
    so that first attempt fails and EGL prints ``EGL_BAD_MATCH`` on stderr (once in 4.2,
    three times in 5.x) before 4.5 succeeds. Telling Mesa to grant 4.6 makes the first
    attempt succeed: Blender uses no 4.6-only feature (its GLSL is 4.30, extensions are
    queried one by one). Only Mesa reads the variable; a user's own setting is kept."""
    if "MESA_GL_VERSION_OVERRIDE" in os.environ:
        return
    if os.environ.get("LIBGL_ALWAYS_SOFTWARE") or not glob.glob("/dev/dri/renderD*"):
        os.environ["MESA_GL_VERSION_OVERRIDE"] = "4.6"


def ensure_gpu_context() -> None:
    """Make the ``gpu`` module usable, creating a context in background mode if needed.

    Leaves no datablock, scene or registered class behind. Raises GPUUnavailableError with
    the driver's message when the platform has no OpenGL/EGL.
    """
    if gpu_is_ready():
        return
    _let_mesa_software_grant_gl46()
    if hasattr(gpu, "init"):  # newer Blender versions expose this directly
        gpu.init()
        if gpu_is_ready():
            return
    had_render_result = {im.name for im in bpy.data.images if im.type == 'RENDER_RESULT'}
    bpy.utils.register_class(_HaoGPUInitEngine)
    scene = bpy.data.scenes.new("__hao_gpu_init")
    cam_data = bpy.data.cameras.new("__hao_gpu_init")
    cam = bpy.data.objects.new("__hao_gpu_init", cam_data)
    try:
        scene.collection.objects.link(cam)
        scene.camera = cam
        scene.render.engine = _HaoGPUInitEngine.bl_idname
        scene.render.resolution_x = scene.render.resolution_y = 8
        scene.render.resolution_percentage = 100
        bpy.ops.render.render(scene=scene.name)
    except RuntimeError as exc:
        raise GPUUnavailableError(f"could not create a GPU context: {exc}") from exc
    finally:
        bpy.data.objects.remove(cam)
        bpy.data.cameras.remove(cam_data)
        bpy.data.scenes.remove(scene)
        bpy.utils.unregister_class(_HaoGPUInitEngine)
        for im in [i for i in bpy.data.images if i.type == 'RENDER_RESULT']:
            if im.name not in had_render_result:
                bpy.data.images.remove(im)
    if not gpu_is_ready():
        raise GPUUnavailableError(
            "no GPU context: install an OpenGL 4.3+ driver (on headless Linux: "
            "libegl1 libegl-mesa0 libgl1-mesa-dri)")
