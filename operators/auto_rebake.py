# SPDX-License-Identifier: GPL-3.0-or-later
"""Auto Re-bake (the bake panel's setting, off by default): after an edit of a mesh, Re-bake
Changed runs on the selected meshes once edits have paused for AUTO_REBAKE_DELAY seconds,
in Object Mode, and only where each has a bake of this session to start from (an automatic
bake never starts a full one the user did not ask for). A depsgraph handler notes geometry
and transform updates of mesh objects and (re)starts a one-shot timer; the timer runs the
operator. Registration adds the handler; unregistration removes it and the timer."""
from __future__ import annotations

import bpy

from ..hao_addon.blender import rebake_records
from ..hao_addon.blender.bake_request import output_path_for
from .bake_operator import bake_targets

# Seconds without an edit before the re-bake starts (a drag's many updates make one re-bake).
AUTO_REBAKE_DELAY = 1.0


def _edited_meshes(depsgraph) -> bool:
    """Whether the update moved or reshaped a mesh object."""
    return any(isinstance(u.id, bpy.types.Object) and u.id.type == 'MESH'
               and (u.is_updated_geometry or u.is_updated_transform) for u in depsgraph.updates)


@bpy.app.handlers.persistent  # survive file loads
def note_edit(scene, depsgraph) -> None:
    """depsgraph_update_post: schedule the re-bake (again: the delay counts from the last edit)."""
    settings = getattr(scene, "hao_bake", None)
    if settings is None or not settings.auto_rebake or not rebake_records.remembered_any():
        return
    if not _edited_meshes(depsgraph):
        return
    if bpy.app.timers.is_registered(run_auto_rebake):
        bpy.app.timers.unregister(run_auto_rebake)
    bpy.app.timers.register(run_auto_rebake, first_interval=AUTO_REBAKE_DELAY)


def ready_targets(context) -> list:
    """The selected meshes when each has a bake of this session to re-bake from, else []."""
    settings = getattr(context.scene, "hao_bake", None)
    targets = bake_targets(context) if settings is not None else []
    if not targets or settings.selected_to_active or settings.match_names:
        return []
    request = settings.to_request(targets, context.active_object)
    if not request.kind.writes_images or request.frames:
        return []
    labels = [obj.name for obj in request.targets]
    paths = [output_path_for(request, obj) for obj in request.targets]
    return targets if all(rebake_records.is_remembered(l, p) for l, p in zip(labels, paths)) else []


def run_auto_rebake() -> float | None:
    """The timer: Re-bake Changed of the selected meshes (later again outside Object Mode)."""
    context = bpy.context
    if context.mode != 'OBJECT':
        return AUTO_REBAKE_DELAY
    if ready_targets(context):
        bpy.ops.object.hao_bake_ao('EXEC_DEFAULT', changed_only=True)
    return None


def register() -> None:
    bpy.app.handlers.depsgraph_update_post.append(note_edit)


def unregister() -> None:
    while note_edit in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(note_edit)
    if bpy.app.timers.is_registered(run_auto_rebake):
        bpy.app.timers.unregister(run_auto_rebake)
    rebake_records.forget_all()
