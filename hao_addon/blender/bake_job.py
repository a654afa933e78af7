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

import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Generator

import bpy
import numpy as np

from ..bake import BakeResult, bake_key, bake_steps, thickness_steps
from ..core.steps import relay
from ..core.bake.error_estimate import estimate
from ..verify import verify_steps
from ..core.imageio import StagedFiles
from ..core.output_files import check_output_files
from ..core.bake.projection import HighToLow
from ..core.bake.scene_changes import SceneState
from ..core.bake.settings import BakeSettings
from ..core.bake.map_kinds import EXTRA_MAPS
from ..core.bake.targets import BakeTarget
from ..core.bake.texture_set import texture_set_target
from . import color_attributes, images, mesh_data
from .bake_request import (TEXTURE_SET_NAME, BakeGroup, BakeRequest, input_files, output_kinds, output_path_for,
                           planned_files, terminator_settings, tile_paths, validate_request)
from .map_producers import bent_normal_image, orm_map, surface_maps
from .rebake_records import keeps_records, recorded_steps, remember_records, stage_records
from .auto_uv import unwrapped_steps
from .instances import instanced_soups
from .visibility import rendered_meshes
from .job_summary import job_summary
from .view_scene import BAKED_AO_PROPERTY

@dataclass
class BakeUnit:
    """One bake of a job: the objects baked together (one, or a texture set's), the label
    its image and files are named after, the Selected-to-Active sources (None: the objects'
    own surface), the other meshes that occlude, and whether the scene's mesh instances
    occlude too (blender/instances.py: with every visible mesh)."""

    label: str
    objects: list
    sources: list | None
    occluders: list
    instanced: bool = False


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
        self.maps: dict[str, dict[str, np.ndarray]] = {kind.key: {} for kind in EXTRA_MAPS}
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
        # Each label's (map path, bake, scene state) for Re-bake Changed (_recorded_steps):
        # remembered or written beside the map at commit.
        self.records: dict[str, tuple[str, BakeResult, SceneState]] = {}
        self.finished = False
        self.unwrap_seconds = 0.0
        self.unwrap_notes: list[str] = []  # which unwraps fell back to xatlas' own charts (auto_uv.py)

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
        t0 = time.perf_counter()  # the maps it adds are removed again if the bake fails
        unwrap = unwrapped_steps(obj, self.request.settings.size, self.created_uv)
        new_name, note = yield from relay(unwrap, lambda step: (0.0, step[1]))
        self.unwrap_seconds += time.perf_counter() - t0
        self.unwrap_notes += [note] if note else []
        return new_name

    def _occluder_objects(self, target) -> list:
        mode = self.request.options.occluders
        if mode == "target":
            candidates = []
        elif mode == "selected":
            candidates = [o for o in self.request.targets if o != target]
            candidates += [o for o in bpy.context.selected_objects if o.type == 'MESH' and o not in candidates]
        else:
            candidates = rendered_meshes(bpy.context.view_layer, bpy.context.scene)
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
        every = req.options.occluders == "visible"
        if req.options.texture_set:
            objects = list(req.targets)
            return [BakeUnit(TEXTURE_SET_NAME, objects, None,
                             [o for o in self._occluder_objects(objects[0]) if o not in skip | set(objects)], every)]
        return [BakeUnit(obj.name, [obj], req.high_poly, [o for o in self._occluder_objects(obj) if o not in skip],
                         every) for obj in req.targets]

    def _group_unit(self, group: BakeGroup, low) -> BakeUnit:
        """A low-poly of a bake group. 'group': its own group occludes (the highs, which are
        the sources; or, without highs, the group's other lows). 'all': every visible mesh but
        the lows that stand in for highs."""
        sources = list(group.highs) or None
        if self.request.options.group_occluders == "group":
            occluders = [] if sources else [o for o in group.lows if o != low]
        else:
            stand_ins = {o for g in self.request.groups if g.highs for o in g.lows}
            occluders = [o for o in rendered_meshes(bpy.context.view_layer, bpy.context.scene)
                         if o not in stand_ins and o != low and o not in (sources or ())]
        return BakeUnit(TEXTURE_SET_NAME if self.request.options.texture_set else low.name, [low], sources, occluders,
                        self.request.options.group_occluders == "all")

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
            uv_names[obj.name] = (yield from self._uv_name_for(obj)) if req.kind.needs_uvs else ""
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
        for k, unit in enumerate(units):
            span = (start + share * k / len(units), share / len(units))
            yield from self._bake_unit(unit, uv_names, depsgraph, span, frame, f"({k + 1}/{len(units)})")
        if req.groups is not None and req.options.texture_set:
            self._merge_group_set()

    def _unit_inputs(self, unit: BakeUnit, uv_names: dict, depsgraph) -> tuple:
        """(the unit's target soup, its BakeTarget, the occluders, their alpha notes, the
        settings with the objects' terminator) at the scene's current frame."""
        req = self.request
        parts = [mesh_data.evaluated_soup(o, depsgraph, uv_names[o.name] or None,
                                          shading_normals=req.settings.normals == "mesh") for o in unit.objects]
        soup = texture_set_target(parts, req.settings.size, unit.label) if req.options.texture_set else parts[0]
        corners = None
        if not req.kind.writes_images:  # one value per mesh element: its vertices or face corners
            corners = mesh_data.color_attribute_target(unit.objects[0], depsgraph, req.settings.color_domain)
        high_to_low = self._high_to_low(unit.objects[0], depsgraph, unit.sources) if unit.sources is not None else None
        target = BakeTarget.of(soup, req.settings.target, high_to_low, corners)
        alpha = req.settings.alpha != "off"
        occluders = [mesh_data.evaluated_soup(o, depsgraph, None, shading_normals=False, alpha=alpha,
                                              alpha_size=req.settings.size) for o in unit.occluders]
        occluders += instanced_soups(depsgraph, alpha, req.settings.size) if unit.instanced else []
        alpha_notes = sorted({note for o in occluders if o.alpha is not None for note in o.alpha.notes})
        return soup, target, occluders, alpha_notes, terminator_settings(req.settings, unit.sources or unit.objects)

    def _bake_unit(self, unit: BakeUnit, uv_names: dict, depsgraph, span: tuple[float, float], frame: int | None,
                   count: str) -> Generator[tuple[float, str], None, None]:
        """Bake one unit into self.results (and self.maps); progress over span (start, share)."""
        objects, label = unit.objects, unit.label
        start, share = span
        at = "" if frame is None else f" at frame {frame}"
        soup, target, occluders, alpha_notes, settings = self._unit_inputs(unit, uv_names, depsgraph)
        key = None
        if frame is not None:
            key = (label, bake_key(target, occluders, settings))
            if key in self._frame_bakes:  # the geometry of an earlier frame: its files are copied
                earlier, stats, tiles = self._frame_bakes[key]
                self._copies[label] = earlier
                stub = BakeResult(None, None, None, {**stats, "cache_hit": True}, None, tiles)
                self.results.extend((o, uv_names[o.name], stub) for o in objects)
                yield start + share, f"Reusing frame {earlier} for '{label}'{at}"
                return
        # A sequence bakes past the shared cache: it would hold up to its size in maps.
        # (relay closes it on cancel: bake_steps' finally frees the GPU pass now.)
        steps = bake_steps(target, occluders, settings, use_cache=frame is None)
        if keeps_records(self.request, frame):  # re-bakes only what changed, or keeps its state for that
            steps = recorded_steps(self.request, unit, target, occluders, settings, self.records)
        result = yield from relay(steps, lambda frac: (start + share * frac,
                                                       f"Baking AO of '{label}'{at} {count}: {frac * 100:.0f}%"))
        result = yield from self._verified(result, target, occluders, settings, label, start + share, at)
        yield from self._make_maps(unit, uv_names, depsgraph, soup, settings, result, start + share, frame)
        result = replace(result, stats={**result.stats, "instanced_occluders": len(occluders) - len(unit.occluders),
                                        "warnings": [*result.stats.get("warnings", []), *alpha_notes]})
        # A texture set's objects share one result (commit writes it once).
        self.results.extend((o, uv_names[o.name], result) for o in objects)
        if key is not None:
            self._frame_bakes[key] = (frame, dict(result.stats), result.tiles)

    def _verified(self, result: BakeResult, target, occluders: list, settings: BakeSettings, label: str,
                  fraction: float, at: str) -> Generator[tuple[float, str], None, BakeResult]:
        """--verify: the result with its check against the reference (self.verifications)."""
        if not self.request.options.verify:
            return result
        check = yield from _with_status(verify_steps(target, occluders, settings, result, self.request.options.verify),
                                        fraction, f"Verifying '{label}'{at} against the reference")
        if check is None:
            return result
        self.verifications.append((label, check))
        return replace(result, stats={**result.stats, "verify": check.as_dict()})

    def _make_maps(self, unit: BakeUnit, uv_names: dict, depsgraph, soup, settings: BakeSettings,
                   result: BakeResult, fraction: float, frame: int | None) -> Generator[tuple[float, str], None, None]:
        """The maps besides the AO that the request asks for, into self.maps: thickness (a
        bake of its own), the ORM texture and the bent normals (blender/map_producers.py)."""
        req, label = self.request, unit.label
        at = "" if frame is None else f" at frame {frame}"
        if settings.thickness:
            steps = thickness_steps(soup, settings, use_cache=frame is None)
            thick = yield from _with_status(steps, fraction, f"Baking thickness of '{label}'{at}")
            self.maps["thickness"][label] = thick.ao
        if req.map_path("orm"):
            self.maps["orm"][label] = orm_map(req, unit.objects[0], depsgraph, soup, result)
        if settings.bent_normals:
            self.maps["bent"][label] = bent_normal_image(req, unit.objects, depsgraph,
                                                         [uv_names[o.name] for o in unit.objects], soup, result)
        for key, made in surface_maps(req, soup, result.tiles).items():  # curvature, cavity
            self.maps[key][label] = made

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
        merged = BakeResult(ao, covered, filled, stats, None, first.tiles, twin, error, first.method)
        self.own_stats = {obj.name: result.stats for obj, _uv, result in self.results}
        self.results = [(obj, uv, merged) for obj, uv, _r in self.results]

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
        if not req.kind.writes_images:
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
        remember_records(req, self.records)
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
                    paths = tile_paths(path, result.tiles)
                    if label in self._copies:  # a repeated frame: the earlier frame's files, byte for byte
                        earlier = output_path_for(req, obj, filepath, self._copies[label])
                        for file_path, source in zip(paths, tile_paths(earlier, result.tiles)):
                            staged.write_bytes(file_path, Path(source).read_bytes())
                    else:
                        maps = self._map_of(kind, label, result)
                        if maps is None:
                            continue
                        for file_path, tile_map in zip(paths, [maps] if result.tiles is None else maps):
                            staged.write_image(file_path, tile_map, req.file_text, req.options.png_bit_depth,
                                               req.options.dither)
                    self.files.setdefault((label, kind), []).extend(paths)
            stage_records(staged, req, self.records)
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
                images.wire_into_material(obj, image, uv_name, req.multiply_base_color)
                if (self.label_of(obj), "orm") in extra:  # glTF's ORM texture in place of the AO's
                    images.wire_orm(obj, extra[self.label_of(obj), "orm"], uv_name)

    def summary(self) -> list[dict]:
        """One entry per baked object of the last bake (the --json report's objects: job_summary.py)."""
        return job_summary(self)

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
