# SPDX-License-Identifier: GPL-3.0-or-later
"""Re-bake Changed where users meet it (issue 42): the command line's --rebake-changed against
the previous output file and the record beside it, the panel's Re-bake Changed button and
its Auto Re-bake (off by default). The re-baked map against a full bake of the edited scene:
each texel within the report's bound of it (the GPU gather bakes its cells bit for bit as a
whole bake does, tests/test_rebake.py); what cannot be kept is re-baked in full and says why."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

import bpy
from bake_helpers import load_image_rgba, write_obj
from conftest import run_hao, select_only, soup_to_object
from hao_addon.core import scenes
from hao_addon.rebake import record_path

BAKE = ["--object", "floor", "--size", "64", "--directions", "32", "--margin", "2", "--method", "gather",
        "--json", "-"]


def floor_and_ball(shift: float = 0.0):
    floor = scenes.grid_plane(8.0, 16, name="floor")
    ball = scenes.uv_sphere(0.4, (1.5 + shift, 1.0, 0.4), 16, 8, name="ball")
    return floor, ball


def bake_cli(tmp: Path, source: Path, out: Path, *extra) -> dict:
    done = run_hao(["bake", source, "--out", out, *BAKE, *extra], cwd=tmp)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout)


def gray(path: Path) -> np.ndarray:
    return load_image_rgba(path)[..., 0].astype(np.float64)


def test_cli_rebakes_what_changed_against_the_file_and_its_record(tmp_path):
    source, out, full_out = tmp_path / "scene.obj", tmp_path / "ao.exr", tmp_path / "full.exr"
    write_obj(source, {s.name: s for s in floor_and_ball()})
    first = bake_cli(tmp_path, source, out, "--rebake-changed")["objects"][0]["rebake"]
    assert first["full"] and first["why"] == "no earlier bake of this target"
    assert Path(record_path(str(out))).is_file()
    write_obj(source, {s.name: s for s in floor_and_ball(shift=0.1)})  # the ball nudged
    report = bake_cli(tmp_path, source, out, "--rebake-changed")
    rebake = report["objects"][0]["rebake"]
    assert not rebake["full"] and 0 < rebake["rebaked"] < rebake["covered"]
    assert rebake["how"] == "by difference"  # the record keeps the scene before the edit
    assert report["objects"][0]["error"]["rmse"] > 0.0
    bake_cli(tmp_path, source, full_out)
    diff = np.abs(gray(out) - gray(full_out))
    assert diff.max() <= rebake["kept_bound"] + 1e-6, (diff.max(), rebake)
    assert (diff > 1e-6).sum() <= rebake["covered"] - rebake["rebaked"]  # the re-baked texels: equal
    # (Nothing changed and a changed setting: tests/test_rebake.py, without a process each.)
    Path(record_path(str(out))).write_bytes(b"not a record")
    broken = bake_cli(tmp_path, source, out, "--rebake-changed", "--seed", "9")["objects"][0]["rebake"]
    assert broken["full"] and broken["why"] == "no earlier bake of this target"
    refused = run_hao(["bake", source, "--out", out, *BAKE[:-2], "--rebake-changed", "--verify", "10"], cwd=tmp_path)
    assert refused.returncode == 2 and "hao: error:" in refused.stderr and "verify" in refused.stderr


def test_panel_rebake_changed_and_auto_rebake(scene, addon):
    auto_rebake = sys.modules[f"{addon.__name__}.operators.auto_rebake"]
    floor_soup, ball_soup = floor_and_ball()
    floor, ball = soup_to_object(floor_soup, "floor"), soup_to_object(ball_soup, "ball")
    settings = scene.hao_bake
    settings.size, settings.directions, settings.margin, settings.method = 64, 32, 2, 'GATHER'
    assert not settings.auto_rebake  # off by default
    select_only(floor)
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    image = bpy.data.images["floor_AO"]

    def pixels() -> np.ndarray:
        px = np.empty(64 * 64 * 4, np.float32)
        image.pixels.foreach_get(px)
        return px.reshape(64, 64, 4)[..., 0].copy()

    first = pixels()
    ball.location.x += 0.1
    bpy.context.view_layer.update()
    assert not bpy.app.timers.is_registered(auto_rebake.run_auto_rebake)  # Auto Re-bake is off
    assert bpy.ops.object.hao_bake_ao(changed_only=True) == {'FINISHED'}
    changed = pixels()
    assert 0 < (np.abs(changed - first) > 1e-6).sum() < 0.9 * changed.size
    settings.auto_rebake = True
    ball.location.x += 0.1
    bpy.context.view_layer.update()
    assert bpy.app.timers.is_registered(auto_rebake.run_auto_rebake)
    assert auto_rebake.run_auto_rebake() is None  # the timer's run (background Blender runs no timers)
    assert (np.abs(pixels() - changed) > 1e-6).any()
    select_only(ball)  # never baked: no automatic bake starts for it
    assert auto_rebake.ready_targets(bpy.context) == []
