# SPDX-License-Identifier: GPL-3.0-or-later
"""A bake of one or more Blender objects, driven step by step (for progress and cancel).

Nothing the user can see changes until ``commit``: files are written all or none first (each
staged beside its target, then all renamed into place), then image datablocks and material
nodes; a failure there puts the earlier files back. The only change made earlier is a new
``AO_UV`` map for meshes without UVs (the evaluated mesh must carry it); ``cancel`` removes
it again. A frame sequence is the exception, by design: each frame's files are written as
soon as that frame is baked (memory stays flat in the frame count, and an interrupted
sequence keeps its finished frames, listed in ``written``).
"""
from __future__ import annotations

import glob
import os
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Generator

import bpy
import numpy as np

from .. import compat
from ..bake import BakeResult, bake_key, bake_steps, thickness_steps
from ..core.steps import relay
from ..core.bake.error_estimate import estimate
from ..verify import verify_steps
from ..core.file_checks import image_is_whole, output_is_whole
from ..core.imageio import BAKE_KEY, FORMATS, StagedFiles, check_writable, read_text
from ..core.output_files import check_output_files, frame_file, with_token
from ..core.bake.projection import HighToLow
from ..core.errors import BakeInputError
from ..core.bake.settings import BakeSettings
from ..core.bake.job_options import JobOptions
from ..core.bake.map_kinds import EXTRA_MAPS, MAP_KINDS
from ..core.bake.orm import orm_image
from ..core.bake.tangent_space import bent_normal_map
from ..core.bake.targets import BakeTarget
from ..core.bake.texture_set import texture_set_target
from ..core.bake.udim import tile_path, udim_layout
from ..core.geometry import TriangleSoup, face_normals_areas
from ..core.bake.unwrap import check_unwrap_overlap, unwrap_steps
from . import color_attributes, images, mesh_data
from .material_channels import roughness_metallic
from .paths import FRAME_TOKEN, OBJECT_TOKEN, absolute_path, example_path, object_file_name
from .view_scene import BAKED_AO_PROPERTY

# What a texture set's image and files are named after (JobOptions.texture_set).
TEXTURE_SET_NAME = "TextureSet"


@dataclass
class BakeGroup:
    """A bake group (core/bake/name_groups.py): each low-poly is baked from the highs
    (Selected to Active), or, without highs, as itself."""

    name: str
    lows: list
    highs: list


@dataclass
class BakeUnit:
    """One bake of a job: the objects baked together (one, or a texture set's), the label
    its image and files are named after, the Selected-to-Active sources (None: the objects'
    own surface) and the other meshes that occlude."""

    label: str
    objects: list
    sources: list | None
    occluders: list


@dataclass
class BakeRequest:
    """targets: mesh objects to bake. occluders: 'TARGET' (self only), 'SELECTED' (the other
    selected meshes too) or 'VISIBLE' (every visible mesh). uv_map: a UV map name, '' for the
    active render UV map, or 'AUTO': AO_UV if present, else the first UV map, else a new
    AO_UV unwrapped automatically (core/bake/unwrap.py).
    image: an existing image to overwrite (one target only), else '<object>_AO' is created.
    filepath: '' or a .png/.exr path; '{object}' in it becomes each object's name (with several
    targets and no token, '_{object}' is appended).
    high_poly: Selected to Active (Cycles' definition): these meshes are baked onto the one
    target's UVs and occlude, the target does not; cage: an optional cage object (the
    target's topology, moved vertices) the rays start from.
    Bent normals (settings.bent_normals): each target also gets an image '<object>_BentNormals'
    in options.bent_space and options.bent_convention, saved to map_paths["bent"] if given
    (tokens as filepath).
    map_paths: the files of the maps besides the AO (core/bake/map_kinds.py: key -> path,
    tokens as filepath): bent normals, thickness (settings.thickness), glTF's ORM texture
    (with wire_material it replaces the AO in the material's glTF wiring), the error map.
    settings.target 'color-attribute': each target's AO goes into its colour attribute hao_ao
    instead (settings.color_domain), UV map, image and files unused.
    options.texture_set: the targets, each with its own UVs (not overlapping across objects),
    bake together into one shared image 'TextureSet_AO' ({object} in file names: 'TextureSet').
    frames: a frame sequence: the scene is set to each frame in turn (restored after), each
    frame's maps go to files ({frame} in the paths, zero-padded; '_{frame}' added otherwise),
    no image datablocks; a frame whose evaluated geometry equals an earlier one reuses its
    bake (the bake cache)."""

    targets: list
    settings: BakeSettings
    uv_map: str = "AUTO"
    image: "bpy.types.Image | None" = None
    image_name: str = ""
    filepath: str = ""
    wire_material: bool = False
    source_path: str = ""  # the file the scene was loaded from (CLI): never overwritten
    high_poly: list | None = None
    cage: "bpy.types.Object | None" = None
    map_paths: dict[str, str] = field(default_factory=dict)
    options: JobOptions = field(default_factory=JobOptions)
    frames: list | None = None
    # What else the caller reads and writes, as (path, what) pairs, so that one check
    # (core/output_files.py) sees every file of the run: the CLI's --json report, --gltf-out,
    # a colour bake's mesh file, high-poly files, a batch's other inputs.
    extra_inputs: list = field(default_factory=list)
    extra_outputs: list = field(default_factory=list)
    # Files others write (a batch's earlier inputs' outputs): this run must not write them.
    claimed: list = field(default_factory=list)
    # Bake groups matched by name (options.match_names): every low-poly of each group is a
    # target (targets lists them all), baked from its group's highs; None: no groups.
    groups: list[BakeGroup] | None = None
    # Warnings from making the request (bake groups: the names that matched nothing).
    notes: list[str] = field(default_factory=list)
    # Text entries every image file of the run carries (core/imageio.py's BAKE_KEY: what made
    # it, for --skip-existing).
    file_text: dict = field(default_factory=dict)

    @property
    def to_color_attribute(self) -> bool:
        """settings.target 'color-attribute': AO into each target's colour attribute hao_ao
        (blender/color_attributes.py), no UV map, image or file."""
        return self.settings.target == "color-attribute"

    def map_path(self, key: str) -> str:
        """The file pattern of the map `key` (core/bake/map_kinds.py), '' when it is not written."""
        return self.filepath if key == "ao" else self.map_paths.get(key, "")


