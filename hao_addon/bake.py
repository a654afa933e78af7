# SPDX-License-Identifier: GPL-3.0-or-later
"""Bake orchestration shared by the operator, the CLI and the tests.

``bake_steps`` is a generator: it yields the fraction done after each light direction (and
during a Selected-to-Active projection, after each step of its rays), so the modal operator
can draw progress and stop between any two (cancel), and ``bake`` simply drains it.
Nothing here touches Blender data: input and output are numpy.
"""
from __future__ import annotations

import hashlib
import math
import time
from collections import OrderedDict
from dataclasses import dataclass, field, replace
from typing import Callable, Generator

import numpy as np

from .core.steps import drain, relay
from .core.blas_threads import single_threaded_blas
from .core.geometry import TriangleSoup, bounding_sphere
from .core.errors import BakeInputError
from .core.bake.plan import make_plan_steps
from .core.bake.projection import HighToLow
from .core.bake.error_estimate import ErrorEstimate, converged, estimate, local_rms, next_round, PILOT_DIRECTIONS, \
    replicate_twin, with_floor, directions_for
from .contact_repair import traced_contacts_steps
from .floor_check import FLOOR_REACH, floor_sample, floor_steps, floor_warnings, probe_steps, take_probe
from .replicates import replicate_sums_steps
from .core.bake.seams import dilate, finalize_vectors
from .core.bake.settings import QUALITY_CAPS, BakeSettings
from .core.bake.abilities import declaration
from .core.bake.bake_run import BakeRun
from .core.bake.targets import BakeTarget, as_bake_target
from .core.bake.target_kinds import IMAGE_TARGET
from .core.bake.vertex_target import VertexTarget


@dataclass
class BakeResult:
    """ao: (size, size) float32 accessibility (1 = open), row 0 at v = 0 (Blender's pixel
    order); covered: texels with a direct estimate; filled: covered plus margin;
    bent_normals: (size, size, 3) float32 unit world-space bent normals (zero outside
    filled), or None unless settings.bent_normals. A colour-attribute bake (VertexTarget):
    ao, covered and filled are (count,), one per vertex or corner (1.0 where no lit corner
    sampled it, e.g. a loose vertex). A UDIM layout: tiles are the UDIM numbers, and ao,
    covered, filled (and bent_normals) gain a leading axis, one map per tile in that order."""

    ao: np.ndarray
    covered: np.ndarray
    filled: np.ndarray
    stats: dict = field(default_factory=dict)
    bent_normals: np.ndarray | None = None
    tiles: tuple[int, ...] | None = None
    # The bake's own statistical error (core/bake/error_estimate.py): each covered texel's (or
    # element's) twin, a draw from its error's distribution (ao's shape, 0 elsewhere), and
    # the map's estimate from them; None with a single direction.
    twin: np.ndarray | None = None
    error: ErrorEstimate | None = None
    # The bake method that ran (the plan's choice, BakePlan.method; stats["method"] reports it).
    method: str = ""
    # An incremental re-bake's (hao_addon/rebake.py): each cell's bound on how far it lies from
    # a whole bake of its scene (ao's shape, float32): 0 where baked, a kept cell's bounds
    # added up over the re-bakes that kept it. None: every cell is baked.
    kept_offset: np.ndarray | None = None

    def error_map(self) -> np.ndarray | None:
        """ao's shape float32: each texel's estimated error (its neighbourhood's RMS twin)."""
        return None if self.twin is None else local_rms(self.twin, self.covered)


# Whether the rounds of a bake to an error after the first leave converged texels out
# (core/bake/error_estimate.converged) where the method can. Off: measured on the smooth rocker
# arm at half an 8-bit step (bench/error_bench.py), leaving out the 20 % of texel directions
# that had converged saved 1 % of the time (the gather's time is mostly its depth maps, drawn
# for every direction whatever the texels), and it made the estimate dishonest: 0.0019 p99
# estimated, 0.0025 measured (0.0019 without). Texels chosen for small twins report those
# twins; an honest choice needs a contrast the report does not use, a third replicate
# (1.2-1.3x the map's noise at equal directions).
SKIP_CONVERGED = False

