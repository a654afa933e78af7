# SPDX-License-Identifier: GPL-3.0-or-later
"""The manual's pictures of what each bake option does and of viewport AO beside EEVEE's and
the ray-traced truth; writes the images into docs/images/ and the page docs/options.md.

    .venv/bin/python tools/manual_pictures.py [--only options|viewport]

- Options: Spot (samples/spot.obj, its UVs, shaded smooth) on a floor, baked at 256^2, each
  option against the defaults, side by side (left: default, right: the option).
- Viewport: the viewport benchmark's multi-object scene (bench/hao_bench.py) at a max
  distance of 0.3 times its height: HAO, EEVEE's Ambient Occlusion node and the ray-traced
  AO of every pixel (same points, normals, kernel and distance), with each one's RMSE.
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "bench")]

import numpy as np  # noqa: E402

IMAGES = ROOT / "docs" / "images"
SIZE = 256
GAP = 4
BACKGROUND = 0.7  # the viewport pictures' background: open surfaces (AO 1) stand out from it


@dataclass(frozen=True)
class OptionPicture:
    """A picture row: name (file and anchor), title, what to look at, the option's settings
    (and those of the default side, when it is not the defaults)."""
    name: str
    title: str
    caption: str
    after: dict
    before: dict = field(default_factory=dict)
    floor: bool = True


# One row per option worth seeing; the settings come from BakeSettings (one definition).
OPTIONS = [
    OptionPicture("max-distance", "Max Distance", "Only occluders within 0.1 units darken: the floor no longer "
                  "darkens the whole underside, contact shadows stay.", {"max_distance": 0.1}),
    OptionPicture("falloff", "Falloff (Wendland)", "With the same max distance, occlusion fades smoothly to zero "
                  "at it instead of stopping.", {"max_distance": 0.1, "falloff": "wendland"},
                  {"max_distance": 0.1}),
    OptionPicture("spread-angle", "Spread Angle", "45 degrees about the normal instead of the hemisphere: a "
                  "tighter, contact-like AO.", {"spread_angle": 45.0}),
    OptionPicture("min-distance", "Min Distance", "Occluders nearer than 0.05 along a ray are skipped: small "
                  "creases open up, large forms keep their shadow.", {"min_distance": 0.05}),
    OptionPicture("normals", "Normals: Face", "Every texel uses its triangle's normal: the facets show. Mesh "
                  "Shading (left, the default) follows the smooth normals, as Cycles bakes.", {"normals": "face"}),
    OptionPicture("terminator", "Terminator Offset 0", "Without Cycles' shadow-terminator offset, rays that graze "
                  "a smooth-shaded facet can hit its neighbours and darken the triangles; on Spot at this size "
                  "the difference is slight.", {"terminator_offset": 0.0}),
    OptionPicture("weighting", "Weighting: Uniform", "Every direction counts alike (the fraction of the open "
                  "hemisphere) instead of by its cosine: grazing directions, the ones most often blocked, weigh "
                  "as much as those overhead, so the map is darker wherever the horizon is blocked.", {"weighting": "uniform"}),
    OptionPicture("directions", "Directions 16 against 1024", "Few directions are noisy; the bake's own error "
                  "estimate says how noisy (left: 16, right: 1024).", {"directions": 1024}, {"directions": 16}),
    OptionPicture("anti-aliasing", "Anti-Aliasing 16", "16 samples per texel smooth the silhouettes' and UV "
                  "edges' stair steps (at 64^2, enlarged).", {"samples_per_texel": 16, "size": 64},
                  {"size": 64}),
    OptionPicture("texel-sets", "Texel Sets 2 x 2", "Neighbouring texels take turns with four direction sets: "
                  "under the body and in the creases the polygons of each direction's shadow become fine grain "
                  "(plainer on a floor: How it works); four light views per direction.", {"texel_sets": 4}),
    OptionPicture("margin", "Margin 0", "Without a margin, filtering reads the background at UV island edges "
                  "(left: 16 texels, the default).", {"margin": 0}),
    OptionPicture("thickness", "Thickness", "Thickness (right) beside the AO: light where a wall is near in "
                  "every direction inside the mesh (ears, horns, legs: thin), dark where the cow is thick.",
                  {"thickness": True, "thickness_distance": 0.3}, floor=False),
]


def spot_scene(floor: bool):
    from hao_addon.core import scenes
    from hao_addon.core.geometry import TriangleSoup, smooth_vertex_normals
    from hao_addon.core.objfile import obj_soup
    spot = obj_soup(ROOT / "samples" / "spot.obj")
    z_up = spot.positions[..., [0, 2, 1]] * np.array([1.0, -1.0, 1.0])  # the OBJ is Y-up, as Blender imports it
    spot = TriangleSoup(z_up, spot.uvs, name="spot", normals=smooth_vertex_normals(z_up))
    lowest = float(spot.positions[..., 2].min())
    return spot, ([scenes.grid_plane(4.0, 8, z=lowest)] if floor else [])


def option_maps(row: OptionPicture) -> tuple[np.ndarray, np.ndarray]:
    from hao_addon.bake import bake, thickness_steps
    from hao_addon.core.bake.settings import BakeSettings
    from hao_addon.core.steps import drain
    spot, occluders = spot_scene(row.floor)
    base = dict(size=SIZE, directions=256)
    maps = []
    for extra in (row.before, row.after):
        settings = BakeSettings(**{**base, **extra})
        if settings.thickness:  # its own map: 1 thin, 0 thick
            ao = drain(thickness_steps(spot, settings, use_cache=False)).ao
        else:
            ao = bake(spot, occluders, settings, use_cache=False).ao
        if ao.shape[0] != SIZE:  # a small map, enlarged without filtering
            ao = np.kron(ao, np.ones((SIZE // ao.shape[0],) * 2, np.float32))
        maps.append(ao)
    return maps[0], maps[1]


def side_by_side(*images: np.ndarray) -> np.ndarray:
    """(H, W) images in a row with a white gap (row 0 at the bottom, like the maps)."""
    h = max(i.shape[0] for i in images)
    parts = []
    for k, image in enumerate(images):
        if k:
            parts.append(np.ones((h, GAP), np.float32))
        parts.append(image.astype(np.float32))
    return np.concatenate(parts, axis=1)


def write_png(path: Path, image: np.ndarray) -> None:
    from hao_addon.core.imageio import atomic_write_bytes, encode_image
    atomic_write_bytes(path, encode_image(path, np.clip(image, 0.0, 1.0), None, 8, True))


def options_pictures() -> list[str]:
    from hao_addon.gpu.context import ensure_gpu_context
    ensure_gpu_context()
    lines = ["# Each option, before and after", "",
             "Generated by `tools/manual_pictures.py`: Spot (`samples/spot.obj`, shaded smooth) on a floor, "
             f"baked at {SIZE}² with 256 directions. Left: the defaults; right: the option. The maps are in "
             "Spot's UV layout. All settings: "
             "[Settings](settings.md).", ""]
    for row in OPTIONS:
        before, after = option_maps(row)
        write_png(IMAGES / "options" / f"{row.name}.png", side_by_side(before, after))
        setting = ", ".join(f"`{k} = {v}`" for k, v in row.after.items())
        lines += [f"## {row.title}", "", f"{row.caption} ({setting})", "",
                  f"![{row.title}: default left, option right](images/options/{row.name}.png)", ""]
        print(f"options: {row.name}", flush=True)
    return lines


def viewport_pictures() -> list[str]:
    import hao_bench as hb
    from hao_addon.gpu.context import ensure_gpu_context
    from hao_addon.core.reference import build_bvh, reference_accessibility
    from hao_addon.gpu.hao_renderer import HaoRenderer
    hb.WIDTH, hb.HEIGHT = 320, 240
    ensure_gpu_context()
    soups = hb.scene_soups("multi-object", quick=True)
    hb.soup_scene(soups)
    objects = hb.objects_of(soups)
    view_proj = hb.view_projection(hb.BENCH_CAMERA)
    height = float(np.ptp(np.concatenate([s.positions for s in soups]).reshape(-1, 3)[:, 2]))
    settings = hb.TABLE1.with_(max_distance=0.3 * height)
    renderer = HaoRenderer()
    try:
        renderer.render(objects, view_proj, hb.WIDTH, hb.HEIGHT, settings)
        hao = renderer.read_ao()
        pos, nrm, _ = renderer.gbuffer.read()
        visible = pos[..., 3] >= 1.0
        ys, xs = np.nonzero(visible)
        tris = np.concatenate([o.world_positions() for o in objects])
        truth = np.ones_like(hao)
        truth[ys, xs] = reference_accessibility(pos[ys, xs, :3].astype(np.float64) + renderer.anchor,
                                                nrm[ys, xs, :3].astype(np.float64), tris, rays=256,
                                                max_distance=settings.max_distance, falloff=settings.falloff,
                                                seed=0, bvh=build_bvh(tris))
    finally:
        renderer.free()
    _seconds, eevee = hb.eevee_ao(settings.max_distance, ROOT / "out")
    rmse = {name: float(np.sqrt(np.mean((image[ys, xs] - truth[ys, xs]) ** 2)))
            for name, image in (("hao", hao), ("eevee", eevee))}
    for name, image in (("hao", hao), ("eevee", eevee), ("truth", truth)):
        write_png(IMAGES / "viewport" / f"{name}.png", np.where(visible, image, BACKGROUND))
    print(f"viewport: RMSE HAO {rmse['hao']:.4f}, EEVEE {rmse['eevee']:.4f}", flush=True)
    return ["## Viewport AO beside EEVEE's and the truth", "",
            f"The viewport benchmark's scene ({hb.WIDTH}x{hb.HEIGHT}, max distance 0.3 times its height). "
            f"Left to right: HAO (RMSE {rmse['hao']:.3f} against the truth), EEVEE's Ambient Occlusion node "
            f"(RMSE {rmse['eevee']:.3f}) and the ray-traced AO of every pixel (256 rays, the same points, "
            "normals, kernel and distance). The background is grey.", "",
            "![HAO](images/viewport/hao.png) ![EEVEE](images/viewport/eevee.png) "
            "![Ray-traced truth](images/viewport/truth.png)", ""]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", choices=("options", "viewport"))
    args = parser.parse_args()
    page = ROOT / "docs" / "options.md"
    lines = options_pictures() if args.only != "viewport" else page.read_text().split("\n## Viewport")[0].splitlines()
    lines += viewport_pictures() if args.only != "options" else []
    page.write_text("\n".join(lines).rstrip("\n") + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
