# SPDX-License-Identifier: GPL-3.0-or-later
"""CPU-side preparation of a bake, shared by both GPU bake variants (pure numpy).

Validates the input, normalizes coordinates (float64 -> float32 near [-1, 1]), computes face
normals and exact normalizers, culls occluders that cannot matter, and chooses the light-view
pixel size from the texel density of the UV layout.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable, Generator

import numpy as np

from ..directions import class_directions
from ..errors import BakeInputError
from ..geometry import (TriangleSoup, bounding_sphere, column_bounds, face_normals_areas, surface_holes,
                        unusable_normal_warnings, uv_areas, weld)
from .abilities import abilities_needed, check_method, choose_method, declaration
from .alpha import DrawnAlpha, drawn_alpha
from .estimators import AMBIENT_OCCLUSION, BENT_NORMALS, Estimator
from .interleave import class_pixel_scale, classes_for, texel_classes
from .plan_weights import inverse_normalizers, shading_corners
from ..steps import drain
from .projection import HighToLow, RayCast, check_high_to_low
from .receivers import Receivers, faces_touching
from .bake_run import BakeRun
from .settings import BakeSettings
from .target_layouts import LAYOUTS, TexelLayout
from .uv_checks import tile_layout_warnings
from .udim import UdimLayout, udim_layout
from .target_kinds import TARGET_KINDS, TargetKind
from .targets import BakeTarget, as_bake_target
from .vertex_target import VertexTarget
from .view_size import DENSE_AREA_LIMIT, light_pixel_size
from .views import OrthoView, fit_views, pixel_jitter


@dataclass
class BakePlan:
    """Everything the bakers read of one bake, made by make_plan_steps (built by keyword)."""

    settings: BakeSettings
    # What this run bakes beside the settings (core/bake/bake_run.py): its directions' count
    # and seed, the cells, whether AO alone.
    run: BakeRun
    # The target kind's part (core/bake/target_layouts.py): its receivers, the shape of its
    # output and how sums become it.
    layout: TexelLayout
    # The bake method that runs: chosen once, here (abilities.choose_method of what the bake
    # needs), and carried forward by the baker factory and the result (BakeResult.method).
    method: str
    centre: np.ndarray            # (3,) float64, world
    scale: float                  # world units per normalized unit
    target_positions: np.ndarray  # (Ft, 3, 3) float32 normalized
    target_uvs: np.ndarray        # (Ft, 3, 2) float32
    target_faces: np.ndarray      # (Ft, 4) float32: unit face normal, 1 / S_f (0 if never lit)
    # (Ft, 3, 4) float32: the unit shading normal n_s at each corner and 1 / S at it, S the
    # exact normalizer of n_s (0 on faces never lit); face normal and 1 / S_f on flat faces.
    target_corners: np.ndarray
    # (Ft, 3) float32: the part of each corner's S that lies above its face (directions the
    # true surface can see), as a fraction; 1 on flat faces. See plan_weights.shading_corners.
    target_above: np.ndarray
    occluder_positions: np.ndarray  # (Fo, 3, 3) float32 normalized
    occluder_normals: np.ndarray    # (Fo, 3) float32
    directions: np.ndarray        # (D, 3) float64: every texel class's (core/bake/interleave.py)
    pixel_size: float             # light-view pixel side, normalized units
    max_view_side: int
    target_points: np.ndarray     # (n, 3) float64 normalized, for fitting views
    drawn_sphere: tuple[np.ndarray, float]  # normalized bounding sphere of everything drawn
    # A run of some cells (of a baker that bakes a subset): the target's faces that reach them
    # (k,) (receivers.faces_touching), and their corners (3k, 3) float64 normalized that each
    # view is cropped to (views.fit_views: the whole bake's pixel grid and depth range); None:
    # the whole views.
    window_faces: np.ndarray | None = None
    window_points: np.ndarray | None = None
    # (k, 4) float64 normalized spheres each view is cropped to instead (a re-bake by
    # difference, hao_addon/rebake_difference.py: only pixels an edit can change are drawn).
    window_spheres: np.ndarray | None = None
    # (drawn (F', 3, 3) float32 normalized, holes as `holes`) of the scene before an edit, for a
    # re-bake by difference (its views subtract: gpu_shaders/bake_gather.comp, DIFFERENCE).
    before_drawn: tuple | None = None
    needs_footprint_splat: bool = False
    # Some corner's shading normal differs from its face normal: the passes then weight by
    # the shading normal and handle the terminator (directions above the shading hemisphere
    # but below the face). False: every pass runs its flat-shading path.
    smooth_shading: bool = False
    closed_surfaces: bool = False  # everything drawn is closed and consistently oriented
    # Hole loops (k, 3) normalized of everything drawn when it bounds solids once capped
    # (core/geometry.surface_holes; [] when closed); None when not, or not needed (a max
    # distance or ignored back faces change what a depth map must hold).
    holes: list[np.ndarray] | None = None
    stats: dict = field(default_factory=dict)
    # What lets light through, per drawn face (core/bake/alpha.py), or None: all opaque.
    alpha: DrawnAlpha | None = None
    # (D,) int the texel class each direction serves (core/bake/interleave.py), and how many
    # classes there are (1: every direction serves every receiver).
    direction_class: np.ndarray | None = None
    classes: int = 1

    @property
    def kind(self) -> TargetKind:
        """The target's kind (core/bake/target_kinds.py): texels, corners or projected points."""
        return TARGET_KINDS[self.layout.KIND]

    @property
    def udim(self) -> UdimLayout | None:
        """The UDIM tiles of a tiled UV layout (core/bake/udim.py): one map per tile."""
        return self.layout.udim

    @property
    def cells(self) -> np.ndarray | None:
        """The output cells (flat indices into output_shape) still to bake, or None for all:
        the later rounds of a bake to an error leave converged texels out, a verification
        bakes its sample. Receivers elsewhere are dropped (bakers that can: abilities.bakes_all_cells)."""
        return self.run.cells

    def with_cells(self, cells: np.ndarray | None) -> "BakePlan":
        """This plan baking `cells` alone (None: all)."""
        return replace(self, run=self.run.with_cells(cells))

    @property
    def seed(self) -> int:
        """The run's seed: the light views' jitter, the passes' own random draws."""
        return self.run.seed

    @property
    def direction_count(self) -> int:
        """Directions drawn: those of every texel class."""
        return len(self.directions)

    @property
    def texel_directions(self) -> int:
        """Directions each receiver sees (the bake's Directions: direction_count over classes)."""
        return len(self.directions) // self.classes

    def receiver_classes(self, texels: np.ndarray) -> np.ndarray:
        """(n,) int the class of receivers at flat texels (n,) (all 0 without classes)."""
        if self.classes == 1:
            return np.zeros(len(texels), np.int64)
        return texel_classes(texels, self.settings.size)

    def receivers(self) -> Receivers:
        """The bake's receivers (its layout's: the projected high-poly points, the target's
        face corners, or the sample points of its own UV layout), those of `cells` alone
        where the run names them."""
        receivers = self.layout.receivers(self)
        return receivers if self.cells is None else receivers.subset(np.isin(receivers.texel, self.cells))

    @property
    def output_shape(self) -> tuple[int, ...]:
        """The shape of the bake's output elements: (size, size) texels, (tiles, size, size)
        of a UDIM layout, or (count,) vertices or corners of a colour-attribute target."""
        return self.layout.output_shape

    @property
    def abilities_needed(self) -> frozenset[str]:
        """What a baker must be able to bake for this plan (core/bake/abilities.py)."""
        needs = _needs(self.settings, self.run, self.kind, self.udim)
        return needs | {"alpha"} if self.alpha is not None else needs

    def check_method(self, method: str) -> None:
        """Refuse `method` if it cannot bake this plan (core/bake/abilities.py)."""
        check_method(method, self.abilities_needed, asked_phrases(self.udim))

    @property
    def estimator(self) -> Estimator:
        """What each direction adds to a receiver's sums (core/bake/estimators.py): ambient
        occlusion, with the bent normal's sums too where the settings ask for it."""
        return BENT_NORMALS if self.settings.bent_normals else AMBIENT_OCCLUSION

    @property
    def lifts_terminator(self) -> bool:
        """Whether ray starts near the terminator are lifted to the smooth surface (Cycles'
        geometry offset, core/bake/terminator.py): smooth shading with the offset on."""
        return self.smooth_shading and self.settings.terminator_offset > 0.0

    @property
    def target_drawn(self) -> bool:
        """Whether the target occludes (its kind's row: not in Selected to Active, as in Cycles)."""
        return self.kind.target_occludes

    @property
    def drawn_positions(self) -> np.ndarray:
        """(F, 3, 3) float32 normalized: every triangle the light views draw, target first."""
        if not self.target_drawn:
            return self.occluder_positions
        return np.concatenate([self.target_positions, self.occluder_positions])

    @property
    def drawn_normals(self) -> np.ndarray:
        """(F, 3) float32 face normals of drawn_positions."""
        if not self.target_drawn:
            return self.occluder_normals
        return np.concatenate([self.target_faces[:, :3], self.occluder_normals])

    @property
    def depth_map_culls_back_faces(self) -> bool:
        """Whether the scatter's depth pre-pass may draw one side of the faces only: when the
        user ignores back faces, and, with unlimited distance, when everything drawn is closed.
        The scatter then keeps the faces turned *away* from the light (its pre-pass culls
        'FRONT', front = facing the light): on closed surfaces the first averted face along a
        pixel's ray lies behind the first light-facing one and in front of whatever that hides,
        so each fragment's visibility, judged against the map at its own pixel, is unchanged,
        except where the ray leaves an occluder within the depth bias of the fragment (grazing
        just behind it), which the bias then lets through (tests/test_skip.py: 0 to 12 of 16k
        texels of a torus, each by at most one direction's term). With a max distance a face where a ray
        enters an occluder can lie within reach while its exit does not, so both stay. The
        gather uses `holes` instead (bake_gather.py)."""
        return self.settings.ignore_back_faces or (self.closed_surfaces and not self.layered)

    @property
    def layered(self) -> bool:
        """Whether the passes need every surface along a ray (per-pixel depth lists), not the
        nearest one: with a max distance, or a min distance that rays go on past."""
        return self.settings.max_distance > 0.0 or self.settings.min_distance > 0.0

    @property
    def max_distance_normalized(self) -> float:
        return self.settings.max_distance / self.scale

    @property
    def layered_reach(self) -> float:
        """The depth lists' max distance, normalized: the setting's, or 1e30 when unlimited."""
        return self.max_distance_normalized if self.settings.max_distance > 0.0 else 1e30

    @property
    def layered_falloff(self) -> str:
        """The depth lists' falloff (none where the distance is unlimited: falloff needs one)."""
        return self.settings.falloff if self.settings.max_distance > 0.0 else "none"

    @property
    def min_distance_normalized(self) -> float:
        return self.settings.min_distance / self.scale

    def view(self, index: int) -> OrthoView:
        """The light view of direction `index`, with a deterministic sub-pixel jitter."""
        return self.views([index])[0]

    def views(self, indices: list[int]) -> list[OrthoView]:
        """The light views of several directions, fitted together (the same views as view())."""
        omegas = self.directions[list(indices)]
        c, r = self.drawn_sphere
        reaches = [float(omega @ c) + r for omega in omegas]
        jitters = np.array([pixel_jitter(self.seed, i) for i in indices]).reshape(-1, 2)
        return fit_views(omegas, self.target_points, reaches, self.pixel_size, jitters, self.max_view_side,
                         self.window_points, self.window_spheres)


