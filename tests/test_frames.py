# SPDX-License-Identifier: GPL-3.0-or-later
"""Frame sequences (issue 13 item 7): one map per frame of a deforming mesh, {frame} in the
file names; a frame whose evaluated geometry equals an earlier one reuses its bake; the
scene's frame comes back afterwards, also when cancelled."""
from __future__ import annotations

import json
import os
from dataclasses import replace
from pathlib import Path

import numpy as np

import bpy
from conftest import run_hao
from hao_addon.bake import clear_cache
from hao_addon.blender.bake_job import BakeJob
from hao_addon.blender.bake_request import BakeRequest
from hao_addon.core.bake.settings import BakeSettings

ROOT = Path(__file__).resolve().parent.parent
CESIUM = ROOT / "tests" / "data" / "CesiumMan.glb"
SETTINGS = BakeSettings(size=128, directions=16, margin=2)


def cesium_man():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=str(CESIUM))
    return bpy.data.objects["Cesium_Man"]


def run_job(request: BakeRequest) -> BakeJob:
    job = BakeJob(request, bpy.context.evaluated_depsgraph_get)
    job.run()
    job.commit()
    return job


def test_each_frame_of_the_walk_equals_a_single_bake_at_that_frame(gpu_context, tmp_path):
    man = cesium_man()
    scene = bpy.context.scene
    scene.frame_set(3)
    frames = [1, 9, 17]
    job = run_job(BakeRequest([man], SETTINGS, filepath=str(tmp_path / "man_{frame}.exr"), frames=frames))
    assert scene.frame_current == 3  # restored
    assert sorted(os.listdir(tmp_path)) == [f"man_{f:04d}.exr" for f in frames]
    assert [e["frame"] for e in job.frame_results] == frames and not any(e["reused"] for e in job.frame_results)
    assert [e["outputs"] for e in job.frame_results] == [[str(tmp_path / f"man_{f:04d}.exr")] for f in frames]
    files = [(tmp_path / f"man_{f:04d}.exr").read_bytes() for f in frames]
    assert files[0] != files[1]  # the walk changes the occlusion
    single_dir = tmp_path / "single"
    single_dir.mkdir()
    for frame, baked in zip(frames, files):
        clear_cache()  # a fresh bake, not the sequence's cached one
        scene.frame_set(frame)
        run_job(BakeRequest([man], SETTINGS, filepath=str(single_dir / f"{frame}.exr")))
        assert (single_dir / f"{frame}.exr").read_bytes() == baked  # 32-bit float: the same map


def test_a_sequence_keeps_no_frame_maps_in_memory(gpu_context, tmp_path):
    """Each frame is written when it is done and its maps dropped: what the job holds after N
    frames is one frame's maps (its last results), whatever N (issue 28: +8 MB a frame)."""
    man = cesium_man()
    job = run_job(BakeRequest([man], replace(SETTINGS, bent_normals=True), filepath=str(tmp_path / "{frame}.png"),
                              map_paths={"bent": str(tmp_path / "bent_{frame}.png")}, frames=[1, 5, 9, 13]))
    assert len(os.listdir(tmp_path)) == 8
    held = [value for entry in job.frame_results for value in entry.values()]
    assert not any(isinstance(v, np.ndarray) or hasattr(v, "ao") for v in held)  # no maps per frame
    assert len(job.results) == 1 and job.maps["bent"] == {}  # the last frame's result only


def test_a_static_mesh_over_ten_frames_bakes_once(gpu_context, tmp_path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_monkey_add()
    clear_cache()
    job = run_job(BakeRequest([bpy.context.active_object], SETTINGS, filepath=str(tmp_path / "m.png"),
                              frames=list(range(1, 11))))
    assert [e["reused"] for e in job.frame_results] == [False] + [True] * 9
    assert len(os.listdir(tmp_path)) == 10 and (tmp_path / "m_0010.png").is_file()
    first = (tmp_path / "m_0001.png").read_bytes()
    assert all((tmp_path / f"m_{f:04d}.png").read_bytes() == first for f in range(2, 11))


def test_cancelling_a_sequence_restores_the_frame_and_keeps_the_finished_frames(gpu_context, tmp_path):
    man = cesium_man()
    scene = bpy.context.scene
    scene.frame_set(4)
    clear_cache()
    job = BakeJob(BakeRequest([man], SETTINGS, filepath=str(tmp_path / "{frame}.png"), frames=[1, 2, 3]),
                  bpy.context.evaluated_depsgraph_get)
    steps = job.steps()
    while not job.written:  # frame 1's bake, its floor check and its file
        next(steps)
    for _ in range(3):  # into the second frame
        next(steps)
    assert scene.frame_current != 4
    steps.close()
    job.cancel()
    # Frame 1 finished and stays (complete, listed); nothing of frame 2, no temporary file.
    assert scene.frame_current == 4 and os.listdir(tmp_path) == ["0001.png"]
    assert job.written == [str(tmp_path / "0001.png")]
    assert job.written_note() == "frame 1 (1 file) is written"


def test_cli_frames_and_report(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    done = run_hao(["bake", CESIUM, "--frames", "1-9:4", "--size", "64", "--directions", "8",
                    "--out", out / "walk.{frame}.png", "--json", tmp_path / "r.json"], cwd=tmp_path, timeout=300)
    assert done.returncode == 0, done.stderr
    assert sorted(os.listdir(out)) == ["walk.0001.png", "walk.0005.png", "walk.0009.png"]
    report = json.loads((tmp_path / "r.json").read_text())
    assert [f["frame"] for f in report["frames"]] == [1, 5, 9] and all(f["seconds"] > 0 for f in report["frames"])
    assert report["outputs"] == [str(out / f"walk.{f:04d}.png") for f in (1, 5, 9)]
    assert "x 3 frames (0 reused" in done.stdout