# The share of a GPU bake's progress bar that measuring its visibility floor fills (a few
# percent of its time: hao_addon/floor_check.py).
FLOOR_PROGRESS_SHARE = 0.05

# The share of a Selected-to-Active bake's progress bar that its projection fills (measured on
# the bunny pair at 1024^2: 2.8 s of 7.8 s at 256 directions, of 22 s at 1024).
PROJECTION_PROGRESS_SHARE = 0.25

_CACHE: "OrderedDict[str, BakeResult]" = OrderedDict()
_CACHE_SIZE = 8


def bake_key(target: TriangleSoup | BakeTarget, occluders: list[TriangleSoup], settings: BakeSettings,
             high_to_low: HighToLow | None = None, vertex_target: VertexTarget | None = None,
             needs: frozenset[str] = frozenset()) -> str:
    """A digest of everything a bake's result depends on (geometry, UVs, normals, settings,
    abilities needed beyond the settings'): equal keys bake equal maps. The cache's key, and
    a frame sequence's test for a frame that repeats an earlier one."""
    bake_target = as_bake_target(target, settings.target, high_to_low, vertex_target)
    target, high_to_low, vertex_target = bake_target.soup, bake_target.high_to_low, bake_target.corners
    h = hashlib.blake2b(digest_size=20)
    h.update(repr(settings.cache_key()).encode())
    if needs:  # (nothing added without: the keys of plain bakes stay as they were)
        h.update(repr(sorted(needs)).encode())
    if vertex_target is not None:
        h.update(b"|vertex-target|%d|" % vertex_target.count)
        h.update(np.ascontiguousarray(vertex_target.cells).tobytes())
    sources = []
    if high_to_low is not None:
        sources = high_to_low.sources
        h.update(b"|high-to-low|%d|" % len(sources))
        for extra in (high_to_low.extrusion_normals, high_to_low.cage):
            h.update(b"|none|" if extra is None else np.ascontiguousarray(extra).tobytes())
    for soup in [target, *sources, *occluders]:
        h.update(np.ascontiguousarray(soup.positions).tobytes())
        h.update(b"|uv|" if soup.uvs is not None else b"|no-uv|")
        if soup.uvs is not None:
            h.update(np.ascontiguousarray(soup.uvs).tobytes())
        h.update(b"|flat|" if soup.normals is None else np.ascontiguousarray(soup.normals).tobytes())
        alpha = soup.alpha
        if alpha is not None:  # what lets light through (core/bake/alpha.py)
            for part in (alpha.constant, alpha.image_index, alpha.uvs, *alpha.images):
                h.update(b"|none|" if part is None else np.ascontiguousarray(part).tobytes())
    return h.hexdigest()


def _renamed(warnings: list[str], old: str | None, new: str) -> list[str]:
    """A cached bake's warnings for the target asking now: the cache is keyed by geometry, not
    by name, and every warning names its object in quotes ('Spot')."""
    if not old or old == new:
        return list(warnings)
    return [w.replace(f"'{old}'", f"'{new}'") for w in warnings]


def clear_cache() -> None:
    _CACHE.clear()


