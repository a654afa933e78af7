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
    from hao_addon.gpu import bake_gather, bake_scatter
    from hao_addon.gpu import light_view
    light_view.depth_shader()
    light_view.layers_shader()
    for uniform in (False, True):
        for layered in (False, True):
            for wendland in (False, True):
                for footprint in (False, True):
                    bake_scatter.splat_shader(uniform, layered, wendland, footprint)
        for falloff in (None, "none", "wendland"):
            for shading in (False, True):
                bake_gather.gather_shader(uniform, 1, shading, falloff)
        bake_gather.gather_shader(uniform, 4)
        bake_gather.texel_list_shader(fill=uniform)
    from hao_addon.gpu import hao_composite, hao_gbuffer, hao_sampling, hao_voxelize
    from hao_addon.gpu.shaders import cached_shader
    hao_addon_shaders = [hao_gbuffer.gbuffer_shader(), hao_voxelize.voxelize_shader(True),
                         hao_voxelize.voxelize_shader(False), cached_shader(("hao_pyramid",), hao_voxelize._pyramid_info)]
    for march in ("hierarchical", "fixed"):
        for falloff in ("none", "wendland"):
            hao_addon_shaders.append(hao_sampling.ao_shader(march, falloff))
    for axis in (0, 1):
        hao_addon_shaders.append(hao_sampling.bilateral_shader(axis, axis == 0))
    cached_shader(("hao_composite",), hao_composite._composite_info)
    from hao_addon.gpu import near_field, sphere_far
    sphere_far.far_shader()
    near_field.near_shader()
    hao_gbuffer.gbuffer_shader(back_layer=True)
    # Every file in gpu_shaders/ is used by some pass (no dead shader text ships).
    sources = "".join(p.read_text() for p in (shaders.SHADER_DIR.parent / "hao_addon").rglob("*.py"))
    for path in shaders.SHADER_DIR.iterdir():
        assert f'"{path.name}"' in sources, f"{path.name} is not loaded by any pass"


def test_registration_needs_no_gpu_and_is_symmetric(addon):
    import bpy
    from hao_ext.operators import cli_command, sphere_operators, viewport_overlay
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
    assert [len(h) for h in handler_lists] == [counts[0] - 1, counts[1] - 2, counts[2] - 1]
    addon.register()
    assert hasattr(bpy.types.Scene, "hao_bake") and all(hasattr(bpy.types, n) for n in names)
    assert [len(h) for h in handler_lists] == counts


def test_constants_reach_glsl_from_python_only():
    """Each constant the GPU and its numpy mirror share is written once, in Python."""
    from hao_addon.core.hao.ao_pattern import GLSL_DEFINES
    from hao_addon.gpu.bake_gather import GATHER_MAX_VIEWS, GATHER_VIEWS_DTYPE, VIEWS_PER_DISPATCH
    from hao_addon.gpu.shaders import SHADER_DIR
    sources = {p.name: p.read_text() for p in SHADER_DIR.iterdir()}
    for name, value in GLSL_DEFINES.items():
        # The value itself only where it is distinctive (1.0 is written everywhere).
        distinctive = len(repr(value)) > 4
        assert not any(f"#define {name}" in s or (distinctive and repr(value) in s) for s in sources.values()), name
    assert "[4]" not in sources["bake_gather_views.glsl"] and "GATHER_MAX_VIEWS" in sources["bake_gather_views.glsl"]
    # std140 size of GatherViews: one array of GATHER_MAX_VIEWS mat4 (64 B) and three of vec4 (16 B).
    assert VIEWS_PER_DISPATCH <= GATHER_MAX_VIEWS
    assert GATHER_VIEWS_DTYPE.itemsize == GATHER_MAX_VIEWS * (64 + 16 + 16 + 16)
    assert [GATHER_VIEWS_DTYPE.fields[f][1] for f in ("view_proj", "plane_slope", "omega", "view_info")] == \
        [0, GATHER_MAX_VIEWS * 64, GATHER_MAX_VIEWS * 80, GATHER_MAX_VIEWS * 96]
