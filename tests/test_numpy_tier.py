# SPDX-License-Identifier: GPL-3.0-or-later
"""The numpy tier (conftest.NUMPY_TIER: the core floor's tests) runs where Blender is not:
with bpy, gpu and mathutils unimportable, `pytest tests` collects exactly the tier and passes.
A core module that starts importing bpy, or a tier test that starts needing it, fails this."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from conftest import NUMPY_TIER, ROOT, bpy

BLOCKED = ("bpy", "gpu", "mathutils", "bmesh", "gpu_extras", "bl_math")


@pytest.mark.release_independent  # whether the core imports Blender does not depend on which Blender
def test_the_numpy_tier_passes_without_blender(tmp_path):
    if bpy is None:  # this run is the tier itself
        return
    for name in BLOCKED:
        (tmp_path / name).mkdir()
        (tmp_path / name / "__init__.py").write_text(f"raise ImportError('{name}: blocked, no Blender here')\n")
    env = {**os.environ, "PYTHONPATH": str(tmp_path)}
    # (The tier's release_independent tests, seconds each of the same numpy code, run in the main suite.)
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-k", "not release_independent",
                           str(ROOT / "tests")],
                          capture_output=True, text=True, env=env, cwd=tmp_path, timeout=600)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    files = {line.split("::")[0].rsplit("/", 1)[-1] for line in subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "--co", "-p", "no:cacheprovider", str(ROOT / "tests")],
        capture_output=True, text=True, env=env, cwd=tmp_path, timeout=120).stdout.splitlines() if "::" in line}
    assert files == set(NUMPY_TIER)  # the whole tier, and nothing that needs Blender