def _window_faces(target, settings: BakeSettings, run: BakeRun, layout: TexelLayout, method: str
                  ) -> np.ndarray | None:
    """(k,) the faces that reach a run of some texels of one UV tile (an incremental re-bake's
    cells): its light views are cropped to their corners, each then covering only their part
    of the whole bake's view (a ray from a receiver stays inside its window) and costing that
    part's pixels. None: the whole views (and for a baker that bakes every texel,
    abilities.bakes_all_cells)."""
    if (run.cells is None or declaration(method).bakes_all_cells or layout.KIND != TexelLayout.KIND
            or layout.udim is not None or target.uvs is None):
        return None
    faces = faces_touching(target.uvs, settings.size, run.cells)
    return faces if len(faces) else None


def asked_phrases(udim: UdimLayout | None) -> dict[str, str]:
    """How a refusal names this bake's abilities where more precise than their phrase."""
    return {} if udim is None else {"udim": f"UDIM tiles {', '.join(map(str, udim.tiles))}"}


def _check_finite(soup: TriangleSoup) -> None:
    if not np.isfinite(soup.positions).all():
        bad = int((~np.isfinite(soup.positions)).any(axis=(1, 2)).sum())
        raise BakeInputError(f"'{soup.name}' has {bad} triangles with NaN or infinite vertex positions")
    if soup.uvs is not None and not np.isfinite(soup.uvs).all():
        raise BakeInputError(f"'{soup.name}' has NaN or infinite UV coordinates")