def terminator_settings(settings: BakeSettings, receiver_objects: list) -> BakeSettings:
    """settings with the terminator offset Cycles would use for these objects (the target, or
    the high-poly sources whose points receive in Selected to Active): each object's own
    where settings.terminator is 'object' and Blender has the property; several sources
    with different offsets bake with the largest."""
    if settings.terminator != "object":
        return settings
    offsets = [o for o in map(compat.object_terminator_offset, receiver_objects) if o is not None]
    return replace(settings, terminator_offset=max(offsets)) if offsets else settings


def output_path_for(request: BakeRequest, obj, filepath: str | None = None, frame: int | None = None) -> str:
    """The file an object's map is saved to (request.filepath, or the given one): '{object}'
    becomes its name; with several targets and no token, '_{object}' is added before the
    extension. A frame sequence: '{frame}' becomes the frame (zero-padded; '_{frame}' is added
    where the path has none); frame None leaves the token (for checks)."""
    filepath = request.filepath if filepath is None else filepath
    if not filepath:
        return ""
    path = absolute_path(filepath)
    if request.frames:
        path = with_token(path, FRAME_TOKEN)
    if frame is not None:
        path = frame_file(path, frame)
    if request.options.texture_set:
        return path.replace(OBJECT_TOKEN, TEXTURE_SET_NAME)
    if len(request.targets) > 1:
        path = with_token(path, OBJECT_TOKEN)
    return path.replace(OBJECT_TOKEN, object_file_name(obj))


def validate_request(request: BakeRequest) -> None:
    """Raise BakeInputError for anything that can be refused before touching the scene."""
    request.settings.validated()
    if request.groups is not None:
        _validate_groups(request)
    elif request.high_poly is not None:
        _validate_high_to_low(request)
    elif request.cage is not None:
        raise BakeInputError("a cage object is used only with Selected to Active")
    if not request.targets:
        raise BakeInputError("no mesh selected: select one or more mesh objects to bake")
    if request.to_color_attribute:
        _validate_color_attribute(request)
    for obj in request.targets:
        if obj.type != 'MESH':
            raise BakeInputError(f"'{obj.name}' is not a mesh")
        if len(obj.data.polygons) == 0:
            raise BakeInputError(f"'{obj.name}' has no faces to bake")
        if request.to_color_attribute:
            continue
        name = request.uv_map
        if name not in ("", "AUTO") and name not in obj.data.uv_layers:
            raise BakeInputError(f"'{obj.name}' has no UV map named '{name}'")
        if name == "" and not obj.data.uv_layers:
            raise BakeInputError(f"'{obj.name}' has no UV map: choose Auto to unwrap it")
    request.options.validated()
    if request.frames is not None:
        _validate_frames(request)
    if request.options.texture_set:
        _validate_texture_set(request)
    elif request.image is not None and len(request.targets) > 1:
        raise BakeInputError("an existing image can receive only one object's bake (or bake them as a texture set)")
    unknown = sorted(set(request.map_paths) - {kind.key for kind in EXTRA_MAPS})
    if unknown:
        raise BakeInputError(f"no map '{unknown[0]}' to write: the maps are {', '.join(k.key for k in EXTRA_MAPS)}")
    if request.map_path("bent") and not request.settings.bent_normals:
        raise BakeInputError("a bent-normal file needs the Bent Normals setting on")
    if request.map_path("orm") and (request.to_color_attribute or request.options.texture_set):
        raise BakeInputError("the ORM texture packs one object's AO with its material (not a colour attribute or a "
                             "texture set)")
    if request.map_path("error") and request.to_color_attribute:
        raise BakeInputError("an error map is an image of the UV layout: a colour-attribute bake reports its error "
                             "(--json) but has no error map")
    if request.map_path("thickness") and not request.settings.thickness:
        raise BakeInputError("a thickness file needs the Thickness setting on")
    if request.settings.thickness and (request.to_color_attribute or request.high_poly is not None
                                       or any(g.highs for g in request.groups or ())):
        raise BakeInputError("thickness bakes the mesh's own surface into an image (not a colour attribute or "
                             "Selected to Active)")
    size = request.settings.size
    for obj in _file_owners(request):
        for _kind, filepath, _what, channels in output_kinds(request):
            path = output_path_for(request, obj, filepath)
            if path:
                check_writable(example_path(path, (request.frames or [0])[0]), size, size, channels,
                               source=request.source_path or None)
    check_output_files(planned_files(request) + list(request.claimed), input_files(request))


