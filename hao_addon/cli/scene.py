# SPDX-License-Identifier: GPL-3.0-or-later
"""The command line's Blender side: input checks and loading, picking meshes, writing mesh files."""
from __future__ import annotations

import os
from pathlib import Path

from .errors import CLIError, last_line
from .io import check_signals
from .parser import INPUT_FORMATS


def check_input(path: Path, allowed: tuple[str, ...]) -> Path:
    if not path.exists():
        raise CLIError(f"input file not found: {path}")
    if path.is_dir():
        raise CLIError(f"input '{path}' is a folder, not a file")
    if path.suffix.lower() not in allowed:
        raise CLIError(f"unsupported input '{path.suffix}': use {', '.join(allowed)}")
    if not os.access(path, os.R_OK):
        raise CLIError(f"cannot read '{path}': permission denied")
    if path.stat().st_size == 0:
        raise CLIError(f"input '{path}' is empty")
    return path.resolve()


def check_json_target(spec: str | None) -> None:
    if spec in (None, "-"):
        return
    from ..core.folders import nearest_existing, unmakeable_reason

    folder = Path(os.path.abspath(spec)).parent
    reason = unmakeable_reason(folder)
    if reason:
        raise CLIError(f"cannot write the report '{spec}': cannot make its folder, {reason}")
    if Path(spec).is_dir() or not os.access(nearest_existing(folder), os.W_OK):
        raise CLIError(f"cannot write the report '{spec}'")


def load_scene(path: Path) -> None:
    """Replace the current Blender session with the input file's content."""
    import bpy

    ext = path.suffix.lower()
    try:
        if ext == ".blend":
            bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
            return
        bpy.ops.wm.read_factory_settings(use_empty=True)
        check_signals()  # it registers the bundled add-ons: one interrupted there is missing
        if ext == ".obj":
            bpy.ops.wm.obj_import(filepath=str(path))
        else:
            bpy.ops.import_scene.gltf(filepath=str(path))
    except (RuntimeError, ValueError, KeyError, OSError, UnicodeError) as exc:  # the importers' own errors
        check_signals()  # a Python importer interrupted by Ctrl-C fails with Blender's RuntimeError
        raise CLIError(f"cannot read '{path.name}': {last_line(exc)}") from None


def import_meshes(path: Path) -> list:
    """Add the meshes of a .obj/.glb/.gltf/.blend file to the current scene; returns them."""
    import bpy

    before = set(bpy.data.objects)
    try:
        ext = path.suffix.lower()
        if ext == ".blend":
            with bpy.data.libraries.load(str(path)) as (data_from, data_to):
                data_to.objects = list(data_from.objects)
            for obj in data_to.objects:
                if obj is not None and obj.type == 'MESH':
                    bpy.context.scene.collection.objects.link(obj)
        elif ext == ".obj":
            bpy.ops.wm.obj_import(filepath=str(path))
        else:
            bpy.ops.import_scene.gltf(filepath=str(path))
    except (RuntimeError, ValueError, KeyError, OSError, UnicodeError) as exc:
        check_signals()
        raise CLIError(f"cannot read '{path.name}': {last_line(exc)}") from None
    check_signals()
    meshes = [o for o in bpy.data.objects if o not in before and o.type == 'MESH']
    if not meshes:
        raise CLIError(f"--high-poly '{path.name}' holds no mesh")
    return meshes


def pick_high_poly(specs: list[str]) -> list:
    """The Selected-to-Active sources: each spec a mesh file to add, or a mesh's name."""
    import bpy

    out = []
    for spec in specs:
        path = Path(spec)
        if path.suffix.lower() in INPUT_FORMATS and bpy.data.objects.get(spec) is None:
            try:
                checked = check_input(path, INPUT_FORMATS)
            except CLIError as exc:
                raise CLIError(f"--high-poly: {exc}") from None
            out += import_meshes(checked)
            continue
        obj = bpy.data.objects.get(spec)
        if obj is None or obj.type != 'MESH':
            raise CLIError(f"--high-poly '{spec}' is neither a mesh file nor a mesh in the input "
                           f"(meshes: {_mesh_names()})")
        out.append(obj)
    return out


def pick_mesh(name: str, option: str):
    import bpy

    obj = bpy.data.objects.get(name)
    if obj is None or obj.type != 'MESH':
        raise CLIError(f"{option}: no mesh object named '{name}' (meshes: {_mesh_names()})")
    return obj


def _mesh_names() -> str:
    """The scene's mesh objects, for messages that name a missing one."""
    import bpy

    return ", ".join(o.name for o in bpy.context.view_layer.objects if o.type == 'MESH') or "none"


# The files a colour-attribute bake saves its mesh to (--target color-attribute --out FILE).
MESH_OUT_FORMATS = (".blend", ".glb", ".ply")