def bake_steps(target: TriangleSoup | BakeTarget, occluders: list[TriangleSoup], settings: BakeSettings,
               use_cache: bool = True, high_to_low: HighToLow | None = None,
               vertex_target: VertexTarget | None = None, needs: frozenset[str] = frozenset()
               ) -> Generator[float, None, BakeResult]:
    """Bake `target` (with UVs) against itself and `occluders`; yields progress in [0, 1].
    With `high_to_low`, bake its sources onto the target's UVs (Selected to Active); with
    settings.target 'color-attribute', at the face corners of `vertex_target` (no UVs).
    target may be a BakeTarget (core/bake/targets.py) that holds either itself. needs:
    abilities the bake needs of a baker beyond its settings' (BakeRun.needs: thickness).

    A re-bake of identical geometry, UVs and settings returns the cached result at once
    (the GPU is not touched). Raises BakeInputError for input that cannot be baked.
    """
    t0 = time.perf_counter()
    if settings.spread_cos > 0.0 and settings.directions * math.sin(math.radians(settings.spread_angle)) ** 2 < 1.0:
        raise BakeInputError("spread angle: " + spread_warning(settings, settings.directions).replace("the map is", "the map would be"))
    target = as_bake_target(target, settings.target, high_to_low, vertex_target)
    key = bake_key(target, occluders, settings, needs=needs) if use_cache else None
    if key is not None and key in _CACHE:
        _CACHE.move_to_end(key)
        cached = _CACHE[key]
        yield 1.0
        stats = {**cached.stats, "cache_hit": True, "target_name": target.name,
                 "warnings": _renamed(cached.stats.get("warnings", []), cached.stats.get("target_name"), target.name)}
        return replace(cached, stats=stats)
    # numpy's BLAS workers would spin on the cores the GPU driver needs (core/blas_threads.py).
    with single_threaded_blas() as blas_threads:
        # The floor check samples more texels for bakes of more directions (floor_texel_count).
        shared: dict = {"floor_directions": settings.direction_cap if settings.error_target > 0.0
                        else settings.directions}
        run = BakeRun.of(settings, needs)
        if settings.error_target > 0.0:
            baking = _bake_to_error(target, occluders, settings, run, shared)
        else:
            baking = _bake_uncached(target, occluders, settings, run, shared)

        def share() -> float:  # the floor check's, once the plan has chosen the method (shared["method"])
            unchecked = "method" in shared and declaration(shared["method"]).floor_unchecked
            return 0.0 if unchecked else FLOOR_PROGRESS_SHARE
        result = yield from relay(baking, lambda fraction: (1.0 - share()) * fraction)
        result = yield from relay(_with_floor_steps(result, shared, settings, target.name),
                                  lambda fraction: 1.0 - share() + share() * fraction)
    result.stats.update(blas_threads_held=blas_threads is not None, seconds=time.perf_counter() - t0,
                        target_name=target.name)
    directions = result.error.directions if result.error is not None else settings.directions
    sparse = spread_warning(settings, directions)
    if sparse:
        result.stats["warnings"] = [*result.stats.get("warnings", []), f"'{target.name}': {sparse}"]
    if key is not None:
        _CACHE[key] = result
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.popitem(last=False)
    return result


# Fewer directions than this expected inside the spread cone make a map of noise (or, with
# none inside, a white one): the bake says so.
MIN_DIRECTIONS_IN_CONE = 16


def spread_warning(settings: BakeSettings, directions: int) -> str:
    """'' or a warning when the spread cone holds too few of the bake's directions: of
    cosine-weighted directions a share sin^2(angle) falls within the cone."""
    if settings.spread_cos <= 0.0:
        return ""
    share = math.sin(math.radians(settings.spread_angle)) ** 2
    expected = directions * share
    if expected >= MIN_DIRECTIONS_IN_CONE:
        return ""
    return (f"about {expected:.3g} of its {directions} directions fall within the spread angle of "
            f"{settings.spread_angle:g} degrees: the map is {'white' if expected < 1 else 'mostly noise'}; "
            f"raise the spread angle or Directions (about {MIN_DIRECTIONS_IN_CONE / share:.3g})")