def _tile_paths(path: str, tiles: tuple[int, ...] | None) -> list[str]:
    """The files of one map: path, or one per UDIM tile (tile_path)."""
    return [path] if tiles is None else [tile_path(path, t) for t in tiles]


def output_kinds(request: BakeRequest) -> tuple[tuple[str, str, str, int], ...]:
    """The image files a request writes per target: (kind, path pattern, what, channels)."""
    return tuple((kind.key, request.map_path(kind.key), kind.noun, kind.channels) for kind in MAP_KINDS)


def _file_owners(request: BakeRequest) -> list:
    """The targets whose files are written: every target, or a texture set's first (shared)."""
    return request.targets[:1] if request.options.texture_set else request.targets


def planned_files(request: BakeRequest, tiles: dict | None = None) -> list[tuple[str, str]]:
    """Every file the request writes, as (path, what): each target's maps and bent normals
    (each frame's, each UDIM tile's where tiles {label: tile numbers} is given), then the
    caller's extra_outputs."""
    out = []
    for obj in _file_owners(request):
        label = TEXTURE_SET_NAME if request.options.texture_set else obj.name
        for _kind, filepath, what, _channels in output_kinds(request):
            if not filepath:
                continue
            for frame in request.frames or [None]:
                path = output_path_for(request, obj, filepath, frame)
                at = "" if frame is None else f" at frame {frame}"
                numbers = (tiles or {}).get(label)
                out += [(tile, f"{what} of '{label}'{f' tile {t}' if numbers else ''}{at}")
                        for tile, t in zip(_tile_paths(path, numbers), numbers or [None])]
    return out + [tuple(entry) for entry in request.extra_outputs]


def finished_files(request: BakeRequest, key: str, frame: int | None = None) -> list[str] | None:
    """The files of the request (of one frame of a sequence) when every one exists and is
    current: an image carries key as its BAKE_KEY and decodes in full (a map on UDIM tiles:
    every tile file that exists does, and one at least), another file (glTF, mesh) is whole
    (output_is_whole). None when
    anything is missing or was made otherwise: the bake must run."""
    one = replace(request, frames=None if frame is None else [frame])
    done = []
    for path, _what in planned_files(one):
        if not path or path == "-":
            continue
        if os.path.splitext(path)[1].lower() not in FORMATS:
            if not output_is_whole(path):
                return None
            done.append(path)
            continue
        files = [path] if os.path.isfile(path) else sorted(glob.glob(_tile_glob(path)))
        if not files or any(read_text(f, BAKE_KEY) != key or not image_is_whole(f) for f in files):
            return None
        done += files
    return done


def _tile_glob(path: str) -> str:
    """A pattern of the UDIM tile files of path (tile_path with any four-digit number)."""
    marker = 987654321  # a number no path holds, where the tile's goes
    return glob.escape(tile_path(path, marker)).replace(str(marker), "[0-9]" * 4)


def input_files(request: BakeRequest) -> list[tuple[str, str]]:
    """The files the run reads, as (path, what): the scene's file, the image files its
    materials read, and the caller's extra_inputs."""
    from .images import scene_image_files
    source = [(request.source_path, "the input file")] if request.source_path else []
    if bpy.data.filepath:
        source.append((bpy.data.filepath, "the open .blend file"))
    return source + scene_image_files() + [tuple(entry) for entry in request.extra_inputs]


def _validate_frames(request: BakeRequest) -> None:
    if not request.frames:
        raise BakeInputError("a frame sequence needs at least one frame")
    if request.to_color_attribute:
        raise BakeInputError("a colour attribute holds one frame: bake a frame sequence into image files")
    if not request.filepath:
        raise BakeInputError("a frame sequence writes one file per frame: set Save To (a path with {frame})")


def _validate_texture_set(request: BakeRequest) -> None:
    if request.to_color_attribute or request.high_poly is not None:
        raise BakeInputError("a texture set bakes the objects' own surfaces into one image: not with a colour "
                             "attribute or Selected to Active")
    for obj in request.targets:
        if obj.type == 'MESH' and not obj.data.uv_layers:
            raise BakeInputError(f"'{obj.name}' has no UV map: a texture set bakes each object's own UVs into one "
                                 f"image, so lay out its islands beside the other objects' first")
    if request.settings.bent_normals and request.options.bent_space == "object":
        raise BakeInputError("object-space bent normals of a texture set would mix the objects' spaces: use "
                             "tangent space")


