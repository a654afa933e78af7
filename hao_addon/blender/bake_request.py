# SPDX-License-Identifier: GPL-3.0-or-later
"""What a bake job is asked to do (BakeRequest), checked before anything is made
(validate_request), and the files it reads and writes: each map's path per object, frame and
UDIM tile (output_path_for, planned_files), which are already finished (finished_files, for
--skip-existing) and what it reads (input_files). The job itself: bake_job.py."""
from __future__ import annotations

import glob
import os
from dataclasses import dataclass, field, replace

import bpy

from .. import compat
from ..core.bake.job_options import JobOptions
from ..core.bake.map_kinds import EXTRA_MAPS, MAP_KINDS
from ..core.bake.settings import BakeSettings
from ..core.bake.target_kinds import TargetKind, target_kind
from ..core.bake.udim import tile_path
from ..core.errors import BakeInputError
from ..core.file_checks import image_is_whole, output_is_whole
from ..core.imageio import BAKE_KEY, FORMATS, check_writable, read_text
from ..core.output_files import check_output_files, frame_file, with_token
from ..core.setting_spec import specs
from .paths import FRAME_TOKEN, OBJECT_TOKEN, absolute_path, example_path, object_file_name

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
    multiply_base_color: bool = False  # with wire_material: the AO also multiplies Base Color
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
    # Keep each map's bake in this session's memory for a later Re-bake Changed (the panel's
    # bakes; blender/rebake_records.py).
    remember: bool = False

    @property
    def kind(self) -> TargetKind:
        """The targets' kind (core/bake/target_kinds.py), from the Target setting and Selected to
        Active (high-poly meshes, or bake groups with some): images of the UV layout, or (a
        colour attribute, hao_ao: blender/color_attributes.py) one value per mesh element,
        no UV map, image or file."""
        return target_kind(self.settings.target, self.high_poly is not None or any(g.highs for g in self.groups or ()))

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
    if not request.kind.writes_images:
        _validate_element_target(request)
    for obj in request.targets:
        if obj.type != 'MESH':
            raise BakeInputError(f"'{obj.name}' is not a mesh")
        if len(obj.data.polygons) == 0:
            raise BakeInputError(f"'{obj.name}' has no faces to bake")
        if not request.kind.needs_uvs:
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
    _validate_maps(request)
    size = request.settings.size
    for obj in file_owners(request):
        for _kind, filepath, _what, channels in output_kinds(request):
            path = output_path_for(request, obj, filepath)
            if path:
                check_writable(example_path(path, (request.frames or [0])[0]), size, size, channels,
                               source=request.source_path or None)
    check_output_files(planned_files(request) + list(request.claimed), input_files(request))


def tile_paths(path: str, tiles: tuple[int, ...] | None) -> list[str]:
    """The files of one map: path, or one per UDIM tile (tile_path)."""
    return [path] if tiles is None else [tile_path(path, t) for t in tiles]


def output_kinds(request: BakeRequest) -> tuple[tuple[str, str, str, int], ...]:
    """The image files a request writes per target: (kind, path pattern, what, channels)."""
    return tuple((kind.key, request.map_path(kind.key), kind.noun, kind.channels) for kind in MAP_KINDS)


def file_owners(request: BakeRequest) -> list:
    """The targets whose files are written: every target, or a texture set's first (shared)."""
    return request.targets[:1] if request.options.texture_set else request.targets


def planned_files(request: BakeRequest, tiles: dict | None = None) -> list[tuple[str, str]]:
    """Every file the request writes, as (path, what): each target's maps and bent normals
    (each frame's, each UDIM tile's where tiles {label: tile numbers} is given), then the
    caller's extra_outputs."""
    out = []
    for obj in file_owners(request):
        label = TEXTURE_SET_NAME if request.options.texture_set else obj.name
        for _kind, filepath, what, _channels in output_kinds(request):
            if not filepath:
                continue
            for frame in request.frames or [None]:
                path = output_path_for(request, obj, filepath, frame)
                at = "" if frame is None else f" at frame {frame}"
                numbers = (tiles or {}).get(label)
                out += [(tile, f"{what} of '{label}'{f' tile {t}' if numbers else ''}{at}")
                        for tile, t in zip(tile_paths(path, numbers), numbers or [None])]
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


def _validate_maps(request: BakeRequest) -> None:
    """Each map asked for (its file, or its setting) by a kind of target that can make it (the
    map rows' target_kinds, core/bake/map_kinds.py), and each file with the setting it needs on."""
    unknown = sorted(set(request.map_paths) - {kind.key for kind in EXTRA_MAPS})
    if unknown:
        raise BakeInputError(f"no map '{unknown[0]}' to write: the maps are {', '.join(k.key for k in EXTRA_MAPS)}")
    labels = {f.name: spec.label for f, spec in specs(BakeSettings)}
    for row in MAP_KINDS:
        if row.setting and request.map_path(row.key) and not getattr(request.settings, row.setting):
            raise BakeInputError(f"{row.panel_label} ({row.noun}) needs the {labels[row.setting]} setting on")
    for row in MAP_KINDS:
        asked = request.map_path(row.key) or (row.setting and getattr(request.settings, row.setting))
        if asked and request.kind.name not in row.target_kinds:
            raise BakeInputError(row.refusal)
    if request.map_path("orm") and request.options.texture_set:
        raise BakeInputError("the ORM texture packs one object's AO with its material (not a texture set)")


def _validate_frames(request: BakeRequest) -> None:
    if not request.frames:
        raise BakeInputError("a frame sequence needs at least one frame")
    if not request.kind.writes_images:
        raise BakeInputError("a colour attribute holds one frame: bake a frame sequence into image files")
    if not request.filepath:
        raise BakeInputError("a frame sequence writes one file per frame: set Save To (a path with {frame})")


def _validate_texture_set(request: BakeRequest) -> None:
    if request.high_poly is not None or not request.kind.writes_images:
        raise BakeInputError("a texture set bakes the objects' own surfaces into one image: not with a colour "
                             "attribute or Selected to Active")
    for obj in request.targets:
        if obj.type == 'MESH' and not obj.data.uv_layers:
            raise BakeInputError(f"'{obj.name}' has no UV map: a texture set bakes each object's own UVs into one "
                                 f"image, so lay out its islands beside the other objects' first")
    if request.settings.bent_normals and request.options.bent_space == "object":
        raise BakeInputError("object-space bent normals of a texture set would mix the objects' spaces: use "
                             "tangent space")


def _validate_element_target(request: BakeRequest) -> None:
    """A target kind of one value per mesh element (a colour attribute): the mesh's own
    surface, and no image or file."""
    if request.high_poly is not None:
        raise BakeInputError("a colour attribute holds the AO of the mesh's own surface: Selected to Active bakes "
                             "into images (Target: Image Textures)")
    if request.filepath or request.image is not None:
        raise BakeInputError("a colour-attribute bake writes no image: clear the image and the file path, or "
                             "bake to Image Textures")


def _validate_groups(request: BakeRequest) -> None:
    if request.high_poly is not None or request.cage is not None:
        raise BakeInputError("bake groups find their high-poly meshes by name: no separate high-poly or cage")
    if not request.kind.writes_images:
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