def _bake_uncached(target: BakeTarget, occluders: list[TriangleSoup], settings: BakeSettings, run: BakeRun,
                   shared: dict | None = None) -> Generator[float, None, BakeResult]:
    """bake_steps without its cache: plan `run` (core/bake/bake_run.py: its directions, seed,
    cells), run the baker's directions, finish the output. shared: kept across the rounds of
    a bake to an error; what a later round may reuse of the plan (the Selected-to-Active
    projection, BakePlan.layout.reusable) is stored there, and the method that ran."""
    from .bakers import BAKE_METHODS, baker_for, ray_cast_name, ray_caster_for  # deferred: need a GPU context
    projects = target.high_to_low is not None
    share = PROJECTION_PROGRESS_SHARE if projects else 0.0
    shared = {} if shared is None else shared
    # The plan chooses the method (BakePlan.method), and the projection casts with its own rays.
    planning = make_plan_steps(target, occluders, settings, projection=shared.get("projection"), run=run,
                               cast_for=ray_caster_for)
    plan = yield from relay(planning, lambda fraction: share * fraction)  # a cancel stops the projection
    shared["projection"] = plan.layout.reusable()
    method = shared["method"] = plan.method
    cast_stats = {"ray_cast": ray_cast_name(method)} if projects and method in BAKE_METHODS else {}
    baker_cls = baker_for(method)
    baker_cls.check_limits(plan)
    baker = baker_cls(plan)
    try:
        count = plan.direction_count
        best = shared["floor_probe"].half if shared.get("floor_probe") else 0
        snapshots = probe_steps(method, count, best)
        sums_a, sums_b = yield from replicate_sums_steps(baker, count, share, snapshots)
        contacts = yield from traced_contacts_steps(plan, baker, count, (sums_a, sums_b), shared)
        # The map is the replicates' mean (each receiver weighs 1 in each).
        sums = sums_b if sums_a is None else sums_a + sums_b
        gpu_stats = {**baker.stats, **contacts}
        if "floor_sample" not in shared:  # the first round's sample points serve every round
            # The texels the map's error covers: a scatter's texels under half covered are grown
            # from their neighbours, and checking their own partial sums stated a floor the map
            # does not have (the rocker arm at 128^2, 1024 directions: 0.0083 where 0.0065 is
            # measured in all).
            checked = plan.layout.estimated(plan.estimator.ratio(sums)[1])
            shared["floor_sample"] = floor_sample(method, checked, baker,
                                                  shared.get("floor_directions", plan.texel_directions), plan.seed)
        if snapshots is not None and shared["floor_sample"] is not None:
            shared["floor_probe"] = take_probe(plan, baker, count, snapshots, shared["floor_sample"].cells,
                                               (sums_b if sums_a is None else sums_a, sums_b))
    finally:
        baker.free()
    # A run of some cells grows no margins and is finished at its cells alone: whoever merges
    # it grows them from the merged values (_combine_rounds, rebake.py).
    if plan.cells is None:
        ao, covered, filled, bent = plan.layout.finished(plan.estimator, sums, settings.margin)
    else:
        ao, covered, filled, bent = plan.layout.finished_cells(plan.estimator, sums, plan.cells)
    twin = None if sums_a is None else _twin(plan, sums_a, sums_b, covered)
    error = None if twin is None else estimate(twin, covered, plan.texel_directions)
    if not covered.any() and not plan.layout.per_element:
        # A map of no texel is not a bake: a success here would hand back an empty image.
        raise BakeInputError(f"'{target.name}': no texel centre of the {settings.size}x{settings.size} map lies "
                             f"inside its UV triangles (they lie outside the 0..1 tile, or are smaller than a "
                             f"texel): nothing to bake; check its UV map")
    stats = {**plan.stats, **cast_stats, **gpu_stats, "method": method, "texel_sets": plan.classes,
             "covered_texels": int(covered.sum()),
             "cache_hit": False, "error": None if error is None else error.as_dict()}
    return BakeResult(ao, covered, filled, stats, bent, plan.layout.tiles, twin, error, method)


def _twin(plan, sums_a: np.ndarray, sums_b: np.ndarray, covered: np.ndarray) -> np.ndarray:
    """(covered's shape) float32 each covered cell's twin (replicate_twin), 0 elsewhere; a run
    of some cells computes it at them alone."""
    ratio = plan.estimator.ratio
    if plan.cells is None or covered.size != np.prod(plan.layout.output_shape):
        twin = replicate_twin(*ratio(sums_a), *ratio(sums_b))
        return np.where(covered, twin.reshape(covered.shape), np.float32(0.0))
    cells = plan.cells
    parts = [part.reshape(-1)[cells] for part in (*ratio(sums_a), *ratio(sums_b))]
    twin = np.zeros(covered.shape, np.float32)
    twin.reshape(-1)[cells] = replicate_twin(*parts)
    return np.where(covered, twin, np.float32(0.0))


