# SPDX-License-Identifier: GPL-3.0-or-later
"""The one place where supported Blender releases (4.2 LTS to 5.3) differ for this add-on.

Every other module calls these instead of testing versions itself. Imports of ``bpy`` and
``gpu`` are local, so the core floor can import this module's constants without Blender.
"""
from __future__ import annotations


def declare_depth_write(info) -> None:
    """Declare that a fragment shader writes ``gl_FragDepth`` (any value).

    4.3+ has ``GPUShaderCreateInfo.depth_write`` (a ``layout(depth_any)`` the Vulkan and Metal
    backends need); 4.2 lacks it, and there GLSL 4.30 lets any fragment shader write
    ``gl_FragDepth`` undeclared, which is what the default (any) qualifier means.
    """
    if hasattr(info, "depth_write"):
        info.depth_write('ANY')


def module_exit_may_crash() -> bool:
    """bpy 4.2 as a Python module segfaults at interpreter exit once a class with methods was
    registered (an operator, or a property group with a method), even after unregistering it:
    a teardown bug fixed in 4.3. Blender itself and later releases exit cleanly. Processes
    that register the add-on under 4.2 (the test suite) end with ``os._exit`` instead."""
    import bpy
    return bpy.app.version < (4, 3, 0)


def path_property_options() -> set[str]:
    """Options of a FILE_PATH StringProperty that accepts '//' (blend-relative) paths: 4.5+
    warns on such paths unless the property declares PATH_SUPPORTS_BLEND_RELATIVE, which
    4.2 does not know (registering it there fails)."""
    import bpy
    if "is_path_supports_blend_relative" in bpy.types.Property.bl_rna.properties:
        return {'PATH_SUPPORTS_BLEND_RELATIVE'}
    return set()


def object_terminator_offset(obj) -> float | None:
    """The Shadow Terminator Geometry Offset Cycles bakes an object with, or None where this
    Blender has no such property (Cycles not registered).

    Newer releases (5.2 here) keep it on the object itself
    (``Object.shadow_terminator_geometry_offset``, which their Cycles sync reads); 4.2 keeps it
    in Cycles' object settings (``Object.cycles.shadow_terminator_geometry_offset``). 5.2 still
    registers the Cycles one, which its Cycles no longer reads, so the object's own comes first."""
    if "shadow_terminator_geometry_offset" in obj.bl_rna.properties:
        return float(obj.shadow_terminator_geometry_offset)
    cycles = getattr(obj, "cycles", None)
    if cycles is not None and hasattr(cycles, "shadow_terminator_geometry_offset"):
        return float(cycles.shadow_terminator_geometry_offset)
    return None


def material_node_tree(material):
    """The material's node tree where its nodes shade it, else None. Blender 5.0 made every
    material use nodes (Material.use_nodes is deprecated there, to be removed in 6.0)."""
    import bpy

    if material is None or material.node_tree is None:
        return None
    if bpy.app.version >= (5, 0, 0) or material.use_nodes:
        return material.node_tree
    return None


def set_shader_inputs(shader, samplers: dict, ints: dict | None = None, floats: dict | None = None) -> None:
    """Set a bound shader's samplers ({name: GPUTexture}), then its push constants ({name:
    value}). In this order on every release: Blender 5.3's uniform_sampler overwrites the
    first push constant set before it with the sampler's slot (every Selected-to-Active ray
    then missed; tests/test_gpu_inputs.py)."""
    for name, texture in samplers.items():
        shader.uniform_sampler(name, texture)
    for name, value in (ints or {}).items():
        shader.uniform_int(name, value)
    for name, value in (floats or {}).items():
        shader.uniform_float(name, value)


def storage_buffers() -> bool:
    """Whether this Blender's gpu module has storage buffers (5.3 and newer: GPUStorageBuf,
    GPUShaderCreateInfo.storage_buf, GPUShader.storage_block); gpu/list_inputs.py then keeps
    a compute pass's lists in them instead of list textures."""
    import gpu
    return (hasattr(gpu.types, "GPUStorageBuf") and hasattr(gpu.types.GPUShaderCreateInfo, "storage_buf")
            and hasattr(gpu.types.GPUShader, "storage_block"))


def declare_storage_list(info, slot: int, glsl_type: str, name: str, write: bool) -> None:
    """Declare a storage buffer `glsl_type name[]` (5.3's storage_buf), read-only unless write."""
    info.storage_buf(slot, glsl_type, f"{name}[]", qualifiers={'WRITE'} if write else {'READ'})


def storage_buffer(data) -> object:
    """A storage buffer holding data (a gpu.types.Buffer), 5.3's GPUStorageBuf."""
    import gpu
    return gpu.types.GPUStorageBuf(data)