def make_plan(target: TriangleSoup | BakeTarget, occluders: list[TriangleSoup], settings: BakeSettings,
              high_to_low: HighToLow | None = None, cast: RayCast | None = None,
              vertex_target: VertexTarget | None = None, run: BakeRun | None = None) -> BakePlan:
    """Prepare a bake of `target` (which must carry UVs) against itself plus `occluders`, or,
    with `high_to_low`, of its sources projected onto its UVs (Selected to Active: the sources
    and the occluders occlude, the target does not), its rays cast by `cast` (default the
    CPU's, projection.project_steps); or, with `vertex_target` (settings.target
    'color-attribute'), at its face corners, UVs not needed. target may be a BakeTarget
    (core/bake/targets.py) instead, which holds high_to_low or vertex_target itself. run: what
    this run bakes beside the settings (core/bake/bake_run.py; default BakeRun.of(settings))."""
    return drain(make_plan_steps(target, occluders, settings, high_to_low, cast, vertex_target, run=run))


def make_plan_steps(target: TriangleSoup | BakeTarget, occluders: list[TriangleSoup], settings: BakeSettings,
                    high_to_low: HighToLow | None = None, cast: RayCast | None = None,
                    vertex_target: VertexTarget | None = None, projection: tuple | None = None,
                    run: BakeRun | None = None, cast_for: Callable[[str], RayCast | None] | None = None
                    ) -> Generator[float, None, BakePlan]:
    """make_plan(), yielding the fraction of the Selected-to-Active projection done (nothing
    without high_to_low): its seconds of ray casting can be drawn and cancelled. projection:
    an earlier plan's (BakePlan.reusable) of the same target, sources and settings but for
    the run, used instead of casting again. cast_for: the chosen method's ray cast (cast,
    where not given)."""
    settings = settings.validated()
    run = BakeRun.of(settings) if run is None else run
    bake_target, occluders = _checked_inputs(target, occluders, settings, high_to_low, vertex_target)
    kind, target = bake_target.kind, bake_target.soup
    normals, areas = _face_normals_areas(target)
    uv_area, udim, uv_warnings, uv_counters = _uv_layout(target, kind, settings)
    method = _checked_method(settings, run, kind, udim)  # before the projection's rays
    if cast is None and cast_for is not None and bake_target.high_to_low is not None:
        cast = cast_for(method)
    centre, scale, t_pos = _normalized(target)
    # The kind's own steps (a Selected-to-Active projection casts its rays here).
    layout = yield from LAYOUTS[kind.name].made(bake_target, settings, udim, centre, scale, cast, projection)
    flat = np.concatenate([target.positions.reshape(-1, 3), layout.receiver_points() * scale + centre])
    o_pos, alpha_parts, culling = _drawn_occluders(occluders, flat, settings, kind, target, centre, scale)
    o_normals, _ = face_normals_areas(o_pos)
    alpha, sized_for = drawn_alpha(alpha_parts, settings.alpha, settings.alpha_clip), method
    method, classes, directions, direction_class = _method_directions(settings, run, kind, udim, layout, method, alpha)
    inv_s = inverse_normalizers(normals, areas, directions, settings)
    corners, above, smooth_corners = shading_corners(target, normals, inv_s, directions, settings)
    extent = layout.extent  # (over every projected point: once)
    pixel_size, dense_fraction = light_pixel_size(settings, kind, udim, areas, uv_area, scale, sized_for, extent)
    pixel_size *= class_pixel_scale(classes)

    drawn = np.concatenate(([t_pos.reshape(-1, 3)] if kind.target_occludes else []) + [o_pos.reshape(-1, 3)])
    target_weld = weld(t_pos.reshape(-1, 3))
    holes = _drawn_holes(settings, alpha, drawn, target_weld if len(o_pos) == 0 else None)
    stats = _plan_stats(target, settings, areas, uv_area, len(o_pos), culling, pixel_size * scale, dense_fraction,
                        holes, smooth_corners, uv_warnings + layout.warnings + unusable_normal_warnings(
                            target.name, target.normals if settings.normals == "mesh" else None),
                        alpha, {**uv_counters, **layout.counters})
    uvs = np.zeros((target.face_count, 3, 2)) if target.uvs is None else target.uvs
    # A view's side is at most the diameter of the whole target (extent about the origin); a
    # run of some cells draws a window of such views (views.fit_views).
    window = _window_faces(target, settings, run, layout, method)
    return BakePlan(
        settings=settings, run=run, layout=layout, method=method, centre=centre, scale=scale,
        target_positions=t_pos.astype(np.float32), target_uvs=uvs.astype(np.float32),
        target_faces=np.concatenate([normals, inv_s[:, None]], axis=1).astype(np.float32), target_corners=corners,
        target_above=above, occluder_positions=o_pos.astype(np.float32),
        occluder_normals=np.asarray(o_normals, dtype=np.float32), directions=directions, pixel_size=pixel_size,
        max_view_side=int(np.ceil(2.0 * extent / pixel_size)) + 4,
        # Distinct corners: a light view's window is fitted to them (shared corners once).
        target_points=layout.view_points(t_pos.reshape(-1, 3)[target_weld[0]], pixel_size),
        window_faces=window, window_points=None if window is None else t_pos[window].reshape(-1, 3),
        window_spheres=None if run.window_spheres is None else run.window_spheres / np.array([scale] * 4)
        - np.append(centre / scale, 0.0),
        drawn_sphere=bounding_sphere(drawn), needs_footprint_splat=dense_fraction > DENSE_AREA_LIMIT,
        smooth_shading=smooth_corners > 0 or layout.smooth_receivers, closed_surfaces=holes == [], holes=holes,
        stats=stats, alpha=alpha, direction_class=direction_class, classes=classes)