def _validate_color_attribute(request: BakeRequest) -> None:
    if request.high_poly is not None or request.settings.bent_normals:
        raise BakeInputError("a colour attribute holds the AO of the mesh's own surface: Selected to Active and "
                             "bent normals bake into images (Target: Image Textures)")
    if request.filepath or request.image is not None:
        raise BakeInputError("a colour-attribute bake writes no image: clear the image and the file path, or "
                             "bake to Image Textures")


def _validate_groups(request: BakeRequest) -> None:
    if request.high_poly is not None or request.cage is not None:
        raise BakeInputError("bake groups find their high-poly meshes by name: no separate high-poly or cage")
    if request.to_color_attribute:
        raise BakeInputError("bake groups bake each low-poly into an image (not a colour attribute)")
    if request.options.texture_set and (request.settings.bent_normals or request.settings.thickness
                                        or request.map_path("orm") or request.frames):
        raise BakeInputError("bake groups in one texture set bake the AO of one frame (not bent normals, thickness, "
                             "an ORM texture or frames)")
    if not request.groups:
        raise BakeInputError(f"no bake group found: no mesh name ends in '{request.options.low_suffix}'")
    for group in request.groups:
        for obj in group.highs:
            if obj.type != 'MESH' or len(obj.data.polygons) == 0:
                raise BakeInputError(f"high-poly '{obj.name}' of group '{group.name}' is not a mesh with faces")


def _validate_high_to_low(request: BakeRequest) -> None:
    if len(request.targets) != 1 or request.targets[0] is None:
        raise BakeInputError("Selected to Active bakes onto one low-poly mesh: make it the active object")
    if not request.high_poly:
        raise BakeInputError(f"Selected to Active: select the high-poly meshes besides '{request.targets[0].name}'")
    low = request.targets[0]
    for obj in request.high_poly:
        if obj.type != 'MESH':
            raise BakeInputError(f"high-poly '{obj.name}' is not a mesh")
        if obj == low or obj == request.cage:
            raise BakeInputError(f"'{obj.name}' cannot be both the high-poly and the low-poly or cage")
        if len(obj.data.polygons) == 0:
            raise BakeInputError(f"high-poly '{obj.name}' has no faces")
    cage = request.cage
    if cage is not None and (cage.type != 'MESH' or cage == low):
        raise BakeInputError(f"the cage '{cage.name}' must be a mesh other than the low-poly")


def _with_status(steps: Generator, fraction: float, text: str) -> Generator[tuple[float, str], None, object]:
    """Re-yield a generator's steps as (fraction, text); return its value; close it on exit."""
    return (yield from relay(steps, lambda _step: (fraction, text)))


