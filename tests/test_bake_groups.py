# SPDX-License-Identifier: GPL-3.0-or-later
"""Bake groups matched by name (issue 30 item 1): two low/high pairs that overlap in space bake
in one run as each pair alone would, without moving anything; names that match nothing are
listed; 'all' lets every group occlude every other."""
from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import bpy
from conftest import run_hao, select_only, small_settings, soup_to_object
from hao_addon.core import scenes
from hao_addon.core.bake.name_groups import match_groups, role_of

ROOT = Path(__file__).resolve().parent.parent
BAKE = ["--size", "64", "--directions", "32", "--margin", "2"]


# -- matching names (core) -------------------------------------------------------------------------

def test_names_match_by_suffix_duplicate_number_case_and_collection():
    found = match_groups([("crate_low", ""), ("Crate_HIGH", ""), ("crate_high.001", ""), ("rock_low", ""),
                          ("pebble", "rock_high"), ("rock_high", ""), ("lamp", ""), ("bolt_high", ""),
                          ("_low", "")])
    groups = {g.name: g for g in found.groups}
    assert sorted(groups) == ["crate", "rock"]
    assert groups["crate"].lows == ("crate_low",) and groups["crate"].highs == ("Crate_HIGH", "crate_high.001")
    assert groups["rock"].highs == ("pebble", "rock_high")  # the collection names the pebble
    assert found.unmatched == ("lamp", "_low") and found.orphans == ("bolt_high",)


def test_custom_suffixes_and_their_refusal():
    assert role_of("tree.LP", ".lp", ".hp") == ("low", "tree")
    assert role_of("tree_lowpoly", "_low", "_high") is None  # a suffix ends the name (before '.001')
    with pytest.raises(ValueError, match="must differ"):
        match_groups([("a_low", "")], "_x", "_X")


# -- baking groups (command line and panel) ----------------------------------------------------------

def _pair_objects(scene, names: set[str]) -> None:
    """Two Selected-to-Active pairs in the same place: 'crate' (a ball on a floor, the floor
    a duplicate-numbered part) and 'rock' (another ball, a pebble in a collection named
    rock_high, a floor just below), plus an unmatched mesh and an orphan high-poly; only the
    names in `names` are made."""
    made = {
        "crate_low": lambda: scenes.grid_plane(4.0, 4, z=1.2, name="crate_low"),
        "crate_high": lambda: scenes.uv_sphere(0.5, (0, 0, 0.5), 32, 16, name="crate_high"),
        "crate_high.001": lambda: scenes.grid_plane(200.0, 16, name="crate_high.001"),
        "rock_low": lambda: scenes.grid_plane(4.0, 4, z=1.0, name="rock_low"),
        "rock_high": lambda: scenes.uv_sphere(0.4, (0.9, 0, 0.39), 32, 16, name="rock_high"),
        "rock_high.001": lambda: scenes.grid_plane(200.0, 16, z=-0.01, name="rock_high.001"),
        "pebble": lambda: scenes.uv_sphere(0.3, (-0.9, 0.5, 0.29), 24, 12, name="pebble"),
        "lamp": lambda: scenes.uv_sphere(0.2, (5, 5, 3), 8, 4, name="lamp"),
        "bolt_high": lambda: scenes.uv_sphere(0.1, (8, 0, 0.1), 8, 4, name="bolt_high"),
    }
    for name in made:
        if name not in names:
            continue
        obj = soup_to_object(made[name](), name)
        if name == "pebble":
            collection = bpy.data.collections.new("rock_high")
            scene.collection.children.link(collection)
            scene.collection.objects.unlink(obj)
            collection.objects.link(obj)


def _blend(scene, path: Path, names: set[str]) -> Path:
    _pair_objects(scene, names)
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    return path


def _hao(*args, tmp: Path) -> subprocess.CompletedProcess:
    done = run_hao(args, cwd=tmp, timeout=300)
    assert done.returncode == 0, done.stderr
    return done


def _red(path: Path) -> np.ndarray:
    from bake_helpers import load_image_rgba
    return load_image_rgba(path)[..., 0].ravel()


ALL = {"crate_low", "crate_high", "crate_high.001", "rock_low", "rock_high", "rock_high.001", "pebble", "lamp",
       "bolt_high"}