def _face_normals_areas(target: TriangleSoup) -> tuple[np.ndarray, np.ndarray]:
    """face_normals_areas of the target, which must have a face of some area."""
    normals, areas = face_normals_areas(target.positions)
    if not (areas > 0.0).any():
        raise BakeInputError(f"'{target.name}' has only zero-area faces")
    return normals, areas


def _normalized(target: TriangleSoup) -> tuple[np.ndarray, float, np.ndarray]:
    """(centre, scale, the target's corners (F, 3, 3) normalized): its bounding sphere maps to
    the unit sphere. float64 until here."""
    centre, radius = bounding_sphere(target.positions.reshape(-1, 3))
    scale = radius if radius > 0.0 else 1.0
    return centre, scale, (target.positions - centre) / scale


def _checked_method(settings: BakeSettings, run: BakeRun, kind, udim: UdimLayout | None) -> str:
    """The method that bakes: the run's, or Auto's choice for what the bake needs of a
    baker; a method that cannot bake it is refused here."""
    needs = _needs(settings, run, kind, udim)
    method = choose_method(run.method, needs)
    check_method(method, needs, asked_phrases(udim))
    return method


def _bent_normals(settings: BakeSettings, run: BakeRun) -> bool:
    """Whether the run sums bent normals: the settings ask for them and it reads more than the AO."""
    return settings.bent_normals and not run.ao_only


