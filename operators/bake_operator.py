# SPDX-License-Identifier: GPL-3.0-or-later
"""The Bake AO operator: blocking ``execute`` for scripts and background mode, a modal
``invoke`` with progress bar, status text and ESC to cancel for artists."""
from __future__ import annotations

import time
import traceback
from dataclasses import replace

import bpy

from ..hao_addon.blender.bake_job import BakeJob
from ..hao_addon.blender.color_attributes import AO_ATTRIBUTE
from ..hao_addon.core.errors import UserInputError
from ..hao_addon.gpu.context import GPUUnavailableError
from ..hao_addon.gpu.shaders import ShaderCompileError
from ..hao_addon.rebake import RebakeReport

# Errors a user can act on: the project's own types (and the file system's): reported in one
# line. Anything else is a bug: reported as an internal error, its traceback printed to
# Blender's system console (internal_error), the scene left as it was.
USER_ERRORS = (UserInputError, GPUUnavailableError, ShaderCompileError, OSError)
# Wall time of GPU work per modal tick: short enough to keep the UI responsive.
TICK_BUDGET_S = 0.1


def internal_error(exc: BaseException) -> str:
    """The one-line report of an error that is not the user's: its type and last line, and
    where the traceback went (printed here to Blender's system console)."""
    traceback.print_exception(exc)
    lines = [line.strip() for line in str(exc).splitlines() if line.strip()]
    return (f"Bake AO: internal error ({type(exc).__name__}: {lines[-1] if lines else ''}); "
            f"the traceback is in the system console (Window > Toggle System Console); please report it")


def bake_targets(context) -> list:
    return [o for o in context.selected_objects if o.type == 'MESH']


def error_note(job: BakeJob) -> str:
    """' (error ~0.0084 RMSE, 0.028 p99 (256 directions))': the largest estimate of the job's
    bakes (core/bake/error_estimate.py), or '' when none has one."""
    errors = [result.error for _o, _l, result in job.baked() if result.error is not None]
    if not errors:
        return ""
    return f" ({max(errors, key=lambda e: e.p99).text()})"


class ModalBakeRunner:
    """The modal path's state machine, separate from the operator so tests can drive it
    without a window: ``tick`` runs directions for up to one budget, ``cancel`` rolls back."""

    def __init__(self, job: BakeJob, window_manager=None, workspace=None) -> None:
        self.job = job
        self.steps = job.steps()
        self.wm = window_manager
        self.workspace = workspace
        self.fraction = 0.0
        self.status = ""
        if self.wm is not None:
            self.wm.progress_begin(0, 1000)

    def tick(self, budget_s: float = TICK_BUDGET_S) -> bool:
        """Advance; True when the bake finished and was committed."""
        end = time.perf_counter() + budget_s
        while time.perf_counter() < end:
            try:
                self.fraction, self.status = next(self.steps)
            except StopIteration:
                self.job.commit()
                self._end()
                return True
        if self.wm is not None:
            self.wm.progress_update(int(self.fraction * 1000))
        if self.workspace is not None:
            self.workspace.status_text_set(f"{self.status}   (Esc to cancel)")
        return False

    def cancel(self) -> None:
        self.steps.close()  # runs the bake generator's finally: GPU resources freed
        self.job.cancel()
        self._end()

    def _end(self) -> None:
        if self.wm is not None:
            self.wm.progress_end()
        if self.workspace is not None:
            self.workspace.status_text_set(None)


def cancelled_note(job: BakeJob) -> str:
    """What a cancelled or failed bake left: nothing, or a sequence's finished frames."""
    kept = job.written_note()
    return f"{kept}, nothing of the frame it stopped" if kept else "nothing was changed"