class BakeJob:
    """Prepare, run (``steps``), then ``commit`` or ``cancel``."""

    def __init__(self, request: BakeRequest, depsgraph_getter) -> None:
        validate_request(request)
        self.request = request
        self._depsgraph_getter = depsgraph_getter
        self.created_uv: list[tuple[bpy.types.Mesh, str]] = []
        self.results: list[tuple[bpy.types.Object, str, BakeResult]] = []
        # The maps made beside each result (bent normals (size, size, 4) encoded, thickness
        # (size, size), the ORM texture (size, size, 4)): map key -> label -> map.
        self.maps: dict[str, dict[str, np.ndarray]] = {"bent": {}, "thickness": {}, "orm": {}}
        self.own_stats: dict[str, dict] = {}  # bake groups in a texture set: each low-poly's own bake's stats
        # --verify: (label, Verification) of each verified bake (hao_addon/verify.py).
        self.verifications: list[tuple[str, object]] = []
        self.written: list[str] = []  # the files in place: commit()'s, or a sequence's finished frames
        self.files: dict[tuple[str, str], list[str]] = {}  # the same by (object name, 'ao' | 'bent')
        # A frame sequence: per frame {frame, seconds, reused, outputs} (its maps are written
        # and dropped as each frame finishes).
        self.frame_results: list[dict] = []
        self._staged: StagedFiles | None = None  # commit(hold=True)'s files until release()
        # A sequence's bakes by (label, bake_key): (the frame whose files hold it, its stats and
        # tiles). A frame that repeats one copies those files: no maps are kept in memory.
        self._frame_bakes: dict[tuple[str, str], tuple[int, dict, tuple | None]] = {}
        self._copies: dict[str, int] = {}  # this frame's labels -> the earlier frame to copy
        self.committed: list[bpy.types.Image] = []
        self.finished = False
        self.unwrap_seconds = 0.0

    # -- preparation -----------------------------------------------------------------------
    def _uv_name_for(self, obj) -> Generator[tuple[float, str], None, str]:
        """The UV map to bake into (yields while a mesh that has none is unwrapped)."""
        mesh = obj.data
        name = self.request.uv_map
        if name == "":
            active = next((l for l in mesh.uv_layers if l.active_render), None) or mesh.uv_layers.active
            return active.name
        if name != "AUTO":
            return name
        if mesh_data.AO_UV_NAME in mesh.uv_layers:
            return mesh_data.AO_UV_NAME  # ours from an earlier bake: reuse, never re-unwrap
        if mesh.uv_layers:
            return mesh.uv_layers[0].name  # AUTO: the first UV map when there is one
        positions, tris, tri_loops, polygons = mesh_data.base_mesh_triangles(obj)
        size = self.request.settings.size
        unwrap = unwrap_steps(positions, tris, size, name=obj.name, polygons=polygons)
        t0 = time.perf_counter()
        uvs = yield from _with_status(unwrap, 0.0, f"Unwrapping '{obj.name}'")
        self.unwrap_seconds += time.perf_counter() - t0
        new_name = mesh_data.add_uv_layer(mesh, mesh_data.AO_UV_NAME, tri_loops, uvs)
        self.created_uv.append((mesh, new_name))  # removed again if the bake fails
        check_unwrap_overlap(mesh_data.written_triangle_uvs(mesh, new_name, tri_loops), size, obj.name)
        return new_name

    def _occluder_objects(self, target) -> list:
        mode = self.request.options.occluders
        if mode == "target":
            candidates = []
        elif mode == "selected":
            candidates = [o for o in self.request.targets if o != target]
            candidates += [o for o in bpy.context.selected_objects if o.type == 'MESH' and o not in candidates]
        else:
            candidates = [o for o in bpy.context.view_layer.objects if o.type == 'MESH' and o.visible_get()]
        seen, out = set(), []
        for o in candidates:
            if o != target and o.name not in seen:
                seen.add(o.name)
                out.append(o)
        return out

    def units(self) -> list[BakeUnit]:
        """The job's bakes: one per target, one for a texture set, or one per low-poly of
        each bake group (its sources the group's highs; its occluders by group_occluders)."""
        req = self.request
        if req.groups is not None:
            return [self._group_unit(group, low) for group in req.groups for low in group.lows]
        skip = set(req.high_poly or ()) | {req.cage}
        if req.options.texture_set:
            objects = list(req.targets)
            return [BakeUnit(TEXTURE_SET_NAME, objects, None,
                             [o for o in self._occluder_objects(objects[0]) if o not in skip | set(objects)])]
        return [BakeUnit(obj.name, [obj], req.high_poly, [o for o in self._occluder_objects(obj) if o not in skip])
                for obj in req.targets]

    def _group_unit(self, group: BakeGroup, low) -> BakeUnit:
        """A low-poly of a bake group. 'group': its own group occludes (the highs, which are
        the sources; or, without highs, the group's other lows). 'all': every visible mesh but
        the lows that stand in for highs."""
        sources = list(group.highs) or None
        if self.request.options.group_occluders == "group":
            occluders = [] if sources else [o for o in group.lows if o != low]
        else:
            stand_ins = {o for g in self.request.groups if g.highs for o in g.lows}
            occluders = [o for o in bpy.context.view_layer.objects if o.type == 'MESH' and o.visible_get()
                         and o not in stand_ins and o != low and o not in (sources or ())]
        return BakeUnit(TEXTURE_SET_NAME if self.request.options.texture_set else low.name, [low], sources, occluders)

    def _high_to_low(self, low, depsgraph, high_poly: list) -> HighToLow:
        """The Selected-to-Active request of the low-poly: its sources (high_poly) with their
        shading, the normals Blender extrudes along, the cage's evaluated corners."""
        req = self.request
        sources = [mesh_data.evaluated_soup(o, depsgraph, None, shading_normals=req.settings.normals == "mesh",
                                            alpha=req.settings.alpha != "off", alpha_size=req.settings.size)
                   for o in high_poly]
        normals, linear = mesh_data.extrusion_normals(low, depsgraph)
        cage = None
        if req.cage is not None:
            cage = mesh_data.evaluated_soup(req.cage, depsgraph, None, shading_normals=False).positions
        return HighToLow(sources, normals, cage, req.cage.name if req.cage is not None else "cage", linear)

    # -- running ---------------------------------------------------------------------------
    def steps(self) -> Generator[tuple[float, str], None, None]:
        """Yield (fraction done, status text) after each light direction."""
        req = self.request
        uv_names = {}
        for obj in req.targets:  # a colour attribute needs no UV map
            uv_names[obj.name] = "" if req.to_color_attribute else (yield from self._uv_name_for(obj))
        if not req.frames:
            yield from self._bake_frame(uv_names, 0.0, 1.0)
            self.finished = True
            return
        scene = bpy.context.scene
        original = scene.frame_current
        try:
            for k, frame in enumerate(req.frames):
                scene.frame_set(frame)
                t0 = time.perf_counter()
                self.results = []
                yield from self._bake_frame(uv_names, k / len(req.frames), 1.0 / len(req.frames), frame)
                outputs = self._write_frame(frame)
                self.frame_results.append(dict(frame=frame, seconds=round(time.perf_counter() - t0, 4),
                                               reused=all(r.stats.get("cache_hit") for _o, _u, r in self.results),
                                               outputs=outputs))
                self._clear_maps()
        finally:  # also when cancelled: the scene goes back to its frame
            scene.frame_set(original)
        self.finished = True

    def _bake_frame(self, uv_names: dict, start: float, share: float, frame: int | None = None
                    ) -> Generator[tuple[float, str], None, None]:
        """Bake every target at the scene's current frame into self.results (and self.maps);
        progress runs from start over share of the bar."""
        req = self.request
        depsgraph = self._depsgraph_getter()
        units = self.units()
        if req.groups is not None and req.options.texture_set:  # islands of different lows must not overlap
            texture_set_target([mesh_data.evaluated_soup(u.objects[0], depsgraph, uv_names[u.objects[0].name] or None,
                                                         shading_normals=False) for u in units],
                               req.settings.size, TEXTURE_SET_NAME)
        at = "" if frame is None else f" at frame {frame}"
        for k, unit in enumerate(units):
            objects, label = unit.objects, unit.label
            obj = objects[0]
            parts = [mesh_data.evaluated_soup(o, depsgraph, uv_names[o.name] or None,
                                              shading_normals=req.settings.normals == "mesh") for o in objects]
            soup = texture_set_target(parts, req.settings.size, label) if req.options.texture_set else parts[0]
            corners = None
            if req.to_color_attribute:
                corners = mesh_data.color_attribute_target(obj, depsgraph, req.settings.color_domain)
            high_to_low = self._high_to_low(obj, depsgraph, unit.sources) if unit.sources is not None else None
            target = BakeTarget.of(soup, req.settings.target, high_to_low, corners)
            alpha = req.settings.alpha != "off"
            occluders = [mesh_data.evaluated_soup(o, depsgraph, None, shading_normals=False, alpha=alpha,
                                                  alpha_size=req.settings.size) for o in unit.occluders]
            alpha_notes = sorted({note for o in occluders if o.alpha is not None for note in o.alpha.notes})
            settings = terminator_settings(req.settings, unit.sources or objects)
            key = None
            if frame is not None:
                key = (label, bake_key(target, occluders, settings))
                if key in self._frame_bakes:  # the geometry of an earlier frame: its files are copied
                    earlier, stats, tiles = self._frame_bakes[key]
                    self._copies[label] = earlier
                    stub = BakeResult(None, None, None, {**stats, "cache_hit": True}, None, tiles)
                    self.results.extend((o, uv_names[o.name], stub) for o in objects)
                    yield start + share * (k + 1) / len(units), f"Reusing frame {earlier} for '{label}'{at}"
                    continue
            # A sequence bakes past the shared cache: it would hold up to its size in maps.
            # (relay closes it on cancel: bake_steps' finally frees the GPU pass now.)
            result = yield from relay(bake_steps(target, occluders, settings, use_cache=frame is None),
                                      lambda frac, k=k, label=label, at=at: (
                                          start + share * (k + frac) / len(units),
                                          f"Baking AO of '{label}'{at} ({k + 1}/{len(units)}): {frac * 100:.0f}%"))
            if req.options.verify:
                check = yield from _with_status(verify_steps(target, occluders, settings, result, req.options.verify),
                                                start + share * (k + 1) / len(units),
                                                f"Verifying '{label}'{at} against the reference")
                if check is not None:
                    result = replace(result, stats={**result.stats, "verify": check.as_dict()})
                    self.verifications.append((label, check))
            if settings.thickness:
                steps = thickness_steps(soup, settings, use_cache=frame is None)
                thick = yield from _with_status(steps, start + share * (k + 1) / len(units),
                                                f"Baking thickness of '{label}'{at}")
                self.maps["thickness"][label] = thick.ao
            if req.map_path("orm"):
                self.maps["orm"][label] = self._orm_image(obj, depsgraph, soup, result)
            if settings.bent_normals:
                self.maps["bent"][label] = self._bent_image(objects, depsgraph, [uv_names[o.name] for o in objects],
                                                           soup, result)
            if alpha_notes:
                result = replace(result, stats={**result.stats,
                                                "warnings": [*result.stats.get("warnings", []), *alpha_notes]})
            # A texture set's objects share one result (commit writes it once).
            self.results.extend((o, uv_names[o.name], result) for o in objects)
            if key is not None:
                self._frame_bakes[key] = (frame, dict(result.stats), result.tiles)
        if req.groups is not None and req.options.texture_set:
            self._merge_group_set()

    def _merge_group_set(self) -> None:
        """Bake groups in one texture set: each low-poly was baked from its own group (a result
        each); their islands, which do not overlap, make one map, each texel from the result
        that fills it (the first where margins meet)."""
        results = [result for _o, _uv, result in self.results]
        first = results[0]
        ao, covered, filled = first.ao.copy(), first.covered.copy(), first.filled.copy()
        twin = None if any(r.twin is None for r in results) else first.twin.copy()
        for result in results[1:]:
            new = result.filled & ~filled
            ao[new] = result.ao[new]
            if twin is not None:
                twin[new] = result.twin[new]
            covered |= result.covered
            filled |= result.filled
        error = None if twin is None else estimate(twin, covered, max(r.error.directions for r in results))
        stats = {**first.stats, "covered_texels": int(covered.sum()), "error": error and error.as_dict(),
                 "warnings": [w for r in results for w in r.stats.get("warnings", [])]}
        merged = BakeResult(ao, covered, filled, stats, None, first.tiles, twin, error)
        self.own_stats = {obj.name: result.stats for obj, _uv, result in self.results}
        self.results = [(obj, uv, merged) for obj, uv, _r in self.results]

    def _orm_image(self, obj, depsgraph, target: TriangleSoup, result: BakeResult) -> np.ndarray:
        """(size, size, 4) ORM texture of a finished bake: its AO, the object's roughness and
        metallic in the baked UV layout (blender/material_channels.py)."""
        if result.tiles:
            raise BakeInputError("the ORM texture is a glTF texture, and glTF has no UDIM tiles: these UVs lie on "
                                 "several; bake without --orm-out")
        settings = self.request.settings
        roughness, metallic = roughness_metallic(obj, depsgraph, target.uvs, settings.size, settings.margin)
        return orm_image(result.ao, roughness, metallic)

    def _bent_image(self, objects: list, depsgraph, uv_names: list[str], target: TriangleSoup,
                    result: BakeResult):
        """(size, size, 4) encoded bent-normal image of a finished bake of objects (one, or a
        texture set's, whose target is their soups in that order), in the request's space."""
        req = self.request
        linear = np.array(objects[0].evaluated_get(depsgraph).matrix_world, dtype=np.float64)[:3, :3]
        tangents = normals = None
        if req.options.bent_space == "tangent":
            tangents = np.concatenate([mesh_data.corner_tangents(o, depsgraph, uv)
                                       for o, uv in zip(objects, uv_names)])
            # The world corner normals as they are (not re-normalized: on a scaled object that
            # would turn the decoded direction, 4 degrees on tests/test_bent_normals' sphere).
            normals = target.normals
            if normals is None:  # flat shading: every corner has its face's normal
                normals = np.repeat(face_normals_areas(target.positions)[0][:, None, :], 3, axis=1)
        if result.tiles is None:
            return bent_normal_map(result.bent_normals, result.covered, result.filled, req.settings.margin,
                                   target.uvs, req.options.bent_space, req.options.bent_convention, linear, tangents, normals)
        layout = udim_layout(target.uvs)  # one map per tile, from the tile's own triangles
        maps = []
        for tile in range(layout.count):
            faces, local = layout.local_uvs(target.uvs, tile)
            maps.append(bent_normal_map(result.bent_normals[tile], result.covered[tile], result.filled[tile],
                                        req.settings.margin, local, req.options.bent_space, req.options.bent_convention, linear,
                                        None if tangents is None else tangents[faces],
                                        None if normals is None else normals[faces]))
        return np.stack(maps)

    def run(self) -> None:
        for _ in self.steps():
            pass

    # -- ending ----------------------------------------------------------------------------
    def commit(self, hold: bool = False) -> list:
        """Write files (all or none), then images and material nodes (or the colour
        attributes). Returns the images. hold: keep what the files replaced until release()
        (cancel() puts it back), for a caller with more to write after."""
        if not self.finished:
            raise RuntimeError("commit() before the bake finished")
        req = self.request
        if req.to_color_attribute:
            for obj, _uv, result in self.results:
                color_attributes.store_color_attribute(obj.data, result.ao, req.settings.color_domain)
            return self.committed
        if req.frames:  # each frame's files were written when it finished
            return self.committed
        staged = self._stage_files()
        try:
            self.written += staged.commit()
            self._store_images()
        except BaseException:
            staged.rollback()
            self.written.clear()
            self.files.clear()
            raise
        if hold:
            self._staged = staged
        else:
            staged.release()
        return self.committed

    def written_note(self) -> str:
        """A sequence stopped part-way: its finished frames in words ('frames 1 to 30 (30 frames,
        30 files) are written'), '' when none."""
        done = [e["frame"] for e in self.frame_results]
        if not done:
            return ""
        count = sum(len(e["outputs"]) for e in self.frame_results)
        files = f"{count} file{'s' if count != 1 else ''}"
        if len(done) == 1:
            return f"frame {done[0]} ({files}) is written"
        return f"frames {done[0]} to {done[-1]} ({len(done)} frames, {files}) are written"

    def release(self) -> None:
        """After commit(hold=True): keep the files (drop the backups of those they replaced)."""
        if self._staged is not None:
            self._staged.release()
            self._staged = None

    def _stage_files(self, frame: int | None = None) -> StagedFiles:
        """Every map of self.results (and self.maps) staged beside its file, one per
        UDIM tile, after the collision check of the files as they turned out (tiles known);
        self.files lists them by (label, kind)."""
        req = self.request
        tiles = {label: result.tiles for _obj, label, result in self.baked() if result.tiles}
        if tiles:
            check_output_files(planned_files(replace(req, frames=None if frame is None else [frame]), tiles)
                               + list(req.claimed), input_files(req))
        staged = StagedFiles()
        try:
            for obj, label, result in self.baked():
                for kind, filepath, _what, _channels in output_kinds(req):
                    path = output_path_for(req, obj, filepath, frame)
                    if not path:
                        continue
                    paths = _tile_paths(path, result.tiles)
                    if label in self._copies:  # a repeated frame: the earlier frame's files, byte for byte
                        earlier = output_path_for(req, obj, filepath, self._copies[label])
                        for file_path, source in zip(paths, _tile_paths(earlier, result.tiles)):
                            staged.write_bytes(file_path, Path(source).read_bytes())
                    else:
                        maps = self._map_of(kind, label, result)
                        if maps is None:
                            continue
                        for file_path, tile_map in zip(paths, [maps] if result.tiles is None else maps):
                            staged.write_image(file_path, tile_map, req.file_text, req.options.png_bit_depth,
                                               req.options.dither)
                    self.files.setdefault((label, kind), []).extend(paths)
        except BaseException:
            staged.discard()
            raise
        return staged

    def _map_of(self, key: str, label: str, result: BakeResult) -> np.ndarray | None:
        """The map `key` of one label's finished bake: the AO and the error map from its result,
        the others as the job made them (self.maps); None where it was not made."""
        if key == "ao":
            return result.ao
        if key == "error":
            return result.error_map()
        return self.maps[key].get(label)

    def _clear_maps(self) -> None:
        for made in self.maps.values():
            made.clear()

    def _write_frame(self, frame: int) -> list[str]:
        """Write the finished frame's files (all or none); returns them."""
        staged = self._stage_files(frame)
        self._copies.clear()
        paths = staged.commit()
        staged.release()
        self.written += paths
        return paths

    def _store_images(self) -> None:
        """Image datablocks (loaded from the files where tiled), the baked-map property and
        material nodes of self.results."""
        req = self.request
        files = self.files
        stored, extra = {}, {}
        for _obj, label, result in self.baked():
            name = req.image_name or f"{label}_AO"
            # Re-baking updates the object's AO image in place (materials keep pointing at it).
            existing = req.image or bpy.data.images.get(name)
            stored[label] = self._store_image(result.ao, result.tiles, name, existing, files.get((label, "ao")))
            self.committed.append(stored[label])
            for kind in EXTRA_MAPS:
                if kind.image_suffix and label in self.maps.get(kind.key, {}):
                    name = f"{label}_{kind.image_suffix}"
                    extra[label, kind.key] = self._store_image(self.maps[kind.key][label], result.tiles, name,
                                                               bpy.data.images.get(name), files.get((label, kind.key)))
                    self.committed.append(extra[label, kind.key])
        for obj, uv_name, _result in self.results:
            image = stored[self.label_of(obj)]
            obj[BAKED_AO_PROPERTY] = image.name  # viewport HAO can skip objects with a baked map
            if req.wire_material:
                images.wire_into_material(obj, image, uv_name)
                if (self.label_of(obj), "orm") in extra:  # glTF's ORM texture in place of the AO's
                    images.wire_orm(obj, extra[self.label_of(obj), "orm"], uv_name)

    def summary(self) -> list[dict]:
        """One entry per baked object of the last bake (the --json report's objects): its
        triangles, UV map (and whether the job made it), covered texels, the method, shaded
        corners, and where they apply missed texels (Selected to Active), UDIM tiles, the
        texture set it joined; its estimated error (core/bake/error_estimate.py: rmse, p99,
        directions, capped; None with a single direction)."""
        out = []
        for obj, uv_name, result in self.results:
            st = self.own_stats.get(obj.name, result.stats)
            out.append(dict(name=obj.name, triangles=st["target_faces"], uv_map=uv_name,
                            uv_map_created=any(n == uv_name for _m, n in self.created_uv),
                            covered_texels=st["covered_texels"], method=st["method"],
                            smooth_corners=st["smooth_corners"],
                            **({"texture_set": True} if self.request.options.texture_set else {}),
                            **({"missed_texels": st["missed_texels"]} if "missed_texels" in st else {}),
                            **({"udim_tiles": list(result.tiles)} if result.tiles else {}),
                            error=st.get("error"), **({"verify": st["verify"]} if "verify" in st else {})))
        return out

    def label_of(self, obj) -> str:
        """The name a target's outputs carry: its own, or the texture set's."""
        return TEXTURE_SET_NAME if self.request.options.texture_set else obj.name

    def baked(self, results: list | None = None) -> list:
        """(first object, label, result) of each bake of results (default self.results, the
        last frame's in a sequence; a texture set's objects share one result)."""
        seen, out = set(), []
        for obj, _uv, result in self.results if results is None else results:
            if id(result) not in seen:
                seen.add(id(result))
                out.append((obj, self.label_of(obj), result))
        return out

    @staticmethod
    def _store_image(maps: np.ndarray, tiles: tuple[int, ...] | None, name: str, existing, tile_files):
        if tiles is None:
            return images.store_map_image(maps, name, existing)
        return images.store_tiled_image(maps, tiles, name, existing, tile_files)

    def cancel(self) -> None:
        """Undo the only early change, UV maps this job created, and the files of a held
        commit (a sequence's finished frames stay: they are complete, and listed in written)."""
        if self._staged is not None:
            self._staged.rollback()
            self._staged = None
            self.written.clear()
        for mesh, name in reversed(self.created_uv):
            layer = mesh.uv_layers.get(name)
            if layer is not None:
                mesh.uv_layers.remove(layer)
        self.created_uv.clear()
        self.results.clear()
        self._clear_maps()
