# SPDX-License-Identifier: GPL-3.0-or-later
"""Alpha-aware occluders (issue 30 item 2): a leaf card of alpha a over a floor lets 1 - a
of the light through, on every baker; a card clipped by its alpha texture occludes as its
opaque cut-out mesh; Blender materials are read as the glTF importer sets them up; a scene
without alpha runs the plain passes (counted)."""
from __future__ import annotations

import numpy as np
import pytest

from bake_helpers import assert_within_sample_tolerance, error_stats
from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.bake.abilities import bakers_with
from hao_addon.core.bake.alpha import SoupAlpha, expected_visibility
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.geometry import TriangleSoup

DIRS = 256
COARSE = 32  # directions of the checks that need no accuracy
H = 0.5  # the card's height over the floor


def floor() -> TriangleSoup:
    return scenes.grid_plane(4.0, 4, name="floor")


def card(alpha: float, size: float = 200.0) -> TriangleSoup:
    soup = scenes.grid_plane(size, 4, z=H, name="card")
    return TriangleSoup(soup.positions, None, "card", alpha=SoupAlpha(np.full(soup.face_count, alpha, np.float32)))


def stochastic_sigma(directions: int, through: float = 0.5) -> float:
    """The per-texel noise that keeping a surface with probability alpha adds (the GPU
    passes; the reference weighs each surface exactly): each direction's visibility is then
    a Bernoulli variable of variance p (1 - p), and a cosine-weighted mean of D / 2 such
    terms (the upper hemisphere's) has variance p (1 - p) E[cos^2] / E[cos]^2 / (D / 2),
    E[cos^2] / E[cos]^2 = (1/3) / (1/4) over the hemisphere."""
    return float(np.sqrt(through * (1.0 - through) * (4.0 / 3.0) / (directions / 2.0)))


def assert_within_alpha_tolerance(stats: dict, directions: int, method: str) -> None:
    """The bake's own tolerance (bake_helpers) for the reference; for a GPU pass the
    stochastic noise on top: RMSE at most its sigma (+10 % for the RMSE's own estimate over
    thousands of texels), bias within the structured bound plus 4 sigma / sqrt(n), every
    texel within 5 sigma."""
    if method == "reference":
        assert_within_sample_tolerance(stats, directions, method)
        return
    from bake_helpers import sigma
    noise = stochastic_sigma(directions)
    assert stats["rmse"] <= 1.1 * noise, (method, stats, noise)
    assert abs(stats["bias"]) <= sigma(directions) / 8 + 4 * noise / np.sqrt(stats["n"]), (method, stats)
    assert stats["max"] <= 5 * noise, (method, stats, noise)


def settings(method: str, **kw) -> BakeSettings:
    kw = {"directions": DIRS, **kw}
    return BakeSettings(size=16 if method == "reference" else 64, method=method, margin=0, **kw)


def test_expected_visibility_weighs_each_surface_by_its_alpha():
    assert expected_visibility([0.5], [1.0]) == 0.5
    assert expected_visibility([0.5, 0.5], [1.0, 1.0]) == 0.25  # two half cards: a quarter through
    assert expected_visibility([0.5, 1.0], [1.0, 0.0]) == 0.5  # the second beyond the max distance
    assert expected_visibility([], []) == 1.0


@pytest.mark.parametrize("method", bakers_with("alpha"))
@pytest.mark.parametrize("max_distance", [0.0, 2.0])
def test_half_alpha_card_over_a_floor_lets_half_the_light_through(gpu_context, method, max_distance):
    """Every ray from the floor crosses the (near-infinite) card once, at H / cos(theta):
    unlimited, accessibility 1 - a = 0.5; within d = 2 the rays that reach the card within d
    (cos(theta) > H / d) pass with 1 - a, the others are open: (H/d)^2 + 0.5 (1 - (H/d)^2)."""
    s = settings(method, max_distance=max_distance)
    res = bake(floor(), [card(0.5)], s, use_cache=False)
    open_share = (H / max_distance) ** 2 if max_distance else 0.0
    truth = open_share + 0.5 * (1.0 - open_share)
    stats = error_stats(res.ao, np.full(res.ao.shape, truth), res.covered)
    assert_within_alpha_tolerance(stats, DIRS, method)
    assert res.stats["alpha_faces"] > 0
    if method == "gather" and max_distance == 0.0:  # four depth taps a test: half the noise of one
        assert stats["rmse"] <= 0.6 * stochastic_sigma(DIRS), stats
    # (Coarse checks: a few directions show a solid sheet or no sheet at all.)
    opaque = bake(floor(), [card(0.5)], settings(method, max_distance=max_distance, alpha="off", directions=COARSE),
                  use_cache=False)
    assert opaque.ao[opaque.covered].mean() < truth - 0.3  # 'off': today's solid sheet
    clipped = bake(floor(), [card(0.5)], settings(method, max_distance=max_distance, alpha="clip", alpha_clip=0.6,
                                                  directions=COARSE), use_cache=False)
    assert clipped.ao[clipped.covered].min() > 0.99  # below the clip threshold: nothing stops the light