class OBJECT_OT_hao_bake_ao(bpy.types.Operator):
    """Bake ambient occlusion of the selected meshes into image textures on the GPU"""

    bl_idname = "object.hao_bake_ao"
    bl_label = "Bake AO"
    bl_options = {'REGISTER', 'UNDO'}

    _runner: ModalBakeRunner | None = None
    _timer = None

    changed_only: bpy.props.BoolProperty(
        name="Re-bake Changed", options={'SKIP_SAVE'},
        description="Re-bake only the texels that what changed since the last bake of each map can have moved; "
                    "the report gives how many, why, and the bound on the kept ones")

    @classmethod
    def description(cls, context, properties):
        if properties.changed_only:
            return ("Re-bake only the texels that an edit since the last bake can have changed (the others are "
                    "kept, within the bound the report gives)")
        return cls.__doc__

    @classmethod
    def poll(cls, context):
        if context.mode != 'OBJECT':
            cls.poll_message_set("Switch to Object Mode to bake")
            return False
        if not bake_targets(context):
            cls.poll_message_set("Select one or more mesh objects to bake")
            return False
        if getattr(context.scene, "hao_bake", None) is None:
            cls.poll_message_set("HAO settings are not registered")
            return False
        return True

    def _make_job(self, context) -> BakeJob:
        request = context.scene.hao_bake.to_request(bake_targets(context), context.active_object)
        if self.changed_only:
            request = replace(request, options=replace(request.options, rebake_changed=True))
        return BakeJob(request, context.evaluated_depsgraph_get)

    def _report_done(self, job: BakeJob) -> None:
        for note in job.request.notes:
            self.report({'WARNING'}, note)
        bound = job.request.options.verify_max_error
        for label, check in job.verifications:  # --verify: the map against the reference
            missed = bound > 0.0 and check.misses(bound)
            self.report({'ERROR'} if missed else {'INFO'}, f"'{label}' {check.text()}"
                        + (f": above Verify Max Error {bound:g}" if missed else ""))
        for _obj, _uv, result in job.results:
            for warning in result.stats.get("warnings", []):
                self.report({'WARNING'}, warning)
        for label, (_path, result, _state) in job.records.items():  # Re-bake Changed: what it did
            if "rebake" in result.stats:
                self.report({'INFO'}, f"'{label}' {RebakeReport(**result.stats['rebake']).text()}")
        if job.request.frames:
            files = sum(len(v) for k, v in job.files.items() if k[1] == "ao")
            self.report({'INFO'}, f"Baked AO of {len(job.request.frames)} frames into {files} files "
                                  f"({sum(e['reused'] for e in job.frame_results)} frames reused an earlier bake)")
            return
        if not job.request.kind.writes_images:
            names = ", ".join(f"'{obj.name}'" for obj, _uv, _result in job.results)
            self.report({'INFO'}, f"Baked AO into the colour attribute '{AO_ATTRIBUTE}' of {names}{error_note(job)}")
            return
        names = ", ".join(f"'{im.name}'" for im in job.committed)
        self.report({'INFO'}, f"Baked AO into {names}{error_note(job)}")

    def execute(self, context):
        try:
            job = self._make_job(context)
        except USER_ERRORS as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}
        except Exception as exc:  # a bug: reported as one, the scene as it was
            self.report({'ERROR'}, internal_error(exc))
            return {'CANCELLED'}
        try:
            job.run()
            job.commit()
        except USER_ERRORS as exc:
            job.cancel()
            self.report({'ERROR'}, f"Bake AO failed: {exc}" + (f" ({job.written_note()})" if job.written else ""))
            return {'CANCELLED'}
        except Exception as exc:
            job.cancel()
            self.report({'ERROR'}, internal_error(exc))
            return {'CANCELLED'}
        except BaseException:
            job.cancel()
            raise
        self._report_done(job)
        return {'FINISHED'}

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        try:
            job = self._make_job(context)
        except USER_ERRORS as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}
        except Exception as exc:
            self.report({'ERROR'}, internal_error(exc))
            return {'CANCELLED'}
        wm = context.window_manager
        self._runner = ModalBakeRunner(job, wm, context.workspace)
        self._timer = wm.event_timer_add(0.01, window=context.window)
        wm.modal_handler_add(self)
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        if event.type == 'ESC':
            job = self._runner.job
            self._stop(context, cancelled=True)
            self.report({'WARNING'}, f"Bake AO cancelled: {cancelled_note(job)}")
            return {'CANCELLED'}
        if event.type != 'TIMER':
            return {'RUNNING_MODAL'}  # keep the scene still while baking
        try:
            done = self._runner.tick()
        except USER_ERRORS as exc:
            self._stop(context, cancelled=True)
            self.report({'ERROR'}, f"Bake AO failed: {exc}")
            return {'CANCELLED'}
        except Exception as exc:
            self._stop(context, cancelled=True)
            self.report({'ERROR'}, internal_error(exc))
            return {'CANCELLED'}
        if done:
            job = self._runner.job
            self._stop(context, cancelled=False)
            self._report_done(job)
            return {'FINISHED'}
        return {'RUNNING_MODAL'}

    def cancel(self, context):  # Blender calls this when the window closes mid-bake
        self._stop(context, cancelled=True)

    def _stop(self, context, cancelled: bool) -> None:
        if self._timer is not None:
            context.window_manager.event_timer_remove(self._timer)
            self._timer = None
        if self._runner is not None:
            if cancelled:
                self._runner.cancel()
            self._runner = None


classes = (OBJECT_OT_hao_bake_ao,)
register, unregister = bpy.utils.register_classes_factory(classes)