def _bake_to_error(target: BakeTarget, occluders: list[TriangleSoup], settings: BakeSettings, first_run: BakeRun,
                   shared: dict) -> Generator[float, None, BakeResult]:
    """Rounds of whole bakes, each with its own direction set, until the estimated p99 of their
    union is within settings.error_target or settings.direction_cap is spent (capped). Each
    round's size is predicted from the error so far (core/bake/error_estimate.next_round).
    When the twins reach the target, the visibility floor is measured (hao_addon/floor_check.py);
    where it keeps the whole error above the target but is itself below FLOOR_REACH of it, the
    twins' target is lowered to leave room for it (p99s added in quadrature) and rounds go on.
    Each texel is the mean of the rounds that baked it, weighted by their directions, and so is
    its twin (independent rounds: still a draw of its error). Every round bakes every texel
    (SKIP_CONVERGED); stats' skippable_fraction is the share of texel directions that
    leaving converged texels out would have saved."""
    target_error, cap = settings.error_target, settings.direction_cap
    stat_target, floor_checks = target_error, 0
    rounds, history = [], []
    work = skipped = 0.0  # texel x direction pairs: all of them, and those left out
    size, done, shown, cells, skips = min(cap, PILOT_DIRECTIONS), 0, 0.0, None, True
    while size > 0:
        run = replace(first_run, directions=size, seed=(settings.seed + 7919 * len(rounds)) % 2**31,
                      cells=cells if skips and SKIP_CONVERGED else None)
        def overall(fraction: float, done: int = done, size: int = size) -> float:
            nonlocal shown  # progress never goes back when a round is added
            shown = max(shown, min(0.99, (done + fraction * size) / max(done + size, 1)))
            return shown
        part = yield from relay(_bake_uncached(target, occluders, settings, run, shared), overall)
        skips = not declaration(part.method).bakes_all_cells
        rounds.append((size, part))
        done += size
        combined = _combine_rounds(rounds, settings.margin)
        if combined.error is None:
            break
        history.append((done, combined.error.p99))
        size = next_round(history, stat_target, cap)
        # Checked again where the room left for the floor was too little (the quadrature sum
        # understates the p99 of the floor and the noise per texel: a floor and ball landed 0.0315).
        if not size and floor_checks < 3 and done < cap:
            floor_checks += 1
            whole = yield from relay(_with_floor_steps(combined, shared, settings, target.name), lambda f: shown)
            floor_p99 = whole.error.floor_p99
            if whole.error.p99 > target_error and floor_p99 < FLOOR_REACH * target_error:
                stat_target = min(target_error * math.sqrt(1.0 - (floor_p99 / target_error) ** 2),
                                  combined.error.p99 * target_error / whole.error.p99)
                size = next_round(history, stat_target, cap)
        if size:  # the texels the next round needs: those not yet converged (all if none is)
            active = combined.covered & ~converged(combined.twin, combined.covered, target_error)
            cells = np.flatnonzero(active) if active.any() else None
            work += size * float(combined.covered.sum())
            skipped += size * float(combined.covered.sum() - active.sum())
    skipping = {"rounds": [n for n, _r in rounds], "skippable_fraction": skipped / work if work else 0.0,
                "skipped_converged": SKIP_CONVERGED and skips and skipped > 0.0,
                **({"bakes_all_cells": declaration(rounds[0][1].method).bakes_all_cells} if not skips else {})}
    return _to_error_result(combined, settings, stat_target, done, skipping, target.name)


def _to_error_result(combined: BakeResult, settings: BakeSettings, stat_target: float, done: int, skipping: dict,
                     name: str) -> BakeResult:
    """The rounds' combined result with its error marked capped where the twins' p99 is still
    above stat_target, and the directions the target needs by the measured rate (a warning)."""
    target_error = settings.error_target
    capped = combined.error is not None and combined.error.p99 > stat_target
    error = None if combined.error is None else replace(combined.error, capped=capped)
    stats = {**combined.stats, "error": None if error is None else error.as_dict(), "error_target": target_error,
             **skipping}
    if capped:
        needed = directions_for(error.p99, done, target_error)
        stats["directions_needed"] = int(math.ceil(needed))
        stats["warnings"] = [*stats.get("warnings", []),
                             f"'{name}': the estimated p99 error {error.p99:.2g} is above the target "
                             f"{target_error:.2g} after {done} directions (the cap); by the measured rate it needs "
                             f"about {needed:.3g} directions"
                             + ("" if settings.quality in QUALITY_CAPS else ": raise Directions")]
    return replace(combined, stats=stats, error=error)