def _textured_card() -> tuple[TriangleSoup, TriangleSoup]:
    """A 2-unit card whose alpha image is 0 on its left half (u < 0.5) and 1 on its right,
    and the opaque cut-out mesh of its right half."""
    soup = scenes.grid_plane(2.0, 2, z=H, name="card")
    image = np.zeros((8, 8), np.float32)
    image[:, 4:] = 1.0
    alpha = SoupAlpha(np.ones(soup.face_count, np.float32), [image], np.zeros(soup.face_count, np.int64), soup.uvs)
    right = soup.positions[:, :, 0].mean(axis=1) > 0.0
    return TriangleSoup(soup.positions, None, "card", alpha=alpha), TriangleSoup(soup.positions[right], None, "cut")


@pytest.mark.parametrize("method", bakers_with("alpha"))
def test_a_clipped_texture_card_occludes_as_its_cut_out_mesh(gpu_context, method):
    textured, cut = _textured_card()
    s = settings(method, alpha="clip")
    by_alpha = bake(floor(), [textured], s, use_cache=False)
    by_mesh = bake(floor(), [cut], s, use_cache=False)
    stats = error_stats(by_alpha.ao, by_mesh.ao, by_alpha.covered)
    assert_within_sample_tolerance(stats, DIRS, method)
    solid = bake(floor(), [TriangleSoup(textured.positions, None, "solid")], s, use_cache=False)
    assert (solid.ao[solid.covered].mean() - by_mesh.ao[by_mesh.covered].mean()) < -0.05  # the half matters


def test_without_alpha_the_plain_passes_run_counted(gpu_context):
    for method in bakers_with("alpha", gpu_only=True):
        res = bake(floor(), [scenes.grid_plane(2.0, 2, z=H)], settings(method, directions=16), use_cache=False)
        assert res.stats["alpha_faces"] == 0 and res.stats["alpha_passes_skipped"] == 16
        assert "alpha_passes" not in res.stats


def _card_material(kind: str):
    """A material as Blender's glTF importer makes them: Alpha a value ('value'), an Image
    Texture's alpha wired to it ('image', BLEND), or through a Math node ('mask', MASK)."""
    import bpy
    material = bpy.data.materials.new(f"card_{kind}")
    if bpy.app.version < (5, 0, 0):  # every material uses nodes from 5.0 (use_nodes deprecated)
        material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    bsdf = next(n for n in nodes if n.type == 'BSDF_PRINCIPLED')
    if kind == "value":
        bsdf.inputs['Alpha'].default_value = 0.5
        return material
    image = bpy.data.images.new(f"alpha_{kind}", 4, 4, alpha=True)
    image.pixels.foreach_set(np.tile([1.0, 1.0, 1.0, 0.25], 16).astype(np.float32))
    texture = nodes.new('ShaderNodeTexImage')
    texture.image = image
    if kind == "image":
        links.new(texture.outputs['Alpha'], bsdf.inputs['Alpha'])
    else:
        math = nodes.new('ShaderNodeMath')
        math.operation = 'GREATER_THAN'
        links.new(texture.outputs['Alpha'], math.inputs[0])
        links.new(math.outputs[0], bsdf.inputs['Alpha'])
    return material


@pytest.mark.parametrize("kind,through", [("value", 0.5), ("image", 0.75), ("mask", 0.75)])
def test_blender_materials_let_their_alpha_through(scene, kind, through):
    """A card's material alpha reaches the bake of the floor under it: 0.5 as a value, 0.25
    from an image (directly, or through a Math node: its cut-off is the Alpha Clip setting,
    so 'blend' reads the image's alpha as it is)."""
    import bpy
    from conftest import select_only, small_settings, soup_to_object
    from hao_addon.blender.bake_job import BakeJob

    floor_obj = soup_to_object(floor(), "floor")
    card_obj = soup_to_object(scenes.grid_plane(200.0, 4, z=H, name="card"), "card")
    card_obj.data.materials.append(_card_material(kind))
    select_only(floor_obj)
    settings = small_settings(scene, occluders='visible', directions=DIRS, size=64, margin=0, method='gather')
    job = BakeJob(settings.to_request([floor_obj]), bpy.context.evaluated_depsgraph_get)
    job.run()
    result = job.results[0][2]
    stats = error_stats(result.ao, np.full(result.ao.shape, through), result.covered)
    assert stats["rmse"] <= 1.1 * stochastic_sigma(DIRS, through) and abs(stats["bias"]) < 0.02, stats
    assert result.stats["alpha_faces"] > 0


