# SPDX-License-Identifier: GPL-3.0-or-later
"""Shader loader and GPU hygiene: compile errors carry the driver's message, every shader file
compiles, registration touches no GPU, and nothing is left behind."""
from __future__ import annotations

import gpu
import pytest

from hao_addon.gpu import shaders


def test_compile_error_carries_driver_message(gpu_context):
    info = gpu.types.GPUShaderCreateInfo()
    info.local_group_size(1, 1, 1)
    info.compute_source("void main() { undefined_function_xyz(1); }")
    with pytest.raises(shaders.ShaderCompileError) as err:
        shaders.compile_with_log(info, "broken")
    text = str(err.value)
    assert "broken" in text and "undefined_function_xyz" in text  # the driver's own words


def test_missing_shader_file_is_named():
    with pytest.raises(FileNotFoundError, match="nope.glsl"):
        shaders.load_glsl("nope.glsl")


def test_every_shader_variant_compiles(gpu_context):
    """Every variant of every shader factory the passes declare (shaders.shader_variants)
    compiles; every shader the package compiles comes from a declared factory; every file in
    gpu_shaders/ is used by some pass (no dead shader text ships)."""
    import importlib
    import inspect
    import pkgutil
    import hao_addon.gpu as gpu_package
    for info in pkgutil.iter_modules(gpu_package.__path__):
        importlib.import_module(f"hao_addon.gpu.{info.name}")  # each module registers its factories
    for factory, domains, valid in shaders.SHADER_FACTORIES:
        variants = shaders.variant_arguments(domains, valid)
        assert variants, f"{factory.__name__} declares no valid variant"
        for arguments in variants:
            assert factory(**arguments) is not None, (factory.__name__, arguments)
    # A shader compiled outside a declared factory would escape this test.
    declared = {factory.__qualname__ for factory, _domains, _valid in shaders.SHADER_FACTORIES}
    for info in pkgutil.iter_modules(gpu_package.__path__):
        module = importlib.import_module(f"hao_addon.gpu.{info.name}")
        for name, function in inspect.getmembers(module, inspect.isfunction):
            if function.__module__ == module.__name__ and "cached_shader(" in inspect.getsource(function) \
                    and name != "cached_shader":
                assert function.__qualname__ in declared, f"{module.__name__}.{name} compiles an undeclared shader"
        for _cls_name, cls in inspect.getmembers(module, inspect.isclass):
            if cls.__module__ == module.__name__:
                assert "cached_shader(" not in inspect.getsource(cls), f"{cls.__name__} compiles a shader inline"
    sources = "".join(p.read_text() for p in (shaders.SHADER_DIR.parent / "hao_addon").rglob("*.py"))
    for path in shaders.SHADER_DIR.iterdir():
        assert f'"{path.name}"' in sources, f"{path.name} is not loaded by any pass"


def test_registration_needs_no_gpu_and_is_symmetric(addon):
    import bpy
    from hao_ext.operators import auto_rebake, cli_command, sphere_operators, viewport_overlay
    from hao_ext.operators.properties import HAO_PG_bake_settings
    names = ("OBJECT_OT_hao_bake_ao", "VIEW3D_PT_hao_bake", "RENDER_OT_hao_render_ao", "VIEW3D_PT_hao_view",
             "OBJECT_OT_hao_sync_spheres", "OBJECT_OT_hao_clear_spheres")
    handler_lists = (bpy.app.handlers.depsgraph_update_post, bpy.app.handlers.frame_change_post,
                     bpy.app.handlers.load_post)
    counts = [len(h) for h in handler_lists]
    assert hasattr(bpy.types.Scene, "hao_bake") and hasattr(bpy.types.Scene, "hao_view")
    assert all(hasattr(bpy.types, n) for n in names)
    addon.unregister()
    assert not hasattr(bpy.types.Scene, "hao_bake") and not hasattr(bpy.types.Scene, "hao_view")
    assert not any(hasattr(bpy.types, n) for n in names)
    assert not HAO_PG_bake_settings.is_registered
    assert cli_command._handle is None and viewport_overlay._draw_handle is None
    assert sphere_operators._draw_handle is None
    assert sphere_operators.sync_on_frame_change not in bpy.app.handlers.frame_change_post
    assert auto_rebake.note_edit not in bpy.app.handlers.depsgraph_update_post
    assert not bpy.app.timers.is_registered(auto_rebake.run_auto_rebake)
    # depsgraph updates: the viewport overlay's and Auto Re-bake's handlers
    assert [len(h) for h in handler_lists] == [counts[0] - 2, counts[1] - 2, counts[2] - 1]
    addon.register()
    assert hasattr(bpy.types.Scene, "hao_bake") and all(hasattr(bpy.types, n) for n in names)
    assert [len(h) for h in handler_lists] == counts