@pytest.fixture(scope="module")
def group_runs(tmp_path_factory):
    """The scene baked by groups (group occluders 'group' and 'all'), and each pair alone
    from a file that holds just that pair."""
    from conftest import clear_blend_data
    tmp = tmp_path_factory.mktemp("groups")
    clear_blend_data()
    both = _blend(bpy.context.scene, tmp / "both.blend", ALL)
    crate = _blend(bpy.context.scene, tmp / "crate.blend", {"crate_low", "crate_high", "crate_high.001"})
    rock = _blend(bpy.context.scene, tmp / "rock.blend", {"rock_low", "rock_high", "rock_high.001", "pebble"})
    runs = {}
    for mode in ("group", "all"):
        (tmp / mode).mkdir()
        done = _hao("bake", both, "--out", tmp / mode / "{object}.png", "--match-names", "--group-occluders", mode,
                    "--json", tmp / f"{mode}.json", *BAKE, tmp=tmp)
        runs[mode] = (json.loads((tmp / f"{mode}.json").read_text()), done.stderr)
    (tmp / "alone").mkdir()
    _hao("bake", crate, "--out", tmp / "alone" / "crate_low.png", "--object", "crate_low", "--high-poly",
         "crate_high", "--high-poly", "crate_high.001", "--occluders", "target", *BAKE, tmp=tmp)
    _hao("bake", rock, "--out", tmp / "alone" / "rock_low.png", "--object", "rock_low", "--high-poly", "rock_high",
         "--high-poly", "rock_high.001", "--high-poly", "pebble", "--occluders", "target", *BAKE, tmp=tmp)
    return tmp, runs


def test_groups_bake_as_each_pair_alone(scene, group_runs):
    """Overlapping pairs baked by name in one run equal each pair baked from a file of its own
    (the other pair's meshes neither found by the rays nor occluding)."""
    tmp, runs = group_runs
    report, _stderr = runs["group"]
    groups = {name: (g["low"], sorted(g["high"])) for name, g in report["settings"]["groups"].items()}
    assert groups == {"crate": (["crate_low"], ["crate_high", "crate_high.001"]),
                      "rock": (["rock_low"], ["pebble", "rock_high", "rock_high.001"])}
    assert sorted(Path(p).name for p in report["outputs"]) == ["crate_low.png", "rock_low.png"]
    for name in ("crate_low", "rock_low"):
        grouped, alone = _red(tmp / "group" / f"{name}.png"), _red(tmp / "alone" / f"{name}.png")
        np.testing.assert_array_equal(grouped, alone)
        assert grouped.min() < 0.7  # the relief is there (the balls darken the floor around them)


def test_unmatched_and_orphan_names_are_listed_never_guessed(scene, group_runs):
    _tmp, runs = group_runs
    report, stderr = runs["group"]
    warnings = [w for w in report["warnings"] if w.startswith("bake groups:")]
    assert any("'lamp'" in w and "match no group" in w for w in warnings), warnings
    assert any("'bolt_high'" in w and "no low-poly" in w for w in warnings), warnings
    assert "hao: warning: bake groups:" in stderr
    assert sorted(o["name"] for o in report["objects"]) == ["crate_low", "rock_low"]


def test_group_occluders_all_lets_the_other_groups_occlude(scene, group_runs):
    """With 'all' the rock's ball and pebble (and the lamp) also occlude the crate's floor:
    darker where they stand, never lighter anywhere (beyond 16-bit rounding)."""
    tmp, _runs = group_runs
    own, every = _red(tmp / "group" / "crate_low.png"), _red(tmp / "all" / "crate_low.png")
    assert (every <= own + 1e-4).all()
    assert (own - every).max() > 0.05


def test_the_panel_bakes_the_selected_meshes_by_name(scene, tmp_path):
    """Match Names in the panel: the selection's names (and collections) make the groups; each
    low-poly gets its own image, the unmatched names a warning in the job's notes."""
    from hao_addon.blender.bake_job import BakeJob
    _pair_objects(scene, ALL)
    select_only(*[o for o in scene.objects if o.type == 'MESH'])
    settings = small_settings(scene, match_names=True, size=64, directions=16, margin=2)
    request = settings.to_request([o for o in scene.objects if o.select_get()], None)
    assert sorted(o.name for o in request.targets) == ["crate_low", "rock_low"]
    assert any("'lamp'" in note for note in request.notes)
    job = BakeJob(request, bpy.context.evaluated_depsgraph_get)
    job.run()
    job.commit()
    assert sorted(im.name for im in job.committed) == ["crate_low_AO", "rock_low_AO"]


