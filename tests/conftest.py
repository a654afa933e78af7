# SPDX-License-Identifier: GPL-3.0-or-later
"""Shared fixtures. Tests run headless through the bpy wheel on whatever OpenGL the machine
has (llvmpipe in CI). GPU tests do not skip when the context fails: CI must see it.

The numpy tier (NUMPY_TIER: the core floor's tests) needs no bpy: in an environment without
the wheel (numpy, xatlas and pytest only) `pytest tests` runs those files alone, and
tests/test_numpy_tier.py shows that they pass with bpy, gpu and mathutils unimportable."""
from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
DATA = Path(__file__).resolve().parent / "data"
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

try:
    import bpy  # noqa: E402
except ImportError:  # the numpy tier alone
    bpy = None

# Test files of the numpy floor (hao_addon/core): they import no bpy, gpu or mathutils.
def cli_env(cwd: Path | None = None, **extra: str) -> dict:
    """The environment a child `python -m hao_addon` gets in tests: this checkout on its path
    and, given a folder, its temporary files there (where tests look for leftovers)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    if cwd is not None:
        env.update(TMPDIR=str(cwd), TEMP=str(cwd), TMP=str(cwd))
    return {**env, **extra}


def run_hao(args, cwd: Path | None = None, env: dict | None = None, timeout: float = 600,
            **kw) -> subprocess.CompletedProcess:
    """The shared command-line runner: `python -m hao_addon ARGS` as a child process, its
    output captured as text, in `cwd` (default: the checkout) with cli_env(cwd) plus `env`."""
    return subprocess.run([sys.executable, "-m", "hao_addon", *map(str, args)], capture_output=True, text=True,
                          env=cli_env(cwd, **(env or {})), cwd=cwd or ROOT, timeout=timeout, **kw)


NUMPY_TIER = ("test_core_math.py", "test_output_files.py", "test_spheres.py", "test_unwrap.py", "test_numpy_tier.py")

_EXIT_STATUS = 0

# Tests of CPU code that is the same on every Blender release (the ray-traced reference, a
# process's memory), each tens of seconds, are marked `release_independent`: they run on
# every release but the oldest, which CI runs too (tools/test.sh), to keep CI within its time.
OLDEST_RELEASE = (4, 2)


def pytest_configure(config):
    config.addinivalue_line("markers", "release_independent: CPU-only and release-independent; skipped on the "
                                       "oldest release (run on the newest)")


def pytest_ignore_collect(collection_path, config):
    """Without bpy, everything but the numpy tier."""
    if bpy is None and collection_path.suffix == ".py" and collection_path.name not in NUMPY_TIER:
        return True
    return None


def pytest_collection_modifyitems(config, items):
    if bpy is None or tuple(bpy.app.version[:2]) != OLDEST_RELEASE:
        return
    skip = pytest.mark.skip(reason="release-independent CPU test: run on the newest release (CI time)")
    for item in items:
        if "release_independent" in item.keywords:
            item.add_marker(skip)


def pytest_sessionfinish(session, exitstatus):
    global _EXIT_STATUS
    _EXIT_STATUS = int(exitstatus)


def pytest_unconfigure(config):
    """After the summary is printed: skip bpy 4.2's crashing module teardown (see compat)."""
    from hao_addon import compat
    if bpy is not None and compat.module_exit_may_crash():
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_EXIT_STATUS)


@pytest.fixture(scope="session")
def gpu_context():
    from hao_addon.gpu.context import ensure_gpu_context
    ensure_gpu_context()
    return True


@pytest.fixture
def renderer(gpu_context):
    """A fresh HaoRenderer (viewport AO passes), freed after the test."""
    from hao_addon.gpu.hao_renderer import HaoRenderer
    r = HaoRenderer()
    yield r
    r.free()


@pytest.fixture(scope="session")
def addon():
    """The repository root loaded as an add-on package ('hao_ext') and registered, the way
    Blender loads the extension (relative imports across operators/ and hao_addon/)."""
    spec = importlib.util.spec_from_file_location("hao_ext", ROOT / "__init__.py",
                                                  submodule_search_locations=[str(ROOT)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["hao_ext"] = module
    spec.loader.exec_module(module)
    module.register()
    yield module
    module.unregister()


def clear_blend_data() -> None:
    """Empty scene: remove objects, meshes, materials, images and extra UV-less leftovers."""
    for coll in (bpy.data.objects, bpy.data.meshes, bpy.data.materials, bpy.data.images,
                 bpy.data.cameras, bpy.data.lights):
        for item in list(coll):
            if getattr(item, "type", None) == 'RENDER_RESULT':
                continue
            coll.remove(item)
    bpy.context.view_layer.update()


@pytest.fixture
def scene(addon, gpu_context):
    """A clean scene with the add-on registered and a GPU context."""
    clear_blend_data()
    from hao_addon.bake import clear_cache
    clear_cache()
    settings = bpy.context.scene.hao_bake
    for prop in settings.bl_rna.properties:
        if prop.identifier != "rna_type":
            settings.property_unset(prop.identifier)  # back to the defaults
    yield bpy.context.scene
    clear_blend_data()


def soup_to_object(soup, name: str | None = None, uv: bool = True):
    """Link a TriangleSoup into the scene as a mesh object (shared vertices merged exactly)."""
    pos = soup.positions.reshape(-1, 3)
    verts, inverse = np.unique(pos, axis=0, return_inverse=True)
    faces = inverse.reshape(-1, 3)
    mesh = bpy.data.meshes.new(name or soup.name)
    mesh.from_pydata(verts.tolist(), [], faces.tolist())
    if uv and soup.uvs is not None:
        layer = mesh.uv_layers.new(name="UVMap")
        layer.uv.foreach_set("vector", soup.uvs.reshape(-1).astype(np.float32))
    mesh.update()
    obj = bpy.data.objects.new(name or soup.name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def select_only(*objs) -> None:
    for o in bpy.context.scene.objects:
        o.select_set(False)
    for o in objs:
        o.select_set(True)
    if objs:
        bpy.context.view_layer.objects.active = objs[0]


def small_settings(scene, **kw):
    """A small, quick bake (128^2, 32 directions, margin 4) with the given overrides."""
    s = scene.hao_bake
    s.size, s.directions, s.margin = 128, 32, 4
    for k, v in kw.items():
        setattr(s, k, v)
    return s