# -- issue 38: alpha a user's scene may hold ---------------------------------------------------------

def _card_scene(kind: str):
    """The floor under a card whose material is of `kind`; returns (floor, card, material)."""
    from conftest import select_only, soup_to_object
    floor_obj = soup_to_object(floor(), "floor")
    card_obj = soup_to_object(scenes.grid_plane(200.0, 4, z=H, name="card"), "card")
    material = _card_material("value" if kind in ("nan", "emission") else "image")
    if kind == "nan":
        next(n for n in material.node_tree.nodes if n.type == 'BSDF_PRINCIPLED').inputs['Alpha'].default_value = \
            float("nan")
    elif kind == "emission":
        nodes = material.node_tree.nodes
        output = next(n for n in nodes if n.type == 'OUTPUT_MATERIAL')
        material.node_tree.links.new(nodes.new('ShaderNodeEmission').outputs[0], output.inputs['Surface'])
    elif kind == "missing":
        image = next(n for n in material.node_tree.nodes if n.type == 'TEX_IMAGE').image
        image.filepath = "/nonexistent/folder/alpha_mask.png"
        image.source = 'FILE'
        image.reload()
    card_obj.data.materials.append(material)
    select_only(floor_obj)
    return floor_obj, card_obj, material


def _bake_floor(scene, floor_obj):
    import bpy
    from conftest import small_settings
    from hao_addon.blender.bake_job import BakeJob
    settings = small_settings(scene, occluders='visible', directions=16, size=32, margin=0, method='gather')
    job = BakeJob(settings.to_request([floor_obj]), bpy.context.evaluated_depsgraph_get)
    job.run()
    return job.results[0][2]


def test_a_missing_alpha_image_is_an_error_naming_it_and_its_material(scene):
    """Before: 'internal error (AttributeError ...)'. A map baked as if the card were opaque
    (or absent) would be wrong, so it is refused; Alpha off bakes without it."""
    from hao_addon.core.errors import BakeInputError
    floor_obj, _card, material = _card_scene("missing")
    with pytest.raises(BakeInputError, match=r"the image 'alpha_image' \(/nonexistent/folder/alpha_mask.png\) that "
                                             rf"gives material '{material.name}' its alpha cannot be read"):
        _bake_floor(scene, floor_obj)
    scene.hao_bake.alpha = 'off'
    assert _bake_floor(scene, floor_obj).covered.any()


def test_a_nan_alpha_is_refused(scene):
    from hao_addon.core.errors import BakeInputError
    floor_obj, _card, material = _card_scene("nan")
    with pytest.raises(BakeInputError, match=f"material '{material.name}' has an Alpha of nan"):
        _bake_floor(scene, floor_obj)


def test_a_material_that_is_not_principled_is_opaque_with_a_warning(scene):
    floor_obj, _card, material = _card_scene("emission")
    result = _bake_floor(scene, floor_obj)
    assert f"'card': material '{material.name}' is not a Principled BSDF: read as opaque" in result.stats["warnings"]
    assert result.ao[result.covered].mean() < 0.2  # the card above covers the floor's sky


def test_a_large_alpha_texture_is_read_at_the_size_the_bake_resolves(scene, monkeypatch, tmp_path):
    """A 16k alpha texture took 6.9 GB for a 64^2 bake. Read no finer than max(MAX_ALPHA_SIDE,
    4 x size): here the limit is lowered so a 512^2 image stands for the 16k one."""
    import bpy
    from hao_addon.blender import material_alpha
    monkeypatch.setattr(material_alpha, "MAX_ALPHA_SIDE", 64)
    image = bpy.data.images.new("big_alpha", 512, 256, alpha=True)
    pixels = np.ones((256, 512, 4), np.float32)
    pixels[:, :256, 3] = 0.0  # the left half lets everything through
    image.pixels.foreach_set(pixels.ravel())
    image.filepath_raw, image.file_format = str(tmp_path / "big_alpha.png"), 'PNG'
    image.save()
    image.source = 'FILE'
    image.reload()
    small = material_alpha.image_alpha(image, "m", bake_size=16)
    assert small.shape == (32, 64)  # halved until its longer side is within 64
    assert np.allclose(small[:, :28], 0.0) and np.allclose(small[:, 36:], 1.0)
    assert material_alpha.image_alpha(image, "m", bake_size=128).shape == (256, 512)  # 4 x 128 covers it
    assert "big_alpha" in bpy.data.images and len([i for i in bpy.data.images if i.name.startswith("big")]) == 1