def _with_floor_steps(result: BakeResult, shared: dict, settings: BakeSettings, name: str
                      ) -> Generator[float, None, BakeResult]:
    """result with its stated error made whole: the visibility floor measured at sampled
    texels (hao_addon/floor_check.py) added to the twins' estimate, and a warning where that
    puts a bake to an error above its target."""
    if result.error is None or result.twin is None:
        return result
    ran = declaration(result.method)
    if ran.gpu and ran.floor_unchecked:  # said, so the twins' part is not read as the whole error
        error = replace(result.error, floor_unmeasured=ran.floor_unchecked)
        return replace(result, error=error, stats={**result.stats, "error": error.as_dict()})
    if shared.get("floor_probe") is None:
        return result
    probe = shared["floor_probe"]
    if shared.get("floor_found", (None,))[0] is not probe:  # a bake to an error measures it once per probe
        from .bakers import distance_cast_for  # deferred: the GPU's cast needs a context
        shared["floor_found"] = (probe, (yield from floor_steps(probe, shared["floor_sample"], result.error.directions,
                                                                 shared.get("contact_cells", ()),
                                                                 distance_cast_for(result.method))))
    found = shared["floor_found"][1]
    if found is None:
        return result
    cells, floor_a, floor_b, weight = found
    error = with_floor(result.error, floor_a, floor_b, result.error_map().reshape(-1)[cells], weight)
    warnings = floor_warnings(name, result.error, error, settings.error_target, (floor_a, floor_b))
    return replace(result, error=error, stats={**result.stats, "error": error.as_dict(),
                                               "warnings": [*result.stats.get("warnings", []), *warnings]})


def _combine_rounds(rounds: list[tuple[int, BakeResult]], margin: int) -> BakeResult:
    """The rounds' union: each covered texel (or element) the mean of the rounds that covered
    it, weighted by their directions, and so its bent normal and twin; margins grown again from
    the new values as the first round grew them (seams.dilate)."""
    first, last = rounds[0][1], rounds[-1][1]
    if len(rounds) == 1:
        return first
    weight = sum(n * r.covered for n, r in rounds).astype(np.float64)
    covered = weight > 0.0

    def mean(field):
        total = sum(n * np.where(r.covered.reshape(r.covered.shape + (1,) * (field(r).ndim - r.covered.ndim)),
                                 field(r).astype(np.float64), 0.0) for n, r in rounds)
        w = weight.reshape(weight.shape + (1,) * (total.ndim - weight.ndim))
        return np.divide(total, w, out=np.zeros_like(total), where=w > 0.0)

    ao = regrown(mean(lambda r: r.ao).astype(np.float32), covered, first, margin)
    bent = None
    if last.bent_normals is not None:
        tiles = mean(lambda r: r.bent_normals)
        bent = (finalize_vectors(tiles, covered, first.filled, margin) if tiles.ndim == 3 else
                np.stack([finalize_vectors(t, c, f, margin) for t, c, f in zip(tiles, covered, first.filled)]))
    twin = None
    if all(r.twin is not None for _n, r in rounds):
        twin = mean(lambda r: r.twin).astype(np.float32)
    total = sum(n for n, _r in rounds)
    error = None if twin is None else estimate(twin, covered, total)
    stats = {**last.stats, **{k: first.stats[k] for k in ("covered_texels", "warnings") if k in first.stats},
             "directions": total, "error": None if error is None else error.as_dict()}
    return BakeResult(ao, covered, first.filled, stats, bent, first.tiles, twin, error, first.method)