def _needs(settings: BakeSettings, run: BakeRun, kind, udim: UdimLayout | None) -> frozenset[str]:
    """What a bake with these settings, this run, this target kind and (where tiled) UDIM
    layout needs of a baker, occluders that let light through aside (BakePlan.abilities_needed
    adds them)."""
    return run.needs | abilities_needed(settings.max_distance, _bent_normals(settings, run), kind, udim is not None,
                                        settings.min_distance, settings.spread_cos > 0.0)


def _method_directions(settings: BakeSettings, run: BakeRun, kind: TargetKind, udim, layout: TexelLayout,
                       method: str, alpha: DrawnAlpha | None) -> tuple[str, int, np.ndarray, np.ndarray]:
    """(the method that runs: Auto chooses again where occluders let light through, its
    texel classes (core/bake/interleave.py), the directions (D, 3) and the class each serves (D,))."""
    if alpha is not None:
        method = choose_method(run.method, _needs(settings, run, kind, udim) | {"alpha"})
    classes = classes_for(declaration(method).interleaves, layout.per_element, run.directions, settings.texel_sets)
    return (method, classes, *class_directions(run.directions, run.seed, classes))


def _drawn_holes(settings: BakeSettings, alpha, drawn: np.ndarray, welded) -> list | None:
    """surface_holes of what the light views draw, where it can change what is drawn (see
    depth_map_culls_back_faces); None where it cannot. welded: the drawn corners' weld when
    they are the target's alone (one weld serves both)."""
    # Through surfaces that let light through, every face on a ray counts: no culling of one side.
    if settings.max_distance != 0.0 or settings.min_distance != 0.0 or settings.ignore_back_faces \
            or alpha is not None:
        return None
    return surface_holes(drawn.reshape(-1, 3, 3), welded)