def test_uniform_structs_are_generated_from_their_dtypes():
    """A block's GLSL struct is its numpy dtype's (one layout, written once); a dtype that
    std140 would pad differently is refused rather than generated wrong."""
    import numpy as np
    from hao_addon.gpu.gather_shaders import GATHER_MAX_VIEWS, GATHER_VIEWS_DTYPE
    from hao_addon.gpu.hao_sampling import CASCADES_DTYPE
    from hao_addon.gpu.shaders import SHADER_DIR, glsl_struct
    assert glsl_struct("GatherViews", GATHER_VIEWS_DTYPE).splitlines()[1:3] == [
        f"  mat4 view_proj[{GATHER_MAX_VIEWS}];", f"  vec4 plane_slope[{GATHER_MAX_VIEWS}];"]
    assert glsl_struct("HaoCascades", CASCADES_DTYPE).splitlines()[-2:] == ["  ivec4 count;", "};"]
    assert not any("struct GatherViews" in p.read_text() or "struct HaoCascades" in p.read_text()
                   for p in SHADER_DIR.iterdir())
    for bad in (np.dtype([("a", "<f4", (3,))]), np.dtype([("a", "<f8", (4,))]),
                np.dtype([("a", "<f4", (4,)), ("b", "<i4", (2, 3))])):
        with pytest.raises(TypeError, match="std140"):
            glsl_struct("Bad", bad)


def test_constants_reach_glsl_from_python_only():
    """Each constant the GPU and its numpy mirror share is written once, in Python."""
    from hao_addon.core.hao.ao_pattern import GLSL_DEFINES
    from hao_addon.gpu.bake_gather import VIEWS_PER_DISPATCH
    from hao_addon.gpu.gather_shaders import GATHER_MAX_VIEWS, GATHER_VIEWS_DTYPE
    from hao_addon.gpu.shaders import SHADER_DIR
    sources = {p.name: p.read_text() for p in SHADER_DIR.iterdir()}
    for name, value in GLSL_DEFINES.items():
        # The value itself only where it is distinctive (1.0 is written everywhere).
        distinctive = len(repr(value)) > 4
        assert not any(f"#define {name}" in s or (distinctive and repr(value) in s) for s in sources.values()), name
    # std140 size of GatherViews: one array of GATHER_MAX_VIEWS mat4 (64 B) and four of vec4 (16 B).
    assert VIEWS_PER_DISPATCH <= GATHER_MAX_VIEWS
    assert GATHER_VIEWS_DTYPE.itemsize == GATHER_MAX_VIEWS * (64 + 16 + 16 + 16 + 16)
    assert [GATHER_VIEWS_DTYPE.fields[f][1] for f in ("view_proj", "plane_slope", "omega", "view_info", "window")] \
        == [0, GATHER_MAX_VIEWS * 64, GATHER_MAX_VIEWS * 80, GATHER_MAX_VIEWS * 96, GATHER_MAX_VIEWS * 112]


def test_shader_comments_cite_files_that_exist():
    """A file a shader's comment points to (a Python twin, another shader) exists under the
    name given: from the repository, the package, its gpu/ folder or gpu_shaders/."""
    import re
    from hao_addon.gpu import shaders
    root = shaders.SHADER_DIR.parent
    bases = (root, root / "hao_addon", root / "hao_addon" / "gpu", shaders.SHADER_DIR)
    for path in shaders.SHADER_DIR.iterdir():
        for cited in re.findall(r"[A-Za-z_./]+\.(?:py|glsl|comp|frag|vert)\b", path.read_text()):
            assert any((base / cited).is_file() for base in bases), f"{path.name} cites '{cited}', which does not exist"