def regrown(values: np.ndarray, covered: np.ndarray, first: BakeResult, margin: int) -> np.ndarray:
    """values where covered, the margins grown from them as finalize_map grows a map's, the
    first round's background elsewhere; elements (colour attributes) have no margins."""
    if values.ndim == 1:
        return np.where(covered, values, first.ao)
    if values.ndim == 3:  # UDIM tiles
        return np.stack([regrown(v, c, replace(first, ao=a, filled=f), margin)
                         for v, c, a, f in zip(values, covered, first.ao, first.filled)])
    grown, _valid = dilate(values, covered, margin + 2)
    return np.where(first.filled, grown, first.ao).astype(np.float32)


def bake_cells_steps(target: TriangleSoup, occluders: list[TriangleSoup], settings: BakeSettings,
                     cells: np.ndarray) -> Generator[float, None, BakeResult]:
    """bake_steps of `cells` alone (flat indices into the output, BakePlan.cells), without
    the cache or a bake to an error: the same directions and seed as a whole bake, so a cell
    gets the value a whole bake gives it (bakers that bake every cell return all of them)."""
    run = BakeRun.of(settings).with_cells(np.asarray(cells, np.int64))
    return _bake_uncached(as_bake_target(target, settings.target), occluders, settings, run)


def inverted(soup: TriangleSoup) -> TriangleSoup:
    """The soup seen from inside: every triangle's winding (and so its normal) reversed, its
    shading normals negated, its UVs kept on the same corners."""
    normals = None if soup.normals is None else -soup.normals[:, ::-1]
    uvs = None if soup.uvs is None else soup.uvs[:, ::-1]
    return TriangleSoup(soup.positions[:, ::-1], uvs, soup.name, normals)


def thickness_steps(target: TriangleSoup, settings: BakeSettings, use_cache: bool = True
                    ) -> Generator[float, None, BakeResult]:
    """Thickness of `target`'s own surface in its UV layout (settings.thickness_distance, 0
    = the target's bounding-sphere radius): the occlusion, by the mesh itself, of the
    hemisphere about the inverted normal, i.e. the AO bake of the inverted soup with that
    max distance, as 1 - accessibility (1 thin, 0 nothing within reach; 0 outside the map's
    charts). Yields progress as bake_steps."""
    distance = settings.thickness_distance
    if distance == 0.0:
        distance = float(bounding_sphere(target.positions.reshape(-1, 3))[1])
    # The AO bake of the inverted soup within the distance: a bake of its own (its own cache
    # key), whose baker must be able to bake thickness (core/bake/abilities.py: the plan chooses).
    inside = replace(settings, max_distance=distance, bent_normals=False, thickness=False,
                     target=IMAGE_TARGET)
    # About the true (flat) inverted surface: with shading normals, directions below a face
    # but inside the smooth hemisphere count as occluded at distance 0 (Cycles' AO convention:
    # the ray enters the surface), which for thickness is the ray leaving the mesh; they gave
    # thickness up to 0.47 within a distance of 1e-30.
    result = yield from bake_steps(inverted(replace(target, normals=None)), [], inside, use_cache,
                                   needs=frozenset({"thickness"}))
    stats = {**result.stats, "thickness_distance": distance}
    twin = None if result.twin is None else -result.twin  # 1 - ao errs by minus ao's error
    return BakeResult(1.0 - result.ao, result.covered, result.filled, stats, None, result.tiles, twin, result.error,
                      result.method)


def bake(target: TriangleSoup | BakeTarget, occluders: list[TriangleSoup], settings: BakeSettings,
         progress: Callable[[float], None] | None = None, use_cache: bool = True,
         high_to_low: HighToLow | None = None, vertex_target: VertexTarget | None = None) -> BakeResult:
    """Blocking bake (drains bake_steps)."""
    # (drain closes it if progress() raises: the GPU pass is freed now, not at garbage collection.)
    return drain(bake_steps(target, occluders, settings, use_cache, high_to_low, vertex_target), progress)


__all__ = ["BakeInputError", "BakeResult", "BakeTarget", "HighToLow", "VertexTarget", "bake", "bake_key", "bake_steps",
           "clear_cache", "inverted", "thickness_steps"]