def _checked_inputs(target, occluders: list[TriangleSoup], settings: BakeSettings, high_to_low: HighToLow | None,
                    vertex_target: VertexTarget | None) -> tuple[BakeTarget, list[TriangleSoup]]:
    """The bake target (checked for what the settings ask) and the occluders (Selected to
    Active: the high-poly sources first), every one of them finite."""
    bake_target = as_bake_target(target, settings.target, high_to_low, vertex_target)
    bake_target.check(settings.bent_normals)
    _check_finite(bake_target.soup)
    for occ in occluders:
        _check_finite(occ)
    if bake_target.high_to_low is not None:
        check_high_to_low(bake_target.soup, bake_target.high_to_low, settings.cage_extrusion)
        occluders = [*bake_target.high_to_low.sources, *occluders]
    return bake_target, occluders


def _uv_layout(target: TriangleSoup, kind, settings: BakeSettings) -> tuple:
    """(each face's UV area, the UDIM layout, the layout's warnings and counters), or
    (None, None, [], {}) for a target without a UV layout."""
    if not kind.needs_uvs:  # the light views are as fine as for a Size map over the bounding sphere
        return None, None, [], {}
    uv_area = uv_areas(target.uvs)
    if not (uv_area > 0.0).any():
        raise BakeInputError(f"'{target.name}': every UV triangle has zero area (is the UV map empty?)")
    udim = udim_layout(target.uvs)
    return (uv_area, udim, *tile_layout_warnings(target, settings.size, udim))


def _drawn_occluders(occluders: list[TriangleSoup], flat: np.ndarray, settings: BakeSettings, kind,
                     target: TriangleSoup, centre: np.ndarray, scale: float) -> tuple:
    """(the occluders' drawn faces, normalized (N, 3, 3); (faces, alpha) of every drawn part
    in order, the target's first where it occludes; culling counters). Occluders that cannot
    reach the receivers (flat: their points) within max_distance are never drawn."""
    if settings.max_distance > 0.0 and occluders:
        lo_t, hi_t = column_bounds(flat)
    occ_parts, culled_objects, culled_faces, drawn_objects = [], 0, 0, 0
    alpha_parts = [(target.face_count, None)] if kind.target_occludes else []  # drawn faces, in order
    for occ in occluders:
        if occ.face_count == 0:
            continue
        p = occ.positions
        near = None
        if settings.max_distance > 0.0:
            # Per triangle: the gap between its box and the target's box.
            gap = np.maximum(0.0, np.maximum(p.min(axis=1) - hi_t, lo_t - p.max(axis=1)))
            near = np.sqrt((gap * gap).sum(axis=1)) <= settings.max_distance
            culled_faces += int((~near).sum())
            if not near.any():
                culled_objects += 1
                continue
            p = p[near]
        drawn_objects += 1
        occ_parts.append((p - centre) / scale)
        alpha_parts.append((len(p), occ.alpha if occ.alpha is None or near is None else occ.alpha.subset(near)))
    o_pos = np.concatenate(occ_parts) if occ_parts else np.zeros((0, 3, 3))
    culling = dict(occluder_faces_culled=culled_faces, occluder_objects_drawn=drawn_objects,
                   occluder_objects_culled=culled_objects)
    return o_pos, alpha_parts, culling


def _plan_stats(target: TriangleSoup, settings: BakeSettings, areas: np.ndarray, uv_area: np.ndarray | None,
                occluder_faces: int, culling: dict, pixel_size_world: float, dense_fraction: float, holes,
                smooth_corners: int, warnings: list[str], alpha, counters: dict) -> dict:
    """The plan's counters (BakeResult.stats: what was drawn, culled, skipped)."""
    return dict(target_faces=int(target.face_count), zero_area_faces=int((areas <= 0.0).sum()),
                zero_uv_area_faces=0 if uv_area is None else int((uv_area <= 0.0).sum()),
                occluder_faces_drawn=int(occluder_faces), occluder_faces_culled=culling["occluder_faces_culled"],
                occluder_objects_drawn=culling["occluder_objects_drawn"],
                occluder_objects_culled=culling["occluder_objects_culled"], pixel_size_world=pixel_size_world,
                dense_uv_area_fraction=dense_fraction, closed_surfaces=holes == [],
                holes=-1 if holes is None else len(holes), smooth_corners=smooth_corners,
                samples_per_texel=settings.sample_count, warnings=warnings,
                alpha_faces=0 if alpha is None else int(((alpha.constant < 1.0) | (alpha.layer >= 0)).sum()),
                **counters)