def check_mesh_target(path: str, source: Path, allowed: tuple[str, ...], option: str) -> Path:
    """A mesh file to write (--gltf-out, or --out of a colour-attribute bake), refused before
    any work unless its extension is allowed, its folder writable and it is not the input."""
    out = Path(os.path.abspath(path))
    if out.suffix.lower() not in allowed:
        raise CLIError(f"{option} must be a {' or '.join(allowed)} file (one file, written atomically), got '{path}'")
    from ..core.folders import nearest_existing, unmakeable_reason

    reason = unmakeable_reason(out.parent)
    if reason or not os.access(nearest_existing(out.parent), os.W_OK):
        raise CLIError(f"cannot write '{out}': cannot make its folder, {reason or 'permission denied'}")
    if out.exists() and out.resolve() == source.resolve():
        raise CLIError(f"{option} '{out}' is the input file")
    return out


def check_gltf_target(path: str, source: Path) -> Path:
    """The --gltf-out file: a .glb (check_mesh_target)."""
    return check_mesh_target(path, source, (".glb",), "--gltf-out")


def export_mesh_file(objects: list, path: Path, colors: bool = False) -> None:
    """Write the objects alone as a .glb (Blender's glTF exporter; colors: with their active
    colour attribute as COLOR_0) or a .ply (linear vertex colours when colors), or the whole
    session as a .blend copy; atomically (a temporary file in the same folder, renamed over
    path)."""
    import bpy
    from ..core.folders import make_folders, remove_made

    for other in bpy.context.view_layer.objects:
        other.select_set(other in objects)
    bpy.context.view_layer.objects.active = objects[0]
    obj = objects[0]
    suffix = path.suffix.lower()
    tmp = path.with_name(f".{path.stem}.hao-{os.getpid()}{suffix}")
    made = make_folders(path.parent)
    try:
        if suffix == ".glb":
            extra = {"export_vertex_color": 'ACTIVE'} if colors else {}
            result = bpy.ops.export_scene.gltf(filepath=str(tmp), export_format='GLB', use_selection=True, **extra)
        elif suffix == ".obj":  # the active UV map: a mesh that had none has only the new one
            result = bpy.ops.wm.obj_export(filepath=str(tmp), export_selected_objects=True, export_uv=True,
                                           export_materials=False)
        elif suffix == ".ply":
            result = bpy.ops.wm.ply_export(filepath=str(tmp), export_selected_objects=True,
                                           export_colors='LINEAR' if colors else 'NONE')
        else:
            result = bpy.ops.wm.save_as_mainfile(filepath=str(tmp), copy=True, check_existing=False)
        if result != {'FINISHED'} or not tmp.is_file():
            raise CLIError(f"writing '{obj.name}' to {path.name} failed")
        os.replace(tmp, path)
        made = []
    finally:
        if tmp.exists():
            tmp.unlink()
        remove_made(made)


# The mesh file beside a map whose UV map the bake made, by the input's format (else .glb).
UV_MESH_FORMATS = {".obj": ".obj", ".glb": ".glb", ".gltf": ".glb", ".blend": ".blend"}


def uv_mesh_path(map_path: str, source: Path) -> Path:
    """Where a mesh whose UV map a bake made is written beside its map: the map's name with
    the input's format (UV_MESH_FORMATS), '_uv' added where that would be the input itself."""
    path = Path(map_path).with_suffix(UV_MESH_FORMATS.get(source.suffix.lower(), ".glb"))
    if path.exists() and path.resolve() == source.resolve():
        path = path.with_name(f"{path.stem}_uv{path.suffix}")
    return path


def export_glb(objects: list, path: Path) -> None:
    """Write the objects alone as a .glb with their baked maps (export_mesh_file)."""
    export_mesh_file(objects, path)


def pick_target(name: str, exclude: tuple = (), from_blend: bool = False) -> tuple[object, str]:
    """(the mesh to bake, a line saying why it was chosen or ""): by name; else the input's
    only visible mesh (not among exclude: a hidden one, such as the bone shape a glTF import
    keeps, is no candidate); else, in a .blend (from_blend), its active object, as
    Blender's own bake does. Several meshes and none of these is a refusal that lists them:
    never one of them silently."""
    import bpy

    if name:
        obj = bpy.data.objects.get(name)
        if obj is None or obj.type != 'MESH':
            raise CLIError(f"no mesh object named '{name}' (meshes: {_mesh_names()})")
        return obj, ""
    meshes = [o for o in bpy.context.view_layer.objects
              if o.type == 'MESH' and o not in exclude and o.visible_get()]
    if not meshes:
        every = _mesh_names()
        if every != "none":
            raise CLIError(f"the input's meshes are all hidden ({every}): name one with --object NAME")
        raise CLIError("the input contains no mesh object")
    if len(meshes) == 1:
        return meshes[0], ""
    names = ", ".join(f"'{o.name}'" for o in meshes)
    active = bpy.context.view_layer.objects.active
    if from_blend and active in meshes:
        others = ", ".join(f"'{o.name}'" for o in meshes if o != active)
        return active, (f"hao: baking '{active.name}', the file's active object ({others} occlude it; "
                        "--object NAME or --all-meshes to bake others)")
    raise CLIError(f"the input has {len(meshes)} meshes ({names}) and no active mesh object: choose with "
                   "--object NAME (repeatable), or bake each with --all-meshes")