def test_a_group_without_high_poly_bakes_its_own_parts(scene):
    """'wall_low' and 'wall_low.001' (a ball over the wall) form one group without highs: each
    bakes as itself with the group's other part occluding, and the unmatched ball beside them
    does not occlude (as the two selected alone with Occluders: Selected)."""
    from hao_addon.blender.bake_job import BakeJob
    wall = soup_to_object(scenes.grid_plane(4.0, 8, name="wall_low"), "wall_low")
    ball = soup_to_object(scenes.uv_sphere(0.5, (0, 0, 0.6), 24, 12, name="wall_low.001"), "wall_low.001")
    beside = soup_to_object(scenes.uv_sphere(0.5, (1.2, 0, 0.6), 24, 12, name="other"), "other")

    def baked(targets: list, **kw) -> dict:
        select_only(*targets)
        settings = small_settings(scene, size=64, directions=32, margin=2, **kw)
        job = BakeJob(settings.to_request(targets, None), bpy.context.evaluated_depsgraph_get)
        job.run()
        return {obj.name: result.ao for obj, _uv, result in job.results}

    grouped = baked([wall, ball, beside], match_names=True)
    assert sorted(grouped) == ["wall_low", "wall_low.001"]
    from hao_addon.bake import clear_cache
    clear_cache()  # baked again, not found in the cache
    pair = baked([wall, ball], occluders="selected")
    np.testing.assert_array_equal(grouped["wall_low"], pair["wall_low"])
    assert grouped["wall_low"].min() < 0.5  # the ball darkens the wall under it


def test_groups_bake_into_one_texture_set_when_asked(scene, tmp_path):
    """Two groups whose low-polys' islands sit side by side (u < 0.5, u > 0.5): one shared
    image, each half its own group's bake, texel for texel."""
    from hao_addon.blender.bake_job import BakeJob
    from hao_addon.core.geometry import TriangleSoup

    def low(name: str, x: float, half: int) -> object:
        soup = scenes.grid_plane(2.0, 4, z=1.2, name=name)
        uvs = soup.uvs * [0.5, 1.0] + [0.5 * half, 0.0]
        return soup_to_object(TriangleSoup(soup.positions + [x, 0, 0], uvs, name), name)

    low("a_low", 0.0, 0)
    low("b_low", 10.0, 1)
    soup_to_object(scenes.uv_sphere(0.5, (0, 0, 0.5), 24, 12, name="a_high"), "a_high")
    soup_to_object(scenes.grid_plane(4.0, 4, name="a_high.001"), "a_high.001")
    soup_to_object(scenes.uv_sphere(0.4, (10.3, 0, 0.4), 24, 12, name="b_high"), "b_high")
    soup_to_object(TriangleSoup(scenes.grid_plane(4.0, 4).positions + [10, 0, 0], None, "b_high.001"), "b_high.001")
    meshes = [o for o in scene.objects if o.type == 'MESH']
    select_only(*meshes)

    def run(**kw):
        settings = small_settings(scene, match_names=True, size=64, directions=32, margin=2, **kw)
        job = BakeJob(settings.to_request(meshes), bpy.context.evaluated_depsgraph_get)
        job.run()
        return job

    shared = run(texture_set=True)
    assert len(shared.baked()) == 1 and shared.baked()[0][1] == "TextureSet"
    merged = shared.baked()[0][2]
    singles = {obj.name: result for obj, _uv, result in run().results}
    for name, half in (("a_low", slice(0, 32)), ("b_low", slice(32, 64))):
        own = singles[name]
        mask = own.covered[:, half]
        np.testing.assert_array_equal(merged.ao[:, half][mask], own.ao[:, half][mask])
    assert sorted(e["name"] for e in shared.summary()) == ["a_low", "b_low"]
