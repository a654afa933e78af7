# SPDX-License-Identifier: GPL-3.0-or-later
"""Sync / Clear Sphere Proxies, and the optional drawing of the spheres in the viewport."""

import bpy
import numpy as np
from bpy.props import IntProperty

_draw_handle = None


class OBJECT_OT_hao_sync_spheres(bpy.types.Operator):
    """Cluster the active mesh's rest pose into sphere proxies (Lloyd); from then on the spheres
    follow its armature every frame and cast distant AO"""

    bl_idname = "object.hao_sync_spheres"
    bl_label = "Sync Sphere Proxies"
    bl_options = {'REGISTER', 'UNDO'}

    count: IntProperty(name="Spheres", description="Number of sphere proxies (K)", default=64, min=8, max=1024)
    seed: IntProperty(name="Seed", description="Seed of the deterministic k-means++ start", default=0, min=0)
    max_iterations: IntProperty(name="Max Iterations", description="Cap on Lloyd iterations", default=100,
                                min=1, max=1000)

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        if obj is None or obj.type != 'MESH':
            cls.poll_message_set("Select a mesh object")
            return False
        return True

    def execute(self, context):
        from ..hao_addon.blender.sphere_proxies import make_proxies
        from ..hao_addon.core.proxies.lloyd import ProxyError
        obj = context.active_object
        try:
            info = make_proxies(obj, self.count, self.seed, self.max_iterations)
        except ProxyError as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}
        self.report({'INFO'}, f"{self.count} sphere proxies on '{obj.name}' ({info['iterations']} Lloyd iterations)")
        return {'FINISHED'}


class OBJECT_OT_hao_clear_spheres(bpy.types.Operator):
    """Remove the active mesh's sphere proxies"""

    bl_idname = "object.hao_clear_spheres"
    bl_label = "Clear Sphere Proxies"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        from ..hao_addon.blender.sphere_proxies import has_proxies
        obj = context.active_object
        if obj is None or not has_proxies(obj):
            cls.poll_message_set("The active object has no sphere proxies")
            return False
        return True

    def execute(self, context):
        from ..hao_addon.blender.sphere_proxies import clear_proxies
        clear_proxies(context.active_object)
        return {'FINISHED'}


def draw_spheres() -> None:
    """Three great circles per sphere proxy, when 'Show Spheres' is on (viewport only)."""
    context = bpy.context
    props = getattr(context.scene, "hao_view", None)
    if props is None or not props.show_spheres or bpy.app.background:
        return
    import gpu
    from gpu_extras.batch import batch_for_shader

    from ..hao_addon.blender.sphere_proxies import scene_spheres
    try:
        spheres, _ = scene_spheres(context.view_layer, context.evaluated_depsgraph_get())
    except ValueError:
        return
    if spheres is None:
        return
    centres, radii = spheres
    t = np.linspace(0.0, 2.0 * np.pi, 25)
    ring = np.stack([np.cos(t), np.sin(t), np.zeros_like(t)], 1)
    circles = np.concatenate([ring, ring[:, [2, 0, 1]], ring[:, [1, 2, 0]]])
    segs = np.concatenate([np.stack([circles[i * 25:(i + 1) * 25 - 1], circles[i * 25 + 1:(i + 1) * 25]], 1)
                           for i in range(3)]).reshape(-1, 3)
    pts = (centres[:, None, :] + radii[:, None, None] * segs[None]).reshape(-1, 3).astype(np.float32)
    shader = gpu.shader.from_builtin('UNIFORM_COLOR')
    batch = batch_for_shader(shader, 'LINES', {"pos": pts})
    shader.uniform_float("color", (1.0, 0.5, 0.1, 0.8))
    batch.draw(shader)


@bpy.app.handlers.persistent
def sync_on_frame_change(scene, depsgraph=None) -> None:
    """Per-frame sync: update the proxies of visible meshes whose deformation changed (the
    others are reused, see hao_addon/blender/sphere_proxies.py). Errors (a topology change)
    are left to the passes that use the spheres, which report them."""
    from ..hao_addon.blender.sphere_proxies import scene_spheres
    from ..hao_addon.core.proxies.lloyd import ProxyError
    view_layer = bpy.context.view_layer
    if view_layer is None:
        return
    try:
        scene_spheres(view_layer, depsgraph or bpy.context.evaluated_depsgraph_get())
    except ProxyError:
        pass


classes = (OBJECT_OT_hao_sync_spheres, OBJECT_OT_hao_clear_spheres)


def register() -> None:
    global _draw_handle
    for cls in classes:
        bpy.utils.register_class(cls)
    _draw_handle = bpy.types.SpaceView3D.draw_handler_add(draw_spheres, (), 'WINDOW', 'POST_VIEW')
    bpy.app.handlers.frame_change_post.append(sync_on_frame_change)


def unregister() -> None:
    global _draw_handle
    while sync_on_frame_change in bpy.app.handlers.frame_change_post:
        bpy.app.handlers.frame_change_post.remove(sync_on_frame_change)
    if _draw_handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_draw_handle, 'WINDOW')
        _draw_handle = None
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
